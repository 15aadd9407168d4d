// tool_flexibility: the cutting tool as a clamped Euler–Bernoulli cantilever
// in the holder, its first bending modes added as modal DOFs.
//
// The tool (solid cylinder of diameter d, stick-out L, modulus E, density ρ;
// A = π d²/4, I = π d⁴/64) is clamped at C, L behind the tool tip on the
// tool axis a, and bends in the two lateral directions e_x, e_y of the
// flange axes. Its deflection relative to the holder is
// w(x, t) = Σ_n φ_n(x) η_n(t) e_d with the clamped–free modes
//   φ_n(x) = [cosh β_n x − cos β_n x − σ_n (sinh β_n x − sin β_n x)] / norm,
//   σ_n = (cosh β_n L + cos β_n L)/(sinh β_n L + sin β_n L),
// β_n L = 1.87510, 4.69409, 7.85476, 10.99554, normalised to φ_n(L) = 1 so
// that η_n is the tool-tip deflection of mode n [Blevins 1979, Table 8-1;
// Rao 2007, §8.5]. The clamp moves with the holder (base excitation): a
// point of the tool at x has v = v_C + ω × (x a) + Σ φ_n η_n' e_d, so the
// kinetic energy ½ ρA ∫ |v|² dx gives
//   M[η_nd, η_nd] = ρA ∫ φ_n² dx (= ρA L/4),
//   M[η_nd, z]    = ρA [∫φ_n dx · e_dᵀ, ∫x φ_n dx · (a × e_d)ᵀ] V_C       (1)
// with V_C the holder's twist at C (AssembledSystem::V_T shifted from T to
// C); the rigid part ½ ρA ∫|v_C + ω × x a|² is already in the model because
// the tool's mass belongs to the holder_and_tool body. The strain energy
// gives K[η_n, η_n] = EI ∫ φ_n''² = β_n⁴ EI ∫ φ_n² (modes are orthogonal in
// mass and stiffness), so a rigid holder leaves the cantilever frequencies
// ω_n = (β_n L)² √(EI/(ρA L⁴)); the static tip compliance of n modes is
// Σ 4/(β_n L)⁴ · L³/(EI) → L³/(3EI). The tool tip moves with η (B gains
// e_d) and turns by φ_n'(L) about a × e_d.
//
// Defaults: a Ø10 mm solid-carbide end mill with 40 mm stick-out
// (E = 600 GPa, ρ = 14 500 kg/m³; the fluted part is softer, which an
// effective diameter below the shank's covers): first mode ≈ 5.6 kHz, tip
// stiffness ≈ 1.4e7 N/m. Two modes per direction by default (the second at
// ≈ 35 kHz only completes the static compliance to 0.3 %).
//
// - [Blevins 1979] R. D. Blevins, Formulas for Natural Frequency and Mode
//   Shape, Van Nostrand Reinhold, 1979.
// Damping: ζ per mode (modal damping of the clamped tool), replacing the
// model's Rayleigh α K on these DOFs.
// - [Rao 2007] S. S. Rao, Vibration of Continuous Systems, Wiley, 2007.
#include <array>
#include <cmath>
#include <span>
#include <stdexcept>

#include "dynamics/internal/body_on_springs.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/effect.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

class ToolFlexibilityEffect final : public Effect {
 public:
  static constexpr std::array<double, 4> kBetaL = {1.875104068711961, 4.694091132974175,
                                                   7.854757438237613, 10.99554073487547};

  std::string name() const override { return "tool_flexibility"; }
  std::string description() const override {
    return "tool as a clamped Euler-Bernoulli cantilever: bending modes in both lateral "
           "directions (Blevins 1979)";
  }
  std::vector<ParameterSpec> parameters() const override {
    return {
        {"diameter_m", "m", 0.010, 0.001, 0.05, true, "effective bending diameter of the tool"},
        {"stick_out_m", "m", 0.040, 0.005, 0.3, true, "free length from the holder to the tool tip"},
        {"youngs_modulus_Pa", "Pa", 6.0e11, 5e10, 1e12, false, "tool material (carbide: 600 GPa)"},
        {"density_kg_per_m3", "kg/m³", 14500.0, 1000.0, 20000.0, false,
         "tool material (carbide: 14 500 kg/m³)"},
        {"modes", "1", 2.0, 1.0, 4.0, false, "bending modes per lateral direction (whole number)"},
        // Tools clamped in holders: 1–3 % in tool-point tap tests.
        {"damping_ratio", "1", 0.02, 0.001, 0.3, true,
         "damping ratio of the tool's bending modes (replaces alpha K there)"},
    };
  }
  EffectStage stage() const override { return EffectStage::kTool; }
  int num_extra_dofs(std::span<const double> v) const override {
    return 2 * static_cast<int>(std::lround(v[4]));
  }

