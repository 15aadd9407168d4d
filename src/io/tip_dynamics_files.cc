#include "robomach/io/tip_dynamics_files.h"

#include <cmath>
#include <complex>
#include <map>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/csv_table.h"

namespace robomach::io {

namespace {

int Direction(const CsvTable& t, int row, const char* column) {
  const std::string s = t.Text(row, column);
  if (s == "x") return 0;
  if (s == "y") return 1;
  if (s == "z") return 2;
  throw t.ErrorAt(row, column, "expected x, y or z, got \"" + s + "\"");
}

}  // namespace

std::vector<FrfSetOfPose> ReadFrfCsv(const std::string& path) {
  const CsvTable t = CsvTable::ReadFile(path);
  for (const char* c : {"pose_id", "response", "excitation", "freq_hz", "re", "im"}) t.RequireColumn(c);
  std::string quantity = "receptance";
  if (auto it = t.metadata().find("quantity"); it != t.metadata().end()) quantity = it->second;
  if (quantity != "receptance" && quantity != "mobility" && quantity != "accelerance") {
    throw InputError({path, 0, 0}, "# quantity: expected receptance, mobility or accelerance, got \"" +
                                       quantity + "\"");
  }
  struct Series {
    std::vector<double> f;
    std::vector<std::complex<double>> h;
    int first_line = 0;
  };
  std::map<std::string, std::map<std::pair<int, int>, Series>> by_pose;
  std::vector<std::string> order;
  std::map<std::string, std::pair<int, int>> last_pair;  // to detect a pair given in two blocks
  for (int r = 0; r < t.num_rows(); ++r) {
    const std::string pose = t.Text(r, "pose_id");
    const int i = Direction(t, r, "response"), j = Direction(t, r, "excitation");
    const double f = t.Number(r, "freq_hz");
    if (f < 0.0) throw t.ErrorAt(r, "freq_hz", "expected a frequency >= 0");
    std::complex<double> h(t.Number(r, "re"), t.Number(r, "im"));
    if (quantity != "receptance") {
      if (f == 0.0) throw t.ErrorAt(r, "freq_hz", "a " + quantity + " cannot be converted to receptance at 0 Hz");
      const double w = HzToRadPerSec(f);
      h = quantity == "mobility" ? h / std::complex<double>(0.0, w) : -h / (w * w);
    }
    if (!by_pose.count(pose)) order.push_back(pose);
    Series& s = by_pose[pose][{i, j}];
    if (s.f.empty()) s.first_line = t.line(r);
    if (!s.f.empty() && !(f > s.f.back())) {
      throw t.ErrorAt(r, "freq_hz", "frequencies of FRF " + pose + " " + "xyz"[i] + "xyz"[j] +
                                        " must be strictly increasing (previous " + std::to_string(s.f.back()) +
                                        " Hz)");
    }
    s.f.push_back(f);
    s.h.push_back(h);
  }
  if (order.empty()) throw InputError({path, 0, 0}, "no FRF lines (the file has a header only)");
  std::vector<FrfSetOfPose> out;
  for (const std::string& pose : order) {
    FrfSetOfPose set;
    set.pose_id = pose;
    set.source = path;
    const auto& pairs = by_pose[pose];
    const Series& first = pairs.begin()->second;
    set.freq_hz = Eigen::Map<const Eigen::VectorXd>(first.f.data(), first.f.size());
    set.H.assign(first.f.size(), Eigen::Matrix3cd::Zero());
    for (const auto& [ij, s] : pairs) {
      if (s.f != first.f) {
        throw InputError({path, s.first_line, 0},
                         "FRF " + pose + " " + "xyz"[ij.first] + "xyz"[ij.second] +
                             " uses another frequency grid than FRF " + pose + " " +
                             "xyz"[pairs.begin()->first.first] + "xyz"[pairs.begin()->first.second] +
                             " (line " + std::to_string(first.first_line) +
                             "); the FRFs of one posture must share one grid");
      }
      set.present[ij.first][ij.second] = true;
      for (size_t k = 0; k < s.h.size(); ++k) set.H[k](ij.first, ij.second) = s.h[k];
    }
    out.push_back(std::move(set));
  }
  return out;
}

std::vector<ModalTableEntry> ReadModalTable(const std::string& path) {
  const CsvTable t = CsvTable::ReadFile(path);
  for (const char* c : {"pose_id", "freq_hz", "damping_ratio", "ux", "uy", "uz"}) t.RequireColumn(c);
  const bool has_m = t.HasColumn("modal_mass_kg"), has_k = t.HasColumn("modal_stiffness_N_per_m");
  if (has_m == has_k) {
    throw InputError({path, t.header_line(), 0},
                     "expected exactly one of the columns modal_mass_kg and modal_stiffness_N_per_m");
  }
  std::map<std::string, std::vector<int>> rows;
  std::vector<std::string> order;
  for (int r = 0; r < t.num_rows(); ++r) {
    const std::string pose = t.Text(r, "pose_id");
    if (!rows.count(pose)) order.push_back(pose);
    rows[pose].push_back(r);
  }
  if (order.empty()) throw InputError({path, 0, 0}, "no modes (the file has a header only)");
  std::vector<ModalTableEntry> out;
  for (const std::string& pose : order) {
    ModalTableEntry e;
    e.pose_id = pose;
    const auto& rs = rows[pose];
    const int n = static_cast<int>(rs.size());
    e.modes.omega_rad_s.resize(n);
    e.modes.zeta.resize(n);
    e.modes.p.resize(3, n);
    for (int k = 0; k < n; ++k) {
      const int r = rs[k];
      const double f = t.Number(r, "freq_hz");
      if (!(f > 0.0)) throw t.ErrorAt(r, "freq_hz", "expected a natural frequency > 0");
      const double z = t.Number(r, "damping_ratio");
      if (!(z >= 0.0 && z < 1.0)) throw t.ErrorAt(r, "damping_ratio", "expected a damping ratio in [0, 1)");
      const double w = HzToRadPerSec(f);
      double m = 0.0;
      if (has_m) {
        m = t.Number(r, "modal_mass_kg");
        if (!(m > 0.0)) throw t.ErrorAt(r, "modal_mass_kg", "expected a modal mass > 0");
      } else {
        const double k_s = t.Number(r, "modal_stiffness_N_per_m");
        if (!(k_s > 0.0)) throw t.ErrorAt(r, "modal_stiffness_N_per_m", "expected a modal stiffness > 0");
        m = k_s / (w * w);
      }
      const Eigen::Vector3d u(t.Number(r, "ux"), t.Number(r, "uy"), t.Number(r, "uz"));
      if (!(u.norm() > 0.0)) throw t.ErrorAt(r, "ux", "expected a non-zero mode shape (ux, uy, uz)");
      e.modes.omega_rad_s(k) = w;
      e.modes.zeta(k) = z;
      e.modes.p.col(k) = u.normalized() / std::sqrt(m);
    }
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace robomach::io
