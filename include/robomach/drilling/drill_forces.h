#pragma once

#include <Eigen/Core>

#include "robomach/common/units.h"

namespace robomach::drilling {

/// Geometry of a standard twist drill (formats.md §9.2). SI, radians.
struct DrillGeometry {
  double diameter{5e-3};                        // D [m]
  int lips{2};                                  // number of cutting lips (flutes)
  double point_angle{DegToRad(118.0)};          // 2p, full angle between the lips [rad]
  double helix_angle{DegToRad(30.0)};           // beta_0 at the outer corner [rad]
  double web_thickness_ratio{0.18};             // web thickness 2 w_t / D
  double chisel_edge_angle{DegToRad(125.0)};    // psi [rad]
  double lip_relief_angle{DegToRad(12.0)};      // [rad]; informational (not in the force model)

  double radius() const { return 0.5 * diameter; }
  double half_point_angle() const { return 0.5 * point_angle; }    // p [rad]
  /// Web half-thickness w_t = web_thickness_ratio D / 2 [m] (the lip's offset
  /// from the axis, "omega" in seed 003 eq. 2).
  double web_half_thickness() const { return 0.5 * web_thickness_ratio * diameter; }
  /// Radius where the lips start, r_c = b_psi / 2, b_psi = 2 w_t / sin(psi)
  /// the chisel-edge length (seed 003, text under eq. 6) [m].
  double chisel_half_length() const;
};

/// @throws std::invalid_argument naming the field, its value and the bound.
void CheckValid(const DrillGeometry& drill);

/// How the chisel edge is accounted for.
enum class ChiselModel {
  /// Seed 003 (text after eq. 6): F_A = 2.5 F_L, T_A = 1.67 T, i.e. the lips'
  /// thrust and torque scaled by the factors below.
  kSeedScaling,
  /// The chisel edge as orthogonal cutting at a fixed, strongly negative rake
  /// (ChiselOrthogonal() below), added to the lips.
  kOrthogonal,
  /// Lips only.
  kNone,
};

/// "seed_scaling", "orthogonal", "none" (drill-force-fit's --chisel).
const char* ToString(ChiselModel m);
/// The inverse of ToString.
/// @throws std::invalid_argument naming the three for anything else.
ChiselModel ParseChiselModel(const std::string& name);

/// Fitted coefficients of the force model for one drill/work-material pair
/// (the `material_*.yaml` file written by drill-force-fit).
///
/// Size effect (Kienzle type): the shear-stress factors act at the reference
/// chip thickness h_ref and scale with the local uncut chip thickness h as
/// <pre>
///   tau(h) = K (h / h_ref)^(-m),                                      (K1)
/// </pre>
/// so that forces go as f^(1 - m) at a fixed geometry [Kienzle 1952].
struct DrillingMaterial {
  double shear_stress_thrust{600e6};   // K_TH at h_ref [Pa] (seed eq. 4)
  double shear_stress_torque{600e6};   // K_TQ at h_ref [Pa] (seed eq. 5)
  double kienzle_exponent{0.0};        // m, dimensionless, in [0, 1)
  double reference_chip_thickness{0.1e-3};  // h_ref [m]
  ChiselModel chisel{ChiselModel::kSeedScaling};
  double chisel_thrust_factor{2.5};    // seed: F_A = 2.5 F_L
  double chisel_torque_factor{1.67};   // seed: T_A = 1.67 T
  double chisel_rake_angle{DegToRad(-56.0)};  // for kOrthogonal [rad]
};

/// @throws std::invalid_argument naming the field, its value and the bound.
void CheckValid(const DrillingMaterial& material);

struct ForceModelOptions {
  int num_elements{100};      // oblique-cutting elements per lip (midpoint rule in r)
  bool dynamic_rake{true};   // add the feed-velocity angle to the rake (Minukhin 2013)

