#include "robomach/io/kq_files.h"

#include <sstream>

#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

void WriteKqResidualsCsv(const std::string& path, const identification::JointStiffnessResult& r,
                         const std::vector<identification::LoadCase>& cases) {
  WriteFileAtomically(path, [&](std::ostream& os) {
    os << "case_id,pose_id,dx_mm,dy_mm,dz_mm,pred_dx_mm,pred_dy_mm,pred_dz_mm,rx_mm,ry_mm,rz_mm,r_mm,"
          "r_over_sigma,outlier\n";
    for (size_t c = 0; c < r.residuals.size(); ++c) {
      const auto& x = r.residuals[c];
      os << x.case_id << "," << cases[c].pose_id;
      for (const Eigen::Vector3d* v : {&x.measured, &x.predicted, &x.residual}) {
        for (int a = 0; a < 3; ++a) os << "," << FormatDouble(MToMm((*v)(a)));
      }
      os << "," << FormatDouble(MToMm(x.norm)) << "," << FormatDouble(x.normalized) << ","
         << (x.outlier ? 1 : 0) << "\n";
    }
  });
}

void WriteLoadTestPlanCsv(const std::string& path, const identification::TestPlan& plan,
                          const LoadTestPlanHeader& h) {
  const int num_joints = static_cast<int>(plan.expected_std_dev.size());
  std::ostringstream csv;
  csv << "# kq-identify --plan " << h.num_postures << ": D-optimal load tests for " << h.robot_config << "\n";
  csv << "# log_det_information: " << FormatDouble(plan.log_det_information) << "\n";
  csv << "# tracker_noise_mm: " << FormatDouble(h.tracker_noise_mm) << "\n";
  csv << "# masses_kg:";
  for (double m : h.masses_kg) csv << " " << FormatDouble(m);
  csv << "\n";
  auto point = [&](const char* key, const std::optional<Eigen::Vector3d>& p) {
    csv << "# " << key << ": ";
    if (!p) csv << "tcp";
    else csv << FormatDouble(MToMm(p->x())) << "," << FormatDouble(MToMm(p->y())) << ","
             << FormatDouble(MToMm(p->z()));
    csv << "\n";
  };
  point("load_point_mm", h.load_point);
  point("target_mm", h.target);
  for (int j = 0; j < num_joints; ++j) {
    csv << "# expected_std_kq" << j + 1 << "_Nm_per_rad: " << FormatDouble(plan.expected_std_dev(j)) << "\n";
  }
  csv << "pose_id";
  for (int j = 0; j < num_joints; ++j) csv << ",q" << j + 1 << "_deg";
  csv << ",rope_ux,rope_uy,rope_uz,load_x_mm,load_y_mm,load_z_mm,pulley_x_mm,pulley_y_mm,pulley_z_mm\n";
  for (const auto& l : plan.loads) {
    csv << l.pose_id;
    for (int j = 0; j < l.q.size(); ++j) csv << "," << FormatDouble(RadToDeg(l.q(j)));
    for (int a = 0; a < 3; ++a) csv << "," << FormatDouble(l.rope_direction(a));
    for (int a = 0; a < 3; ++a) csv << "," << FormatDouble(MToMm(l.p_load(a)));
    for (int a = 0; a < 3; ++a) csv << "," << FormatDouble(MToMm(l.p_pulley(a)));
    csv << "\n";
  }
  WriteFileAtomically(path.empty() ? "-" : path, csv.str());
}

}  // namespace robomach::io
