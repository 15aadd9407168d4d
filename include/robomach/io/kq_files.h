#pragma once
// kq-identify's CSV outputs (docs/kq-identify.md): the residuals of an
// identification, and a D-optimal load-test plan.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/identification/joint_stiffness.h"
#include "robomach/identification/test_plan.h"

namespace robomach::io {

/// `case_id,pose_id,dx_mm,dy_mm,dz_mm,pred_dx_mm,...,rx_mm,ry_mm,rz_mm,r_mm,r_over_sigma,outlier`,
/// one row per load case (measured, predicted, residual displacement).
/// Atomic.
void WriteKqResidualsCsv(const std::string& path, const identification::JointStiffnessResult& result,
                         const std::vector<identification::LoadCase>& cases);

/// What a plan file records about how it was made.
struct LoadTestPlanHeader {
  int num_postures{0};
  std::string robot_config;                        // path of the robot config
  double tracker_noise_mm{0.0};
  std::vector<double> masses_kg;
  std::optional<Eigen::Vector3d> load_point;        // tip frame [m]; none: the TCP
  std::optional<Eigen::Vector3d> target;            // tip frame [m]; none: the TCP
};

/// The plan: `# key: value` lines (log det of the information, the noise,
/// masses, load point and target, the expected standard deviation of each
/// joint's stiffness), then one row per load: pose_id, q<i>_deg, the rope
/// direction, the load point and the pulley [mm]. "-" is stdout; atomic.
void WriteLoadTestPlanCsv(const std::string& path, const identification::TestPlan& plan,
                          const LoadTestPlanHeader& header);

}  // namespace robomach::io
