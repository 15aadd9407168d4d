#include "robomach/io/tip_dynamics_files.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <map>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/frf_files.h"

namespace robomach::io {

std::vector<FrfSetOfPose> ReadTipFrfs(const std::string& path, const std::string& default_pose_id,
                                      std::vector<std::string>* warnings, std::vector<std::string>* notes) {
  // The measured-FRF reader (CSV or UFF58 by extension) validates every
  // FRF; here they are grouped per posture onto one shared grid.
  FrfReadResult read = ReadFrfFile(path, default_pose_id);
  if (warnings) warnings->insert(warnings->end(), read.warnings.begin(), read.warnings.end());
  if (notes) notes->insert(notes->end(), read.notes.begin(), read.notes.end());
  if (read.frfs.empty()) throw InputError({path, 0, 0}, "no FRF in the file");
  std::vector<FrfSetOfPose> out;
  for (const std::string& pose : read.frfs.pose_ids()) {
    FrfSetOfPose set;
    set.pose_id = pose;
    set.source = path;
    const dynamics::FrfSet frfs = read.frfs.ForPose(pose);
    const auto keys = frfs.keys();
    const dynamics::Frf& first = frfs.at(keys.front());
    set.freq_hz = first.freq_hz();
    set.H.assign(first.size(), Eigen::Matrix3cd::Zero());
    for (const dynamics::FrfKey& key : keys) {
      const dynamics::Frf& frf = frfs.at(key);
      if (frf.size() != first.size() || frf.freq_hz() != first.freq_hz()) {
        throw InputError({path, 0, 0}, "FRF " + key.ToString() + " uses another frequency grid than FRF " +
                                           keys.front().ToString() +
                                           "; the FRFs of one posture must share one grid");
      }
      const int i = static_cast<int>(key.response), j = static_cast<int>(key.excitation);
      set.present[i][j] = true;
      for (int k = 0; k < frf.size(); ++k) set.H[k](i, j) = frf.receptance()(k);
    }
    out.push_back(std::move(set));
  }
  return out;
}

std::vector<ModalTableEntry> ReadModalTable(const std::string& path) {
  const CsvTable t = CsvTable::ReadFile(path);
  for (const char* c : {"pose_id", "freq_hz", "damping_ratio", "ux", "uy", "uz"}) t.RequireColumn(c, "modal");
  const bool has_m = t.HasColumn("modal_mass_kg"), has_k = t.HasColumn("modal_stiffness_N_per_m");
  if (has_m == has_k) {
    throw InputError({path, t.header_line(), 0},
                     "expected exactly one of the columns modal_mass_kg and modal_stiffness_N_per_m");
  }
  std::map<std::string, std::vector<int>> rows;
  std::vector<std::string> order;
  std::map<std::pair<std::string, std::string>, int> seen;  // (pose, mode) -> line
  for (int r = 0; r < t.num_rows(); ++r) {
    const std::string pose = t.Text(r, "pose_id");
    if (t.HasColumn("mode")) {
      // The same mode twice would be superposed twice: a silent error.
      const std::string mode = t.Text(r, "mode");
      const auto [it, fresh] = seen.emplace(std::pair{pose, mode}, t.line(r));
      if (!fresh) {
        throw t.ErrorAt(r, "mode", "mode " + mode + " of posture " + pose +
                                       " appears twice (first on line " + std::to_string(it->second) + ")");
      }
    }
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

std::vector<std::string> ReceptanceUnitFindings(const std::vector<FrfSetOfPose>& sets) {
  std::vector<std::string> out;
  for (const FrfSetOfPose& s : sets) {
    if (std::string f = stability::TipFrfsUnitFinding(s); !f.empty()) out.push_back(std::move(f));
  }
  return out;
}

}  // namespace robomach::io
