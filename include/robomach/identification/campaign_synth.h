#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "robomach/dynamics/robot_model.h"
#include "robomach/identification/load_case.h"

namespace robomach::identification {

/// Options of a simulated tracker campaign (the seed's rope set-up).
struct CampaignOptions {
  /// The hung masses [kg]: at least one, each finite and > 0.
  std::vector<double> masses_kg{10.0, 20.0, 30.0};
  /// Pulley positions on the floor, in B [m]: one rope direction per pulley.
  std::vector<Eigen::Vector3d> pulleys{Eigen::Vector3d(1.6, -1.2, 0.0), Eigen::Vector3d(1.6, 1.2, 0.0)};
  double tracker_noise{1e-5};       // 1 sigma per measured coordinate [m]; finite, >= 0 (0: exact)
  unsigned seed{1};
  int num_outliers{0};              // cases whose loaded position gets a gross error; >= 0
  double outlier_size{1e-3};        // length of that error [m]; finite, >= 0
  /// Load point and target in the tip frame [m]; nullopt = the TCP. The
  /// defaults (a bracket 150 mm off the tool axis, a target 120 mm off it)
  /// load and observe every joint, the last included.
  std::optional<Eigen::Vector3d> p_load_tip{Eigen::Vector3d(0.15, 0.0, 0.10)};
  std::optional<Eigen::Vector3d> p_target_tip{Eigen::Vector3d(0.0, 0.12, 0.05)};
  /// Rope points A and B lie this far from the load point along the rope
  /// [m]: 0 <= rope_A_distance < rope_B_distance (A to B is the pull's
  /// direction, identification's RopeForce).
  double rope_A_distance{0.1};
  double rope_B_distance{0.6};
  /// CampaignPostures only: the load point's horizontal distance from the
  /// base axis is at least this [m], >= 0. Load tests are made in the
  /// machining workspace with the arm reaching out, where the loads' lever
  /// arms about joints 1-3 (and so the information on them) are large.
  double min_reach{1.5};
  /// Write the load as force components instead of mass and rope points.
  bool force_form{false};

  /// The bounds above.
  /// @throws OptionError naming the field, its value and the bound
  ///   ("rope_B_distance: expected a value > rope_A_distance 0.1, got 0.05").
  void Validate() const;
};

/// Simulates a campaign: for every posture, pulley and mass, the static
/// deflection of the target (SolveStaticDeflection, the large-displacement
/// second method, with stiffness `kq`), and the tracker readings p0, p1, A, B
/// with Gaussian noise (seeded std::mt19937). Outliers, if any, are added to
/// p1 of distinct random cases in random directions.
/// @param outlier_cases  if not null, receives the indices of the outlier cases.
/// @throws std::invalid_argument if a pulley is not below the load point.
std::vector<TrackerMeasurement> SimulateCampaign(const dynamics::RobotModel& model,
                                                 const std::vector<std::string>& pose_ids,
                                                 const std::vector<Eigen::VectorXd>& postures,
                                                 const Eigen::VectorXd& kq,
                                                 const CampaignOptions& options,
                                                 std::vector<int>* outlier_cases = nullptr);

/// The same with pulleys given per posture (e.g. from a TestPlan's loads);
/// `options.pulleys` is ignored.
std::vector<TrackerMeasurement> SimulateCampaign(
    const dynamics::RobotModel& model, const std::vector<std::string>& pose_ids,
    const std::vector<Eigen::VectorXd>& postures,
    const std::vector<std::vector<Eigen::Vector3d>>& pulleys_per_posture, const Eigen::VectorXd& kq,
    const CampaignOptions& options, std::vector<int>* outlier_cases = nullptr);

/// `count` random postures within the joint limits (5° margin), with joint 1
/// within ±45° of the pulleys' side (x > 0), the load point at least 0.3 m
/// above the floor (z = 0) and `options.min_reach` from the base axis, and
/// every rope within 60° of vertical. Seeded.
std::vector<Eigen::VectorXd> CampaignPostures(const dynamics::RobotModel& model, int count,
                                              const CampaignOptions& options, unsigned seed);

}  // namespace robomach::identification
