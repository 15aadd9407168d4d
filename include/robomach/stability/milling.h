#pragma once

#include <Eigen/Core>

namespace robomach::stability {

/// Which side of the tool the material is on. Angles φ of a tooth are
/// measured clockwise from the cutting-frame y axis (the feed normal), the
/// tool turning clockwise seen from the spindle (Altintas 2000,
/// Insperger & Stepan 2004): up-milling enters at φ = 0, down-milling leaves
/// at φ = π.
enum class MillingDirection { kUp, kDown };

/// Linear edge-force-free cutting law per unit depth of cut a and chip
/// thickness h [Altintas 2000, mechanistic model without edge terms]:
/// <pre>
///   F_t = K_t a h,   F_r = K_r a h,   F_a = K_a a h                     (1)
/// </pre>
/// All three in N/m² (N per m of depth per m of chip). K_r is the absolute
/// radial coefficient (Insperger & Stepan's K_n), not the ratio K_r/K_t.
struct CuttingCoefficients {
  double Kt{0.0};  // tangential [N/m²]
  double Kr{0.0};  // radial (normal) [N/m²]
  double Ka{0.0};  // axial [N/m²]

  /// Tlusty's [K_s, β] form: the resultant K_s acts at angle β from the
  /// normal of the cut surface, K_t = K_s sin β, K_r = K_s cos β, K_a = 0.
  static CuttingCoefficients FromKsBeta(double Ks, double beta_rad);
};

/// A milling operation as far as its dynamics are concerned.
///
/// Cutting frame C: x along the feed, z along the tool axis pointing from
/// the tool tip into the spindle, y = z × x (the feed normal).
struct MillingProcess {
  int teeth{2};
  double radial_immersion{1.0};  // a_e / D in (0, 1]
  MillingDirection direction{MillingDirection::kDown};
  CuttingCoefficients coefficients;

  /// @throws std::invalid_argument naming the field if teeth < 1, the
  ///   immersion is outside (0, 1], or a coefficient is negative or not finite.
  void Validate() const;
  /// Entry and exit angles [rad]: up-milling φst = 0, φex = acos(1 − 2 a_e/D);
  /// down-milling φst = acos(2 a_e/D − 1), φex = π.
  double entry_angle() const;
  double exit_angle() const;
};

/// The specific directional matrix of the regenerative force at time t for
/// the spindle speed Ω [rad/s] [Insperger & Stepan 2004, milling example]:
/// <pre>
///   F_C(t) = −a H(t) (x_C(t) − x_C(t − τ)),   τ = 2π/(N Ω),
///   H(t) = Σ_j g(φ_j) [ sφ(Kt cφ + Kr sφ)   cφ(Kt cφ + Kr sφ) ]
///                     [ sφ(−Kt sφ + Kr cφ)  cφ(−Kt sφ + Kr cφ) ]
///                     [ Ka sφ               Ka cφ              ]         (2)
/// </pre>
/// with φ_j = Ω t + 2π j/N, g = 1 inside [φst, φex] and 0 outside.
/// Rows are the force components x, y, z of C; columns the in-plane
/// displacements x, y (an axial displacement of a flat end mill does not
/// change the chip). The axial row uses F_a = −K_a a h along z.
/// @returns 3×2 [N/m²].
Eigen::Matrix<double, 3, 2> DirectionalMatrixAt(const MillingProcess& p, double spindle_speed_rad_s,
                                                double t);

/// The mean of (2) over the rotation angle interval [ψ0, ψ1] of tooth 0
/// (ψ = Ω t), in closed form; over one tooth period this is the
/// Altintas-Budak average directional matrix:
/// <pre>
///   H0 = (N / 2π) ∫_{φst}^{φex} h(φ) dφ                                   (3)
/// </pre>
/// [Altintas & Budak 1995] (their α_xx.. times K_t, with K_r
/// absolute).
Eigen::Matrix<double, 3, 2> MeanDirectionalMatrix(const MillingProcess& p, double psi0,
                                                  double psi1);
/// (3): the average over a tooth period.
Eigen::Matrix<double, 3, 2> AverageDirectionalMatrix(const MillingProcess& p);

/// The 3×3 cutting stiffness per unit depth [N/m²] that the mode-coupling
/// model uses (the average (3) with a zero axial-displacement column):
/// F_C = −a K_c x_C.
Eigen::Matrix3d CuttingStiffnessPerDepth(const MillingProcess& p);

/// - [Altintas 2000] Y. Altintas, Manufacturing Automation, Cambridge UP, 2000.
/// - [Altintas & Budak 1995] Y. Altintas, E. Budak, Analytical prediction of
///   stability lobes in milling, CIRP Annals 44(1):357-362, 1995.
/// - [Insperger & Stepan 2004] T. Insperger, G. Stepan, Updated
///   semi-discretization method for periodic delay-differential equations
///   with discrete delay, Int. J. Numer. Meth. Engng 61:117-141, 2004.

}  // namespace robomach::stability
