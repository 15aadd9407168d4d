#include "robomach/calibration/modal_analysis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "robomach/common/frames.h"
#include "robomach/common/option_validate.h"

namespace robomach::calibration {
namespace {

int AxisIndex(Axis a) { return static_cast<int>(a); }

// The lines of `frf` usable under its noise model (all without one).
std::vector<char> UsableMask(const dynamics::Frf& frf, const FrfNoise* noise) {
  std::vector<char> mask(frf.size(), 1);
  if (noise && static_cast<int>(noise->usable.size()) == frf.size()) mask = noise->usable;
  for (int k = 0; k < frf.size(); ++k) {
    if (!(frf.freq_hz()(k) > 0.0)) mask[k] = 0;
  }
  return mask;
}

dynamics::Frf Prepared(const dynamics::Frf& frf, const FrfNoise* noise, const std::vector<int>& lines) {
  dynamics::Frf f = frf;
  if (noise && noise->sigma_m_per_N.size() == frf.size()) f = frf.WithNoise(noise->sigma_m_per_N);
  return f.Select(lines);
}

// The warning of an FRF none of whose usable lines lies in the band to fit:
// where its lines and its usable lines are, so that the band can be chosen.
std::string NoLineInBand(const std::string& pose, const dynamics::FrfKey& key, const dynamics::Frf& frf,
                         const FrfNoise* noise, const GlobalModalFitOptions& fit) {
  std::ostringstream w;
  w.precision(6);
  w << "posture " << pose << ", " << key.Label() << ": no usable line in the band to fit (fmin_hz " << fit.fmin_hz
    << ", fmax_hz " << fit.fmax_hz << "): ";
  if (frf.size() == 0) {
    w << "the FRF has no line";
    return w.str();
  }
  w << "its lines span " << frf.freq_hz().minCoeff() << "-" << frf.freq_hz().maxCoeff() << " Hz";
  const std::vector<char> mask = UsableMask(frf, noise);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int k = 0; k < frf.size(); ++k) {
    if (mask[k]) {
      lo = std::min(lo, frf.freq_hz()(k));
      hi = std::max(hi, frf.freq_hz()(k));
    }
  }
  if (lo <= hi) {
    w << ", usable " << lo << "-" << hi << " Hz; choose a band that overlaps them";
  } else {
    w << ", none of them usable (|H| under the noise floor everywhere)";
  }
  return w.str();
}

}  // namespace

std::optional<RovingShapes> ShapesOfRovingTest(const ModalGroup& group, std::string* why) {
  auto fail = [&](const std::string& reason) {
    if (why) *why = reason;
    return std::nullopt;
  };
  const auto& keys = group.keys;
  if (keys.size() < 2) return fail("one FRF: no shape to compare across points");
  bool same_response = true, same_excitation = true;
  for (const auto& k : keys) {
    same_response = same_response && k.response_point == keys[0].response_point && k.response == keys[0].response;
    same_excitation =
        same_excitation && k.excitation_point == keys[0].excitation_point && k.excitation == keys[0].excitation;
  }
  RovingShapes s;
  if (same_response && !same_excitation) {
    s.roving = "excitation";
    s.fixed_point = keys[0].response_point;
    s.fixed_direction = keys[0].response;
  } else if (same_excitation && !same_response) {
    s.roving = "response";
    s.fixed_point = keys[0].excitation_point;
    s.fixed_direction = keys[0].excitation;
  } else {
    return fail("the FRFs share no end (a roving test keeps the response or the excitation at one point and "
                "direction)");
  }
  int driving = -1;
  for (size_t i = 0; i < keys.size(); ++i) {
    const bool hammer = s.roving == "excitation";
    s.points.push_back(hammer ? keys[i].excitation_point : keys[i].response_point);
    s.directions.push_back(hammer ? keys[i].excitation : keys[i].response);
    if (keys[i].IsDrivingPoint() && driving < 0) driving = static_cast<int>(i);
  }
  s.shapes = group.fit.ModeShapes(driving);
  s.mass_normalised = driving >= 0;
  return s;
}

