#include "robomach/io/kq_files.h"

#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

nlohmann::json KqSummaryJson(const identification::JointStiffnessResult& r) {
  nlohmann::json j;
  j["status"] = robomach::ToString(r.status);
  j["solver_message"] = r.solver_message;
  j["num_cases"] = r.num_cases;
  auto vec = [](const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); };
  j["joint_stiffness_Nm_per_rad"] = vec(r.joint_stiffness);
  j["std_dev_Nm_per_rad"] = vec(r.std_dev);
  j["lower_95_Nm_per_rad"] = vec(r.lower_95);
  j["upper_95_Nm_per_rad"] = vec(r.upper_95);
  j["relative_std"] = vec(r.relative_std);
  j["linear_start_Nm_per_rad"] = vec(r.linear_start);
  std::vector<std::string> det;
  for (auto d : r.determination) det.push_back(identification::ToString(d));
  j["determination"] = det;
  j["variance_inflation"] = vec(r.variance_inflation);
  j["trade_off_with"] = nlohmann::json::array();
  for (const auto& t : r.trade_off_with) {
    std::vector<int> one_based;
    for (int i : t) one_based.push_back(i + 1);
    j["trade_off_with"].push_back(one_based);
  }
  j["correlation"] = nlohmann::json::array();
  for (int a = 0; a < r.correlation.rows(); ++a) j["correlation"].push_back(vec(r.correlation.row(a).transpose()));
  j["rms_residual_mm"] = MToMm(r.rms_residual);
  j["reduced_chi2"] = r.reduced_chi2;
  j["condition_number"] = r.condition_number;
  j["advice"] = r.advice;
  std::vector<std::string> out_ids;
  for (int c : r.outliers) out_ids.push_back(r.residuals[c].case_id);
  j["outliers"] = out_ids;
  j["residuals"] = nlohmann::json::array();
  for (const auto& x : r.residuals) {
    j["residuals"].push_back({{"case_id", x.case_id},
                              {"residual_mm", {MToMm(x.residual.x()), MToMm(x.residual.y()), MToMm(x.residual.z())}},
                              {"r_over_sigma", x.normalized},
                              {"outlier", x.outlier}});
  }
  return j;
}

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
  csv << "# kq-identify --plan " << h.num_postures << ": " << h.design << " for " << h.robot_config << "\n";
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
  for (const auto& [key, value] : h.more) csv << "# " << key << ": " << value << "\n";
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

LoadTestPlanFile ReadLoadTestPlanCsv(const std::string& path, int num_joints) {
  // One row per posture and rope direction, rows of one posture together.
  const CsvTable t = CsvTable::ReadFile(path);
  t.RequireColumn("pose_id", "posture");
  LoadTestPlanFile plan;
  for (int r = 0; r < t.num_rows(); ++r) {
    const std::string id = t.Text(r, "pose_id");
    if (plan.pose_ids.empty() || plan.pose_ids.back() != id) {
      for (const auto& seen : plan.pose_ids) {
        if (seen == id) throw t.ErrorAt(r, "pose_id", "rows of posture " + id + " must be adjacent");
      }
      Eigen::VectorXd q(num_joints);
      for (int j = 0; j < q.size(); ++j) q(j) = DegToRad(t.Number(r, "q" + std::to_string(j + 1) + "_deg"));
      plan.pose_ids.push_back(id);
      plan.q.push_back(q);
      plan.pulleys.emplace_back();
    }
    plan.pulleys.back().emplace_back(MmToM(t.Number(r, "pulley_x_mm")), MmToM(t.Number(r, "pulley_y_mm")),
                                     MmToM(t.Number(r, "pulley_z_mm")));
  }
  if (plan.pose_ids.empty()) throw InputError({path, 0, 0}, "no postures in the plan");
  plan.metadata = t.metadata();
  return plan;
}

}  // namespace robomach::io
