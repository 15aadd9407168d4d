#include "robomach/io/prediction_files.h"

#include <cmath>

#include <algorithm>
#include <stdexcept>

#include "robomach/common/frames.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

DirectionPairs AllDirectionPairs() {
  DirectionPairs p;
  for (int r = 0; r < 3; ++r) {
    for (int e = 0; e < 3; ++e) p.emplace_back(r, e);
  }
  return p;
}

DirectionPairs ParseDirectionPairs(const std::string& text) {
  if (text == "all") return AllDirectionPairs();
  DirectionPairs out;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t comma = text.find(',', pos);
    if (comma == std::string::npos) comma = text.size();
    const std::string item = text.substr(pos, comma - pos);
    // The one axis parser (a capital too); the pair's message for a bad one.
    auto axis = [&](char c) {
      try {
        return static_cast<int>(ParseAxis(std::string(1, c)));
      } catch (const std::invalid_argument&) {
        throw std::invalid_argument("direction pair '" + item +
                                    "': expected two of x, y, z such as xx or xy");
      }
    };
    if (item.size() != 2) {
      throw std::invalid_argument("direction pair '" + item +
                                  "': expected two of x, y, z such as xx or xy");
    }
    const std::pair<int, int> pair(axis(item[0]), axis(item[1]));
    if (std::find(out.begin(), out.end(), pair) != out.end()) {
      throw std::invalid_argument("direction pair '" + item + "' is given twice");
    }
    out.push_back(pair);
    pos = comma + 1;
  }
  return out;
}

void WritePredictedFrfCsv(const std::string& path, const std::vector<PosturePrediction>& predictions,
                          const DirectionPairs& pairs) {
  WriteFileAtomically(path, [&](std::ostream& os) { WritePredictedFrfCsv(os, predictions, pairs); });
}

void WritePredictedFrfCsv(std::ostream& os, const std::vector<PosturePrediction>& predictions,
                          const DirectionPairs& pairs) {
  {
    os << "# quantity: receptance\n";
    os << "# written by robomach frf-predict; receptance in m/N, directions in the robot base frame\n";
    os << "pose_id,response,excitation,freq_hz,re,im\n";
    for (const auto& p : predictions) {
      for (const auto& [r, e] : pairs) {
        for (Eigen::Index i = 0; i < p.freq_hz.size(); ++i) {
          const std::complex<double> h = p.H[i](r, e);
          os << p.pose_id << ',' << "xyz"[r] << ',' << "xyz"[e] << ',' << FormatDouble(p.freq_hz(i))
             << ',' << FormatDouble(h.real()) << ',' << FormatDouble(h.imag()) << '\n';
        }
      }
    }
  }
}

void WriteModalTableCsv(const std::string& path, const std::vector<std::string>& pose_ids,
                        const std::vector<std::vector<dynamics::Mode>>& modes,
                        const std::vector<dynamics::PostureModeIntervals>* intervals) {
  WriteFileAtomically(path, [&](std::ostream& os) {
    os << "pose_id,mode,freq_hz,damping_ratio,modal_mass_kg,ux,uy,uz";
    if (intervals) {
      os << ",freq_hz_lower,freq_hz_upper,damping_ratio_lower,damping_ratio_upper,peak_receptance_m_per_N,"
            "peak_receptance_m_per_N_lower,peak_receptance_m_per_N_upper,interval_method";
    }
    os << '\n';
    for (size_t p = 0; p < pose_ids.size(); ++p) {
      for (size_t k = 0; k < modes[p].size(); ++k) {
        const dynamics::Mode& m = modes[p][k];
        os << pose_ids[p] << ',' << k + 1 << ',' << FormatDouble(m.freq_hz) << ','
           << FormatDouble(m.damping_ratio) << ',' << FormatDouble(m.modal_mass_kg) << ','
           << FormatDouble(m.shape_T(0)) << ',' << FormatDouble(m.shape_T(1)) << ','
           << FormatDouble(m.shape_T(2));
        if (intervals) {
          const dynamics::PostureModeIntervals& pi = (*intervals)[p];
          if (k < pi.modes.size()) {
            const dynamics::ModeIntervals& mi = pi.modes[k];
            os << ',' << FormatCell(mi.freq_hz.lower) << ',' << FormatCell(mi.freq_hz.upper) << ','
               << FormatCell(mi.damping_ratio.lower) << ',' << FormatCell(mi.damping_ratio.upper) << ','
               << FormatCell(mi.peak_receptance_m_per_N.value) << ',' << FormatCell(mi.peak_receptance_m_per_N.lower)
               << ',' << FormatCell(mi.peak_receptance_m_per_N.upper) << ','
               << dynamics::ToString(pi.propagation.method_used);
          } else {
            os << ",,,,,,,,";
          }
        }
        os << '\n';
      }
    }
  });
}

namespace {

// frf-predict --summary: matrices as arrays of rows, non-finite entries null.

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

}  // namespace robomach::io
