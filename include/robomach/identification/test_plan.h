#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/run_status.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/identification/joint_stiffness.h"
#include "robomach/identification/load_case.h"

namespace robomach::identification {

/// Fisher information of log-stiffness, θ_i = log k_i, for load cases with
/// displacement noise σ_D per coordinate [m], at stiffness `kq`
/// [N·m/rad]: I = Σ_cases Gᵀ G / σ_D², G = ∂D/∂θ = −A diag(c). Its inverse
/// is the covariance of θ, whose diagonal is (σ_k / k)².
Eigen::MatrixXd LogStiffnessInformation(const dynamics::RobotModel& model,
                                        const std::vector<LoadCase>& cases,
                                        const Eigen::VectorXd& kq, double sigma_displacement);

/// Options of PlanLoadTests (defaults for the seed's rope set-up).
struct PlanOptions {
  int num_postures{12};
  std::vector<double> masses_kg{10.0, 20.0, 30.0};   // each planned direction gets every mass
  int directions_per_posture{2};                      // rope directions (pulley positions) per posture
  double tracker_noise{1e-5};                         // 1 sigma per coordinate [m]
  double floor_z{0.0};                                // floor height in B [m]
  double min_load_height{0.3};                        // load point above the floor [m]
  double max_rope_angle{0.7853981633974483};          // rope from vertical [rad] (45°)
  double joint_limit_margin{0.08726646259971647};     // keep this far inside the limits [rad] (5°)
  /// Random feasible postures the design chooses from; 0 = automatic,
  /// max(400, 4 · num_postures) (kq-identify --plan's choice).
  int num_candidate_postures{0};
  int num_azimuths{8};                                // candidate rope azimuths per tilt
  unsigned seed{1};
  std::optional<Eigen::Vector3d> p_load_tip;          // [m] in the tip frame; nullopt = TCP
  std::optional<Eigen::Vector3d> p_target_tip;        // [m] in the tip frame; nullopt = TCP
  /// A joint whose expected relative standard deviation exceeds this is
  /// weakly determined (the identification's own threshold).
  double weak_relative_std{IdentificationOptions{}.weak_relative_std};
  /// A targeted design (issue #37 §5): columns g_t = ∂ ln y_t / ∂ ln k (one
  /// row per joint) of the quantities y_t the user cares about, such as the
  /// lowest natural frequency or the safe depth at the postures of a work
  /// region. Non-empty: the postures and directions minimise
  /// Σ_t g_tᵀ I⁻¹ g_t, the sum of the targets' relative variances (a linear,
  /// "L-optimal" design [Atkinson & Donev 1992, ch. 10]), instead of
  /// maximising log det I.
  Eigen::MatrixXd target_gradients;
  /// With target_gradients: design for them (true), or keep the D-optimal
  /// design and only report the targets' widths (false: the comparison).
  bool design_for_targets{true};
  /// The relative half-width of the targets' intervals (at
  /// target_confidence) the user wants, e.g. 0.05; 0: none. The plan says
  /// how many of its postures reach it.
  double target_half_width{0.0};
  double target_confidence{0.95};

  /// num_postures, directions_per_posture and num_azimuths >= 1; masses_kg
  /// not empty, each > 0; tracker_noise > 0; max_rope_angle in [0, pi/2);
  /// num_candidate_postures 0 or >= num_postures; joint_limit_margin >= 0;
  /// weak_relative_std > 0; target_gradients finite; target_half_width
  /// finite and >= 0; target_confidence in (0, 1).
  /// @throws OptionError naming the field, the violated bound and the value
  ///   ("PlanOptions::num_postures: expected at least 1, got 0").
  void Validate() const;
};

/// Whether a plan must determine `joint` (0-based): always for a D-optimal
/// plan; for a targeted one when some target's gradient on it exceeds 1e-3
/// of the largest (a joint no target feels is neither flagged nor warned about).
bool TargetsDependOnJoint(const PlanOptions& options, int joint);

/// One planned rope direction at one posture.
struct PlannedLoad {
  std::string pose_id;
  Eigen::VectorXd q;                   // [rad]
  Eigen::Vector3d rope_direction;      // unit vector in B, from the load point to the pulley
  Eigen::Vector3d p_load;              // load point in B [m]
  Eigen::Vector3d p_pulley;            // where the rope meets the floor, in B [m]
};

/// Flagged (its `verdict`, kq-identify --plan's exit 3) with one finding per
/// joint the planned tests cannot determine; weakly determined joints are in
/// expected_determination, not findings (more postures fix them).
struct TestPlan {
  RunFindings verdict;
  RunStatus status() const { return verdict.status(); }
  std::vector<PlannedLoad> loads;        // num_postures × directions_per_posture
  std::vector<LoadCase> cases;           // the loads with every mass (no displacement)
  double log_det_information{NAN};       // D-optimality index, log det I (θ = log k)
  Eigen::VectorXd expected_relative_std; // √diag(I⁻¹) [-]; +inf where I is singular
  Eigen::VectorXd expected_std_dev;      // [N·m/rad] at the model's stiffness
  int num_candidates{0};                 // feasible candidate postures found
  /// Per joint, by DeterminationFromRelativeStd(expected_relative_std).
  std::vector<Determination> expected_determination;
  /// With target_gradients: each target's expected relative standard
  /// deviation √(g_tᵀ I⁻¹ g_t) with the whole plan; the largest target's
  /// relative half-width (z √(g_tᵀ I_k⁻¹ g_t), z the target_confidence
  /// quantile) with the first k postures of the plan, k = 1..num_postures
  /// (+inf while some target is not determined).
  Eigen::VectorXd expected_target_relative_std;
  std::vector<double> target_half_width_by_postures;
  /// With target_half_width: the fewest of the plan's first postures that
  /// bring every target within it (0: the plan does not), and, when the plan
  /// does not, about how many postures would (a variance falling as 1/k from
  /// the whole plan's; 0 when no target is determined).
  int postures_for_target_width{0};
  int postures_for_target_width_estimate{0};
};

/// Chooses postures (within the joint limits with a margin) and rope
/// directions (downward, within max_rope_angle of vertical, reaching the
/// floor from a load point at least min_load_height above it) that maximise
/// log det of the Fisher information of log-stiffness at the model's
/// stiffness (D-optimal design [Atkinson & Donev 1992]), or with
/// target_gradients minimise the targets' summed relative variance:
/// greedy selection followed by Fedorov-style exchange passes over the
/// random candidate set. A plan that misses target_half_width is flagged.
/// Each chosen posture gets `directions_per_posture` directions and every
/// mass. Deterministic for a given seed.
/// @throws std::invalid_argument for invalid options.
///
/// - [Atkinson & Donev 1992] A. C. Atkinson, A. N. Donev, Optimum
///   Experimental Designs, Oxford University Press, 1992.
TestPlan PlanLoadTests(const dynamics::RobotModel& model, const PlanOptions& options);

}  // namespace robomach::identification
