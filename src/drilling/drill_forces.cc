// Twist-drill forces by elemental oblique cutting along the lips with the
// dynamic rake angle (seed 003 eqs. 2-7, after [Minukhin 2013]).
//
// The seed's copy of eqs. 2-7 is partly garbled; the model below is derived
// from classical oblique-cutting theory, and every choice is written down:
//
// (C1) Lip geometry [Armarego & Cheng 1972; seed eq. 3]: the straight lip is
//      offset from the axis by the web half-thickness w_t, so at radius r
//        web angle     w      = asin(w_t / r)
//        inclination   i      = asin(sin w sin p)
//        local helix   beta_r = atan(2r/D tan beta_0)
//        indexing      eps    = atan(tan w cos p)
//        static rake   tan g  = [tan beta_r (cos w + sin w tan w cos^2 p)
//                                - tan w cos p] / sin p
//      (the seed's printed eq. 3 read with the whole bracket over sin p;
//      this gives +29 deg at the corner and -36 deg near the chisel edge of a
//      118 deg / 30 deg drill, the textbook range).
// (C2) Dynamic rake [Minukhin 2013]: the feed tilts the cutting velocity by
//      eta with tan eta = (f / 2 pi) sin p / (r cos w): feed velocity f N
//      projected onto the lip normal (sin p) over the speed component normal
//      to the lip in the end view (2 pi N r cos w). gamma_d = g + eta.
// (C3) Normal friction and shear angles as printed in seed eq. 3:
//        beta_n = pi/6 + gamma_d/2,   phi_n = pi/4 + (gamma_d - beta_n)/2
//      (Merchant's minimum-energy shear angle with a rake-dependent friction
//      angle).
// (C4) Oblique-cutting forces per element [Budak, Altintas & Armarego 1996,
//      eqs. 9], Stabler's chip-flow rule eta_c = i:
//        F_c = tau b h [cos(beta_n - a_n) + tan i tan eta_c sin beta_n] / S
//        F_t = tau b h sin(beta_n - a_n) / (cos i S)
//        F_r = tau b h [cos(beta_n - a_n) tan i - tan eta_c sin beta_n] / S
//        S   = sin phi_n sqrt(cos^2(phi_n + beta_n - a_n) + tan^2 eta_c sin^2 beta_n)
//      with a_n = gamma_d, width b = dl = r dr / (sin p sqrt(r^2 - w_t^2))
//      (seed eq. 2 with the sign under the root corrected: the lip is a
//      straight line at distance w_t from the axis, projected on the cone)
//      and uncut chip thickness h = (f / lips) sin p.
// (C5) Projection: the cutting force F_c acts along the cutting velocity,
//      tangential at radius r, so dT = r F_c. F_t is normal to the lip in the
//      plane of the axis and F_r along the lip, so the axial (thrust) part is
//      F_t sin p - F_r cos p and the in-plane part pushing the lip towards
//      the axis is F_t cos p + F_r sin p. (The seed's eqs. 4-5 carry extra
//      cos(eps) factors of the indexing angle; we keep the plain projection,
//      so eps is reported but not used.)
// (C6) The seed uses separate factors K_TH (thrust) and K_TQ (torque); tau in
//      F_t and F_r is K_TH, in F_c it is K_TQ, each with the Kienzle size
//      effect tau = K (h/h_ref)^(-m) (drill_forces.h, K1).
// (C7) Chisel edge: seed scaling (F_A = 2.5 F_L, T_A = 1.67 T) by default;
//      or orthogonal cutting at a fixed rake of -56 deg (typical chisel
//      rakes are -50 to -60 deg) with width r_c per half and h = f / lips.
// (C8) Entry (seed eq. 6) and tilt (seed eq. 7): see drill_forces.h. The
//      chisel contribution is taken as fully engaged from the first contact
//      (its length is below 1.1 mm, passed within the first 0.1 mm of feed).
//
// - [Armarego & Cheng 1972] E. J. A. Armarego, C. Y. Cheng, Drilling with
//   flat rake face and conventional twist drills, Int. J. Mach. Tool Des.
//   Res. 12, 17-35.
// - [Budak, Altintas & Armarego 1996] Prediction of milling force
//   coefficients from orthogonal cutting data, ASME J. Manuf. Sci. Eng. 118,
//   216-224.
// - [Kienzle 1952] O. Kienzle, Die Bestimmung von Kräften und Leistungen an
//   spanenden Werkzeugen und Werkzeugmaschinen, VDI-Z 94, 299-305.
// - [Minukhin 2013] I. Minukhin, An improved method of cutting forces
//   prediction for the primary cutting edges of twist drills, MASc thesis,
//   Concordia University, Montreal, 2013.
#include "robomach/drilling/drill_forces.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "robomach/common/enum_names.h"
#include "robomach/common/option_validate.h"