  /// The bounds (issue #36):
  /// - num_elements >= 1: the midpoint rule needs one element.
  /// @throws OptionError(field, "FIELD: expected a value >= LO, got VALUE").
  void Validate() const;
};

/// The oblique-cutting quantities of one lip element at radius r (seed 003
/// eq. 3, with the choices listed in drill_forces.cc).
struct LipElementAngles {
  double web_angle{0.0};        // w = asin(w_t / r)
  double inclination{0.0};      // i = asin(sin w sin p)
  double local_helix{0.0};      // beta_r = atan(2r/D tan beta_0)
  double static_rake{0.0};      // normal rake of the ground lip
  double dynamic_rake{0.0};     // gamma_d = static rake + feed-velocity angle
  double friction_angle{0.0};   // beta_n = pi/6 + gamma_d / 2
  double shear_angle{0.0};      // phi_n = pi/4 + (gamma_d - beta_n) / 2
  double indexing_angle{0.0};   // epsilon = atan(tan w cos p)
};

LipElementAngles ComputeLipElementAngles(const DrillGeometry& drill, double feed_per_rev,
                                         double r, bool dynamic_rake);

/// Force per unit radius dF/dr of ONE lip at radius r (r_c < r <= D/2):
/// thrust along the drill axis [N/m], torque about it [N·m/m] and the
/// in-plane (radial) force pushing the lip towards the axis [N/m].
struct LipIntegrand {
  double thrust{0.0};
  double torque{0.0};
  double radial{0.0};
};
LipIntegrand LipForcePerRadius(const DrillGeometry& drill, const DrillingMaterial& material,
                               double feed_per_rev, double r, bool dynamic_rake);

/// Integrated loads of one lip between r_c and r_outer (midpoint rule with
/// options.num_elements elements over [r_c, D/2], elements beyond r_outer
/// dropped and the one containing it cut at r_outer).
LipIntegrand IntegrateLip(const DrillGeometry& drill, const DrillingMaterial& material,
                          double feed_per_rev, double r_outer, const ForceModelOptions& options);

/// Where the drill is in the cut.
struct DrillState {
  double feed_per_rev{0.1e-3};   // f [m/rev]
  double penetration{1.0};       // axial advance since the chisel touched [m]
  double tilt{0.0};              // angle between drill axis and hole axis [rad]
  double spindle_angle{0.0};     // angle of lip 1 in the drill frame, from x_d [rad]
};

/// Loads on the drill (the reaction of the work piece) in the drill frame
/// (z_d along the drill axis, pointing into the hole).
struct DrillForces {
  double thrust{0.0};            // pushes the drill back, along -z_d [N]
  double torque{0.0};            // resists the spindle, about -z_d [N·m]
  Eigen::Vector2d radial{Eigen::Vector2d::Zero()};  // net in-plane force (x_d, y_d) [N]
  double engaged_radius{0.0};    // outer engaged radius of the full lip [m]
  double short_lip_radius{0.0};  // outer radius of the shorter (tilted) lip [m]
  bool fully_engaged{false};
};

/// Engaged lip radius after an axial penetration d (seed 003 eq. 6):
/// Delta = d tan p along the lip, r = sqrt((sqrt(r_c^2 - w_t^2) + Delta)^2 + w_t^2),
/// capped at D/2.
double EngagedRadius(const DrillGeometry& drill, double penetration);
/// Outer radius of the shorter lip of a drill tilted by `tilt` (seed eq. 7):
/// r_q = r sin B / sin C with A = tilt, B = pi/2 - p, C = pi - A - B.
double TiltedLipRadius(const DrillGeometry& drill, double r, double tilt);

/// Thrust, torque and in-plane imbalance of the whole drill (all lips and the
/// chisel edge) at `state`. With a tilt one lip cuts to the engaged radius,
/// the other (for two lips; every second one otherwise) to r_q; the net
/// radial force then points from the axis towards the short lip and turns
/// with the spindle (1x spindle frequency).
/// @throws std::invalid_argument for an invalid geometry, material or state.
DrillForces ComputeDrillForces(const DrillGeometry& drill, const DrillingMaterial& material,
                               const DrillState& state, const ForceModelOptions& options = {});

/// Chisel-edge loads (both halves) of the kOrthogonal model: orthogonal
/// cutting of width r_c per half, chip thickness f / lips, rake
/// material.chisel_rake_angle, Merchant-type shear and friction angles as for
/// the lips. Returns {thrust, torque, 0}.
LipIntegrand ChiselOrthogonal(const DrillGeometry& drill, const DrillingMaterial& material,
                              double feed_per_rev);

}  // namespace robomach::drilling
