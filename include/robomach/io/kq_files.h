#pragma once
// kq-identify's outputs (docs/kq-identify.md): the residuals of an
// identification, its summary JSON, and a D-optimal load-test plan.

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "robomach/identification/joint_stiffness.h"
#include "robomach/identification/test_plan.h"

namespace robomach::io {

/// `case_id,pose_id,dx_mm,dy_mm,dz_mm,pred_dx_mm,...,rx_mm,ry_mm,rz_mm,r_mm,r_over_sigma,outlier`,
/// one row per load case (measured, predicted, residual displacement).
/// Atomic.
void WriteKqResidualsCsv(const std::string& path, const identification::JointStiffnessResult& result,
                         const std::vector<identification::LoadCase>& cases);

/// The summary JSON (docs/formats.md §4.1): status and solver message, the
/// stiffness of every joint with its standard deviation, 95 % interval,
/// relative std, start, determination, variance inflation and trade-offs
/// (1-based joints), the correlation matrix, the residual statistics, the
/// advice, the outliers and every case's residual [mm].
nlohmann::json KqSummaryJson(const identification::JointStiffnessResult& result);

/// What a plan file records about how it was made.
struct LoadTestPlanHeader {
  int num_postures{0};
  std::string robot_config;                        // path of the robot config
  double tracker_noise_mm{0.0};
  std::vector<double> masses_kg;
  std::optional<Eigen::Vector3d> load_point;        // tip frame [m]; none: the TCP
  std::optional<Eigen::Vector3d> target;            // tip frame [m]; none: the TCP
  /// How the postures were chosen, in the first line ("D-optimal load
  /// tests", or a targeted plan's "load tests for the <quantity> at ...").
  std::string design{"D-optimal load tests"};
  /// More `# key: value` lines after the target (a targeted plan's target
  /// file, quantity and promised half-widths).
  std::vector<std::pair<std::string, std::string>> more;
};

/// The plan: `# key: value` lines (log det of the information, the noise,
/// masses, load point and target, the expected standard deviation of each
/// joint's stiffness), then one row per load: pose_id, q<i>_deg, the rope
/// direction, the load point and the pulley [mm]. "-" is stdout; atomic.
void WriteLoadTestPlanCsv(const std::string& path, const identification::TestPlan& plan,
                          const LoadTestPlanHeader& header);

/// A plan file read back (tracker-synth --plan): its postures in file
/// order with their rope directions' pulleys, and its `# key: value` lines
/// (load_point_mm and target_mm among them).
struct LoadTestPlanFile {
  std::vector<std::string> pose_ids;
  std::vector<Eigen::VectorXd> q;                     // [rad], per posture
  std::vector<std::vector<Eigen::Vector3d>> pulleys;  // [m], per posture, per rope direction
  std::map<std::string, std::string> metadata;
};

/// Reads the plan CSV of WriteLoadTestPlanCsv (columns pose_id,
/// q<i>_deg and pulley_x_mm..pulley_z_mm are used; the rows of one posture
/// must be adjacent).
/// @throws InputError with file:line:column.
LoadTestPlanFile ReadLoadTestPlanCsv(const std::string& path, int num_joints);

}  // namespace robomach::io