namespace robomach::drilling {
namespace {

void Require(bool ok, const std::string& field, double value, const std::string& bound) {
  if (ok) return;
  std::ostringstream s;
  s << field << ": expected " << bound << ", got " << value;
  throw std::invalid_argument(s.str());
}

double SizeEffect(const DrillingMaterial& m, double h) {
  return std::pow(h / m.reference_chip_thickness, -m.kienzle_exponent);
}

// Orthogonal-cutting force ratios per unit (tau b h) for rake a (C3, C4 with i = 0).
void OrthogonalRatios(double rake, double* cutting, double* normal) {
  const double beta = kPi / 6.0 + 0.5 * rake;
  const double phi = kPi / 4.0 + 0.5 * (rake - beta);
  const double den = std::sin(phi) * std::cos(phi + beta - rake);
  *cutting = std::cos(beta - rake) / den;
  *normal = std::sin(beta - rake) / den;
}

}  // namespace

double DrillGeometry::chisel_half_length() const {
  return web_half_thickness() / std::sin(chisel_edge_angle);
}

void CheckValid(const DrillGeometry& d) {
  Require(std::isfinite(d.diameter) && d.diameter > 0.0, "diameter", d.diameter, "> 0 m");
  Require(d.lips >= 1 && d.lips <= 8, "lips", d.lips, "1..8");
  Require(d.point_angle > DegToRad(60) && d.point_angle < DegToRad(180), "point_angle",
          RadToDeg(d.point_angle), "60..180 deg");
  Require(d.helix_angle >= 0.0 && d.helix_angle < DegToRad(60), "helix_angle",
          RadToDeg(d.helix_angle), "0..60 deg");
  Require(d.web_thickness_ratio >= 0.0 && d.web_thickness_ratio < 0.5, "web_thickness_ratio",
          d.web_thickness_ratio, "0..0.5");
  Require(d.chisel_edge_angle > DegToRad(90) && d.chisel_edge_angle < DegToRad(180),
          "chisel_edge_angle", RadToDeg(d.chisel_edge_angle), "90..180 deg");
  Require(d.lip_relief_angle >= 0.0 && d.lip_relief_angle < DegToRad(45), "lip_relief_angle",
          RadToDeg(d.lip_relief_angle), "0..45 deg");
  Require(d.chisel_half_length() < d.radius(), "web_thickness_ratio", d.web_thickness_ratio,
          "a chisel edge shorter than the diameter");
}

void CheckValid(const DrillingMaterial& m) {
  Require(std::isfinite(m.shear_stress_thrust) && m.shear_stress_thrust > 0.0,
          "shear_stress_thrust", m.shear_stress_thrust, "> 0 Pa");
  Require(std::isfinite(m.shear_stress_torque) && m.shear_stress_torque > 0.0,
          "shear_stress_torque", m.shear_stress_torque, "> 0 Pa");
  Require(m.kienzle_exponent >= 0.0 && m.kienzle_exponent < 1.0, "kienzle_exponent",
          m.kienzle_exponent, "0 <= m < 1");
  Require(m.reference_chip_thickness > 0.0, "reference_chip_thickness",
          m.reference_chip_thickness, "> 0 m");
  Require(m.chisel_thrust_factor >= 1.0, "chisel_thrust_factor", m.chisel_thrust_factor, ">= 1");
  Require(m.chisel_torque_factor >= 1.0, "chisel_torque_factor", m.chisel_torque_factor, ">= 1");
  Require(m.chisel_rake_angle > -kPi / 2 && m.chisel_rake_angle < 0.0, "chisel_rake_angle",
          RadToDeg(m.chisel_rake_angle), "-90..0 deg");
}

LipElementAngles ComputeLipElementAngles(const DrillGeometry& d, double f, double r,
                                         bool dynamic_rake) {
  const double p = d.half_point_angle();
  const double wt = d.web_half_thickness();
  LipElementAngles a;
  a.web_angle = std::asin(std::min(1.0, wt / r));
  const double w = a.web_angle;
  a.inclination = std::asin(std::sin(w) * std::sin(p));
  a.local_helix = std::atan(2.0 * r / d.diameter * std::tan(d.helix_angle));
  const double cp = std::cos(p);
  a.static_rake = std::atan(
      (std::tan(a.local_helix) * (std::cos(w) + std::sin(w) * std::tan(w) * cp * cp) -
       std::tan(w) * cp) /
      std::sin(p));
  double eta = 0.0;
  if (dynamic_rake) eta = std::atan(f / (2.0 * kPi) * std::sin(p) / (r * std::cos(w)));
  a.dynamic_rake = a.static_rake + eta;
  a.friction_angle = kPi / 6.0 + 0.5 * a.dynamic_rake;
  a.shear_angle = kPi / 4.0 + 0.5 * (a.dynamic_rake - a.friction_angle);
  a.indexing_angle = std::atan(std::tan(w) * cp);
  return a;
}

LipIntegrand LipForcePerRadius(const DrillGeometry& d, const DrillingMaterial& m, double f,
                               double r, bool dynamic_rake) {
  const LipElementAngles a = ComputeLipElementAngles(d, f, r, dynamic_rake);
  const double p = d.half_point_angle();
  const double wt = d.web_half_thickness();
  const double h = f / d.lips * std::sin(p);
  const double db_dr = r / (std::sin(p) * std::sqrt(r * r - wt * wt));  // (C4) width per dr
  const double size = SizeEffect(m, h);
  const double i = a.inclination, eta_c = a.inclination;
  const double bn = a.friction_angle, an = a.dynamic_rake, phin = a.shear_angle;
  const double c = std::cos(phin + bn - an);
  const double S = std::sin(phin) * std::sqrt(c * c + std::pow(std::tan(eta_c) * std::sin(bn), 2));
  const double Fc = std::cos(bn - an) + std::tan(i) * std::tan(eta_c) * std::sin(bn);
  const double Ft = std::sin(bn - an) / std::cos(i);
  const double Fr = std::cos(bn - an) * std::tan(i) - std::tan(eta_c) * std::sin(bn);
  const double th = m.shear_stress_thrust * size * h * db_dr / S;
  const double tq = m.shear_stress_torque * size * h * db_dr / S;
  LipIntegrand out;
  out.torque = tq * Fc * r;
  out.thrust = th * (Ft * std::sin(p) - Fr * std::cos(p));
  out.radial = th * (Ft * std::cos(p) + Fr * std::sin(p));
  return out;
}

void ForceModelOptions::Validate() const {
  CheckOptionAtLeast("num_elements", num_elements, 1);
}

LipIntegrand IntegrateLip(const DrillGeometry& d, const DrillingMaterial& m, double f,
                          double r_outer, const ForceModelOptions& options) {
  options.Validate();
  const double rc = d.chisel_half_length();
  const double R = d.radius();
  const double dr = (R - rc) / options.num_elements;
  LipIntegrand sum;
  for (int k = 0; k < options.num_elements; ++k) {
    const double a = rc + k * dr;
    if (a >= r_outer) break;
    const double b = std::min(a + dr, r_outer);
    const LipIntegrand g = LipForcePerRadius(d, m, f, 0.5 * (a + b), options.dynamic_rake);
    sum.thrust += g.thrust * (b - a);
    sum.torque += g.torque * (b - a);
    sum.radial += g.radial * (b - a);
  }
  return sum;
}

double EngagedRadius(const DrillGeometry& d, double penetration) {
  const double rc = d.chisel_half_length();
  const double wt = d.web_half_thickness();
  if (penetration <= 0.0) return rc;
  const double delta = penetration * std::tan(d.half_point_angle());
  const double s = std::sqrt(std::max(0.0, rc * rc - wt * wt)) + delta;
  return std::min(d.radius(), std::sqrt(s * s + wt * wt));
}

double TiltedLipRadius(const DrillGeometry& d, double r, double tilt) {
  const double A = std::abs(tilt);
  const double B = 0.5 * kPi - d.half_point_angle();
  const double C = kPi - A - B;
  return r * std::sin(B) / std::sin(C);
}

LipIntegrand ChiselOrthogonal(const DrillGeometry& d, const DrillingMaterial& m, double f) {
  const double rc = d.chisel_half_length();
  const double h = f / d.lips;
  double cut = 0.0, normal = 0.0;
  OrthogonalRatios(m.chisel_rake_angle, &cut, &normal);
  const double size = SizeEffect(m, h);
  LipIntegrand out;
  out.thrust = d.lips * m.shear_stress_thrust * size * h * normal * rc;
  out.torque = d.lips * m.shear_stress_torque * size * h * cut * 0.5 * rc * rc;
  return out;
}

DrillForces ComputeDrillForces(const DrillGeometry& d, const DrillingMaterial& m,
                               const DrillState& s, const ForceModelOptions& options) {
  options.Validate();
  CheckValid(d);
  CheckValid(m);
  if (!(std::isfinite(s.feed_per_rev) && s.feed_per_rev > 0.0)) {
    throw std::invalid_argument("feed_per_rev: expected > 0 m/rev");
  }
  if (!std::isfinite(s.penetration) || !std::isfinite(s.tilt) ||
      !std::isfinite(s.spindle_angle)) {
    throw std::invalid_argument("drill state: expected finite penetration, tilt and angle");
  }
  DrillForces out;
  const double rc = d.chisel_half_length();
  if (s.penetration <= 0.0) {
    out.engaged_radius = out.short_lip_radius = rc;
    return out;
  }
  const double re = EngagedRadius(d, s.penetration);
  const double rq = std::max(rc, std::min(re, TiltedLipRadius(d, d.radius(), s.tilt)));
  out.engaged_radius = re;
  out.short_lip_radius = rq;
  out.fully_engaged = re >= d.radius();
  const LipIntegrand full = IntegrateLip(d, m, s.feed_per_rev, re, options);
  const LipIntegrand shorter =
      rq < re ? IntegrateLip(d, m, s.feed_per_rev, rq, options) : full;
  // Lips alternate full / short around the drill (every second lip is short).
  const int n_full = (d.lips + 1) / 2;
  const int n_short = d.lips / 2;
  double thrust = n_full * full.thrust + n_short * shorter.thrust;
  double torque = n_full * full.torque + n_short * shorter.torque;
  switch (m.chisel) {
    case ChiselModel::kSeedScaling:
      thrust *= m.chisel_thrust_factor;
      torque *= m.chisel_torque_factor;
      break;
    case ChiselModel::kOrthogonal: {
      const LipIntegrand ch = ChiselOrthogonal(d, m, s.feed_per_rev);
      thrust += ch.thrust;
      torque += ch.torque;
      break;
    }
    case ChiselModel::kNone:
      break;
  }
  out.thrust = thrust;
  out.torque = torque;
  // Each lip is pushed towards the axis (C5): lip k at angle psi + 2 pi k / z
  // gets -radial_k e_k. For an even number of lips the sum is
  // (radial_full - radial_short) times -e_full summed over the full lips, i.e.
  // it points from the axis towards the short lip(s). With an odd number of
  // lips a full lip has no opposite partner; we keep the same pairing rule
  // (every second lip short) and sum the vectors.
  Eigen::Vector2d f = Eigen::Vector2d::Zero();
  for (int k = 0; k < d.lips; ++k) {
    const double ang = s.spindle_angle + 2.0 * kPi * k / d.lips;
    const double radial = (k % 2 == 0) ? full.radial : shorter.radial;
    f -= radial * Eigen::Vector2d(std::cos(ang), std::sin(ang));
  }
  out.radial = f;
  return out;
}

const char* ToString(ChiselModel m) {
  switch (m) {
    case ChiselModel::kSeedScaling: return "seed_scaling";
    case ChiselModel::kOrthogonal: return "orthogonal";
    case ChiselModel::kNone: return "none";
  }
  return "?";
}

ChiselModel ParseChiselModel(const std::string& name) {
  constexpr ChiselModel kAll[] = {ChiselModel::kSeedScaling, ChiselModel::kOrthogonal, ChiselModel::kNone};
  return ParseByName("chisel model", name, kAll);
}

}  // namespace robomach::drilling