std::vector<FitRovingShapes> ShapesOfRovingTests(const std::vector<PoseModes>& poses, std::vector<std::string>* notes) {
  std::vector<FitRovingShapes> out;
  for (size_t p = 0; p < poses.size(); ++p) {
    for (size_t g = 0; g < poses[p].groups.size(); ++g) {
      const ModalGroup& grp = poses[p].groups[g];
      if (grp.fit.status != SolverStatus::kConverged) continue;
      std::string why;
      std::optional<RovingShapes> rs = ShapesOfRovingTest(grp, &why);
      if (!rs) {
        if (notes) notes->push_back("posture " + poses[p].pose_id + ", fit " + std::to_string(g + 1) + ": no mode shapes: " + why);
        continue;
      }
      out.push_back({p, g, std::move(*rs)});
    }
  }
  return out;
}

std::vector<TipMode> TipModes(const ModalGroup& group, std::vector<std::string>* warnings) {
  std::vector<TipMode> out;
  const Eigen::MatrixXcd A = group.fit.ModalConstants();
  // The tool tip of a roving test is its driving point: the FRFs between
  // that point and itself give the mass and shape; a test without one has
  // no modal mass.
  int tip = -1;
  for (const auto& k : group.keys) {
    if (k.response_point == k.excitation_point) {
      tip = k.response_point;
      break;
    }
  }
  if (tip < 0) {
    if (warnings && !group.fit.modes.empty()) {
      warnings->push_back("posture " + group.pose_id + ": no FRF has its response and excitation at one point (" +
                          group.keys[0].ToString() + ", ...), so no mode has a modal mass: the modal table (--out) "
                          "is empty; the modes and shapes are in the summary and --modal-constants / --mode-shapes");
    }
    for (const GlobalMode& m : group.fit.modes) {
      TipMode t;
      t.freq_hz = m.freq_hz;
      t.damping_ratio = m.damping_ratio;
      out.push_back(t);
    }
    return out;
  }
  std::vector<double> unsplit;  // modes seen in two directions with no cross FRF between them
  for (size_t r = 0; r < group.fit.modes.size(); ++r) {
    TipMode t;
    t.freq_hz = group.fit.modes[r].freq_hz;
    t.damping_ratio = group.fit.modes[r].damping_ratio;
    Eigen::Vector3d a_dd = Eigen::Vector3d::Constant(NAN);
    Eigen::Matrix3d a_de = Eigen::Matrix3d::Constant(NAN);
    for (size_t i = 0; i < group.keys.size(); ++i) {
      if (group.keys[i].response_point != tip || group.keys[i].excitation_point != tip) continue;
      const int d = AxisIndex(group.keys[i].response), e = AxisIndex(group.keys[i].excitation);
      // Proportional damping: A is real; its real part carries the sign.
      if (d == e) a_dd(d) = A(i, r).real();
      else a_de(d, e) = A(i, r).real();
    }
    double inv_m = 0.0;
    for (int d = 0; d < 3; ++d) {
      if (std::isfinite(a_dd(d)) && a_dd(d) > 0.0) {
        inv_m += a_dd(d);
        t.directions += "xyz"[d];
      }
    }
    if (inv_m > 0.0) {
      t.modal_mass_kg = 1.0 / inv_m;
      for (int d = 0; d < 3; ++d) {
        if (std::isfinite(a_dd(d)) && a_dd(d) > 0.0) t.shape(d) = std::sqrt(a_dd(d) * t.modal_mass_kg);
      }
      // Signs relative to the strongest direction, from a cross FRF.
      int ref = 0;
      t.shape.cwiseAbs().maxCoeff(&ref);
      std::string unsigned_dirs;
      for (int d = 0; d < 3; ++d) {
        if (d == ref || t.shape(d) == 0.0) continue;
        const double c = std::isfinite(a_de(d, ref)) ? a_de(d, ref) : a_de(ref, d);
        if (std::isfinite(c) && c < 0.0) t.shape(d) = -t.shape(d);
        if (!std::isfinite(c)) unsigned_dirs += "xyz"[d];
      }
      if (!unsigned_dirs.empty()) {
        // No cross FRF gives the sign of these components against the
        // strongest one's: either sign fits the direct FRFs, and the two
        // couple the directions oppositely (a chatter model from a wrong
        // sign is wrong). The mode is written once per direction, each with
        // the modal mass its direct FRF gives and no coupling (H_de = 0, as
        // stability-lobes --frf takes direct FRFs without a cross FRF).
        unsplit.push_back(t.freq_hz);
        for (int d = 0; d < 3; ++d) {
          if (!(std::isfinite(a_dd(d)) && a_dd(d) > 0.0)) continue;
          TipMode one = t;
          one.modal_mass_kg = 1.0 / a_dd(d);
          one.shape = Eigen::Vector3d::Unit(d);
          one.directions = std::string(1, "xyz"[d]);
          out.push_back(one);
        }
        continue;
      }
    } else if (warnings) {
      std::ostringstream w;
      w.precision(6);
      w << "posture " << group.pose_id << ", mode at " << t.freq_hz
        << " Hz: no driving-point FRF has a positive modal constant, so it has no modal mass (left out of the "
           "modal table)";
      warnings->push_back(w.str());
    }
    out.push_back(t);
  }
  if (warnings && !unsplit.empty()) {
    std::ostringstream w;
    w.precision(4);
    w << "posture " << group.pose_id << ": " << unsplit.size() << " mode" << (unsplit.size() > 1 ? "s" : "")
      << " (at";
    for (double f : unsplit) w << " " << f;
    w << " Hz) appear in two direct FRFs but no cross FRF between their directions gives the relative sign of the "
         "shape's components (either sign fits the direct FRFs, and they couple the directions oppositely); each "
         "is written once per direction with no coupling, as stability-lobes --frf takes direct FRFs alone; "
         "measure the cross FRF (e.g. xy) to get the coupled mode";
    warnings->push_back(w.str());
  }
  return out;
}