  /// Mode shape integrals for β_n L with L = 1 (φ(1) = 1): ∫φ, ∫xφ, ∫φ², φ'(1).
  struct ModeIntegrals {
    double i0, i1, i2, slope;
  };
  static ModeIntegrals Integrals(double bl) {
    const double sg = (std::cosh(bl) + std::cos(bl)) / (std::sinh(bl) + std::sin(bl));
    auto raw = [&](double x) {
      return std::cosh(bl * x) - std::cos(bl * x) - sg * (std::sinh(bl * x) - std::sin(bl * x));
    };
    const double norm = raw(1.0);
    // Composite 4-point Gauss–Legendre on 64 panels: the integrands are
    // smooth (|φ⁽⁸⁾| ≲ (β_n L)⁸), error ≪ 1e-12.
    static constexpr double xg[4] = {-0.8611363115940526, -0.3399810435848563,
                                     0.3399810435848563, 0.8611363115940526};
    static constexpr double wg[4] = {0.3478548451374538, 0.6521451548625461,
                                     0.6521451548625461, 0.3478548451374538};
    constexpr int panels = 64;
    ModeIntegrals r{0.0, 0.0, 0.0, 0.0};
    for (int p = 0; p < panels; ++p) {
      const double a = static_cast<double>(p) / panels, h = 1.0 / panels;
      for (int g = 0; g < 4; ++g) {
        const double x = a + 0.5 * h * (xg[g] + 1.0);
        const double phi = raw(x) / norm, w = 0.5 * h * wg[g];
        r.i0 += w * phi;
        r.i1 += w * x * phi;
        r.i2 += w * phi * phi;
      }
    }
    r.slope = bl * (std::sinh(bl) + std::sin(bl) - sg * (std::cosh(bl) - std::cos(bl))) / norm;
    return r;
  }

  void Contribute(const EffectContext& ctx, std::span<const double> v, int first,
                  AssembledSystem* sys) const override {
    const double d = v[0], L = v[1], E = v[2], rho = v[3];
    const double modes_value = v[4];
    if (modes_value != std::round(modes_value)) {
      throw std::invalid_argument("tool_flexibility.modes must be a whole number, got " +
                                  std::to_string(modes_value));
    }
    const int n_modes = static_cast<int>(modes_value);
    const double A = kPi * d * d / 4.0, I = kPi * std::pow(d, 4) / 64.0;
    const double rhoA = rho * A, EI = E * I;
    const Eigen::Matrix3d R = ctx.X_BT.linear();  // flange axes; z = tool axis, away from the robot
    const Eigen::Vector3d a = R.col(2);
    const Eigen::Vector3d p_T = ctx.X_BT.translation();
    const Eigen::Vector3d p_C = p_T - L * a;
    const Matrix6Xd V_C = internal::ShiftTwist(p_C - p_T) * sys->V_T;
    for (int m = 0; m < n_modes; ++m) {
      const double bl = kBetaL[m];
      const ModeIntegrals mi = Integrals(bl);
      const double m_n = rhoA * L * mi.i2;                    // ρA ∫φ² dx
      const double k_n = std::pow(bl / L, 4) * EI * L * mi.i2;  // β⁴ EI ∫φ² dx
      for (int dir = 0; dir < 2; ++dir) {
        const int i = first + 2 * m + dir;
        const Eigen::Vector3d e = R.col(dir);
        Vector6d row;
        row << rhoA * L * mi.i0 * e, rhoA * L * L * mi.i1 * a.cross(e);
        const Eigen::VectorXd coupling = V_C.transpose() * row;  // eq. (1), over all coordinates
        sys->M.row(i) += coupling.transpose();
        sys->M.col(i) += coupling;
        sys->M(i, i) += m_n;  // coupling(i) is zero: V_C has no column i yet
        sys->K(i, i) += k_n;
        // Modal damping 2 ζ ω_n m_n in place of the model's α k_n (which
        // would give α ω_n/2 ≈ 180 % at 5.6 kHz with α = 1e-4 s).
        sys->C_extra(i, i) += 2.0 * v[5] * std::sqrt(k_n / m_n) * m_n - ctx.model.alpha() * k_n;
        sys->V_T.col(i) << e, (mi.slope / L) * a.cross(e);
      }
    }
    sys->B = sys->V_T.topRows<3>();
  }
};

}  // namespace robomach::dynamics

ROBOMACH_REGISTER_EFFECT(tool_flexibility, robomach::dynamics::ToolFlexibilityEffect)
