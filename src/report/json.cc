#include "robomach/report/posture_json.h"

#include <cmath>

#include "robomach/common/version.h"

namespace robomach::report {
namespace {

nlohmann::json Matrix(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      row.push_back(std::isfinite(m(r, c)) ? nlohmann::json(m(r, c)) : nlohmann::json(nullptr));
    }
    rows.push_back(row);
  }
  return rows;
}

nlohmann::json Vector(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    a.push_back(std::isfinite(v(i)) ? nlohmann::json(v(i)) : nlohmann::json(nullptr));
  }
  return a;
}

}  // namespace

nlohmann::json PostureToJson(const std::string& pose_id, const dynamics::PostureDynamics& d) {
  nlohmann::json j;
  j["pose_id"] = pose_id;
  // The matrices mix units by row and column; say which, once per posture.
  j["units"] = {
      {"M_q", "kg·m² (revolute joints: N·m·s²/rad)"},
      {"K_q", "N·m/rad"},
      {"C_q", "N·m·s/rad"},
      {"J_BT", "rows 1-3 m/rad, rows 4-6 rad/rad"},
      {"M_X", "blocks [kg, kg·m; kg·m, kg·m²] for [x y z; rx ry rz]"},
      {"K_X", "blocks [N/m, N/rad; N, N·m/rad]"},
      {"C_X", "blocks [N·s/m, N·s/rad; N·s, N·m·s/rad]"},
      {"static_compliance_m_per_N", "m/N"}};
  j["q_rad"] = Vector(d.q);
  j["tcp_position_m"] = Vector(d.X_BT.translation());
  j["tcp_rotation"] = Matrix(d.X_BT.linear());
  j["jacobian_rows"] = "[vx, vy, vz, wx, wy, wz]; columns: joints";
  j["J_BT"] = Matrix(d.J_BT);
  j["jacobian_condition"] = std::isfinite(d.jacobian_condition) ? nlohmann::json(d.jacobian_condition)
                                                                : nlohmann::json(nullptr);
  j["near_singular"] = d.near_singular;
  j["M_q"] = Matrix(d.M_q());
  j["K_q"] = Matrix(d.K_q());
  j["C_q"] = Matrix(d.C_q());
  j["num_dofs"] = d.system.M.rows();
  if (d.near_singular || !d.M_X.allFinite()) {
    j["cartesian"] = nullptr;
    j["cartesian_note"] =
        "not formed: the Jacobian is near singular (condition number above 1e5) or not square";
  } else {
    j["cartesian"] = {{"order", "[x, y, z, rx, ry, rz] at the TCP, base frame"},
                      {"M_X", Matrix(d.M_X)},
                      {"K_X", Matrix(d.K_X)},
                      {"C_X", Matrix(d.C_X)}};
  }
  j["static_compliance_m_per_N"] = Matrix(d.static_compliance);
  j["proportional_damping"] = d.proportional_damping;
  nlohmann::json modes = nlohmann::json::array();
  for (const auto& m : d.modes) {
    modes.push_back({{"freq_hz", m.freq_hz},
                     {"damping_ratio", m.damping_ratio},
                     {"modal_mass_kg", std::isfinite(m.modal_mass_kg) ? nlohmann::json(m.modal_mass_kg)
                                                                      : nlohmann::json(nullptr)},
                     {"shape_T", Vector(m.shape_T)}});
  }
  j["modes"] = modes;
  return j;
}

std::string DumpJson(const nlohmann::json& j) {
  if (!j.is_object() || j.contains("robomach_version")) return j.dump(2) + "\n";
  nlohmann::json stamped = j;
  stamped["robomach_version"] = Version();
  return stamped.dump(2) + "\n";
}

}  // namespace robomach::report