void ModalAnalysisOptions::Validate() const {
  ValidateNested("fit", fit);
  CheckOptionAtLeast("min_common_lines", min_common_lines, 0);
}

std::vector<PoseModes> AnalyseModes(const dynamics::FrfSet& measured, const NoiseModels& noise,
                                    const ModalAnalysisOptions& options, int file_power) {
  options.Validate();
  std::vector<PoseModes> out;
  for (const std::string& pose : measured.pose_ids()) {
    PoseModes pm;
    pm.pose_id = pose;
    const dynamics::FrfSet set = measured.ForPose(pose);
    std::vector<dynamics::FrfKey> keys;
    std::vector<const FrfNoise*> noises;
    for (const auto& [key, frf] : set) {
      keys.push_back(key);
      const auto it = noise.find(key);
      noises.push_back(it == noise.end() ? nullptr : &it->second);
    }
    // The lines usable in every FRF of the posture (same grid required).
    bool same_grid = true;
    const dynamics::Frf& first = set.at(keys.front());
    for (const auto& key : keys) {
      const dynamics::Frf& f = set.at(key);
      same_grid = same_grid && f.size() == first.size() &&
                  (f.freq_hz() - first.freq_hz()).cwiseAbs().maxCoeff() <= 1e-9 * first.freq_hz().maxCoeff();
    }
    std::vector<int> common;
    if (same_grid) {
      std::vector<char> all(first.size(), 1);
      for (size_t i = 0; i < keys.size(); ++i) {
        const std::vector<char> m = UsableMask(set.at(keys[i]), noises[i]);
        for (int k = 0; k < first.size(); ++k) all[k] = all[k] && m[k];
      }
      for (int k = 0; k < first.size(); ++k) {
        const double f = first.freq_hz()(k);
        if (all[k] && f >= options.fit.fmin_hz && f <= options.fit.fmax_hz) common.push_back(k);
      }
    }
    bool together = !options.per_frf && keys.size() > 1;
    // A band that holds no line at all is said per FRF below (NoLineInBand),
    // not as FRFs with too few common lines.
    const Eigen::VectorXd& f0 = first.freq_hz();
    const bool band_has_lines = ((f0.array() >= options.fit.fmin_hz) && (f0.array() <= options.fit.fmax_hz)).any();
    if (together && same_grid && !band_has_lines) together = false;
    if (together && (!same_grid || static_cast<int>(common.size()) < options.min_common_lines)) {
      pm.warnings.push_back("posture " + pose + ": its FRFs " +
                            (same_grid ? "have only " + std::to_string(common.size()) +
                                             " lines usable in all of them"
                                       : std::string("are on different frequency lines")) +
                            ", so each is fitted alone (its own poles)");
      together = false;
    }
    auto fit_group = [&](const std::vector<size_t>& members, const std::vector<int>& lines_all) {
      ModalGroup g;
      g.pose_id = pose;
      for (size_t i : members) {
        std::vector<int> lines = lines_all;
        if (lines.empty()) {
          const std::vector<char> m = UsableMask(set.at(keys[i]), noises[i]);
          const dynamics::Frf& f = set.at(keys[i]);
          for (int k = 0; k < f.size(); ++k) {
            if (m[k] && f.freq_hz()(k) >= options.fit.fmin_hz && f.freq_hz()(k) <= options.fit.fmax_hz) {
              lines.push_back(k);
            }
          }
        }
        g.keys.push_back(keys[i]);
        g.data.push_back(Prepared(set.at(keys[i]), noises[i], lines));
      }
      for (size_t j = 0; j < g.data.size(); ++j) {
        if (g.data[j].size() == 0) {
          g.fit.message = "no usable line in the band";
          pm.warnings.push_back(NoLineInBand(pose, g.keys[j], set.at(g.keys[j]), noises[members[j]], options.fit));
          return g;
        }
      }
      GlobalModalFitOptions o = options.fit;
      o.fmin_hz = 0.0;
      o.fmax_hz = std::numeric_limits<double>::infinity();
      if (options.weights_in_file_quantity) o.uniform_weights_power = file_power;
      if (options.model_error) o.model_error_power = file_power;
      g.fit = FitModesGlobal(g.data, o);
      for (size_t i = 0; i < g.data.size(); ++i) {
        g.misfit.push_back(i < g.fit.per_frf.size() ? RelativeMisfit(g.fit.per_frf[i], g.data[i], file_power) : NAN);
      }
      if (g.fit.status != SolverStatus::kConverged) {
        std::string which;
        for (const auto& k : g.keys) which += (which.empty() ? "" : ", ") + k.ToString();
        pm.warnings.push_back(which + ": " + g.fit.message);
      } else if (g.data.front().size() >= 2) {
        // A mode whose half-power bandwidth 2ζf_n is under half the line
        // spacing sits between lines: its peak is not sampled and its
        // damping (and so its modal mass) is not identified by the data
        // (pyuff's beam: ζ = 3e-9 fitted at 51.6 Hz on 1 Hz lines).
        const Eigen::VectorXd& f = g.data.front().freq_hz();
        std::vector<double> steps;
        for (int k = 1; k < f.size(); ++k) steps.push_back(f(k) - f(k - 1));
        std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
        const double df = steps[steps.size() / 2];
        for (const GlobalMode& m : g.fit.modes) {
          const double bw = 2.0 * m.damping_ratio * m.freq_hz;
          if (bw < 0.5 * df) {
            std::ostringstream w;
            w.precision(4);
            w << "posture " << pose << ", mode at " << m.freq_hz << " Hz: its half-power bandwidth 2 zeta f = " << bw
              << " Hz (zeta " << m.damping_ratio << ") is under half the line spacing " << df
              << " Hz, so the peak falls between lines and the damping ratio and modal mass are not identified by "
                 "this FRF; measure with finer lines (a longer record: spacing = 1 / record length) to resolve it";
            pm.warnings.push_back(w.str());
          }
        }
      }
      return g;
    };
    if (together) {
      std::vector<size_t> all(keys.size());
      for (size_t i = 0; i < keys.size(); ++i) all[i] = i;
      pm.groups.push_back(fit_group(all, common));
    } else {
      for (size_t i = 0; i < keys.size(); ++i) pm.groups.push_back(fit_group({i}, {}));
    }
    // Fitted together: the tool-tip modes of the one set of poles. Each FRF
    // alone: the modes of each direct FRF, each a mode in its direction.
    std::vector<std::string> transfer;
    for (const ModalGroup& g : pm.groups) {
      if (g.fit.status != SolverStatus::kConverged) continue;
      if (g.keys.size() == 1 && !g.keys[0].IsDrivingPoint()) {
        transfer.push_back(g.keys[0].ToString());
        continue;
      }
      for (const TipMode& t : TipModes(g, &pm.warnings)) pm.tip_modes.push_back(t);
    }
    if (pm.tip_modes.empty() && !transfer.empty()) {
      std::string which;
      for (const std::string& k : transfer) which += (which.empty() ? "" : ", ") + k;
      pm.warnings.push_back("posture " + pose + ": no driving-point FRF (" + which +
                            (transfer.size() > 1 ? " are transfer FRFs" : " is a transfer FRF") +
                            ": response and excitation at different points or in different directions), so no "
                            "mode has a modal mass: the modal table (--out) is empty; the modes are in the summary "
                            "and their constants in --modal-constants");
    }
    std::sort(pm.tip_modes.begin(), pm.tip_modes.end(),
              [](const TipMode& a, const TipMode& b) { return a.freq_hz < b.freq_hz; });
    out.push_back(std::move(pm));
  }
  return out;
}

}  // namespace robomach::calibration
