#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace robomach::identification {

/// One laser-tracker load case (formats.md §2), in SI units and radians.
///
/// The robot holds posture q; a force F acts at a point L fixed to the
/// robot's tip frame (the arm's tip, `tool0` for the KR210: origin on the
/// flange face, z along the tool axis); the tracker measures a target point
/// T, also fixed to the tip frame, before and after loading. All vectors
/// except the two tip-frame points are expressed in the base frame B, which
/// is the tracker frame.
struct LoadCase {
  std::string case_id;
  std::string pose_id;
  Eigen::VectorXd q;                      // [rad], one per joint
  Eigen::Vector3d force{Eigen::Vector3d::Zero()};         // F in B [N]
  Eigen::Vector3d displacement{Eigen::Vector3d::Zero()};  // D = p1 − p0 of the target, in B [m]
  /// Load point in the tip frame [m]; nullopt = the model's tool centre point.
  std::optional<Eigen::Vector3d> p_load_tip;
  /// Target in the tip frame [m]; nullopt = the model's tool centre point.
  std::optional<Eigen::Vector3d> p_target_tip;
  int line{0};                            // line in the source file, for messages (0 = none)
};

/// One row of a tracker file as measured (formats.md §2), in SI units: the
/// target positions before and after loading and the load in one of its two
/// forms. ToLoadCase() turns it into the model's LoadCase.
struct TrackerMeasurement {
  std::string case_id;
  std::string pose_id;
  Eigen::VectorXd q;                                // [rad]
  Eigen::Vector3d p0{Eigen::Vector3d::Zero()};      // target unloaded, in B [m]
  Eigen::Vector3d p1{Eigen::Vector3d::Zero()};      // target loaded, in B [m]
  /// Force form: F in B [N]. If absent, the rope form below is used.
  std::optional<Eigen::Vector3d> force;
  double mass_kg{0.0};                              // rope form: hanging mass [kg]
  Eigen::Vector3d rope_A{Eigen::Vector3d::Zero()};  // rope form: rope point A in B [m]
  Eigen::Vector3d rope_B{Eigen::Vector3d::Zero()};  // rope form: rope point B in B [m]
  std::optional<Eigen::Vector3d> p_load_tip;        // [m] in the tip frame
  std::optional<Eigen::Vector3d> p_target_tip;      // [m] in the tip frame
  int line{0};
};

/// The rope load of the seed experiment: `mass_kg` · 9.80665 N along the unit
/// vector from rope point A to rope point B (formats.md §2), in B [N].
/// @throws std::invalid_argument if A and B coincide (closer than 1e-9 m),
///   the mass is negative, or any value is non-finite.
Eigen::Vector3d RopeForce(double mass_kg, const Eigen::Vector3d& p_A, const Eigen::Vector3d& p_B);

/// D = p1 − p0 and the force of either load form.
/// @throws std::invalid_argument as RopeForce does.
LoadCase ToLoadCase(const TrackerMeasurement& m);
std::vector<LoadCase> ToLoadCases(const std::vector<TrackerMeasurement>& m);

}  // namespace robomach::identification
