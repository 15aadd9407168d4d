#include "robomach/audit/error_patterns.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <string>

#include "robomach/audit/correlation.h"
#include "robomach/common/errors.h"
#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/gravity_torque.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/kinematics/serial_chain.h"

namespace robomach::audit {

namespace {

const Eigen::VectorXd& PostureOf(const calibration::PostureMap& postures, const std::string& id) {
  const auto it = postures.find(id);
  if (it == postures.end()) {
    std::string known;
    for (const auto& [k, q] : postures) known += (known.empty() ? "" : ", ") + k;
    throw std::invalid_argument("posture " + id + " of the measured FRFs is not in the posture map (known: " +
                                known + ")");
  }
  return it->second;
}

}  // namespace

PostureDescriptors DescribePostures(const dynamics::RobotModel& model, const calibration::PostureMap& postures,
                                    const std::vector<std::string>& pose_ids) {
  const int n = model.num_joints();
  PostureDescriptors d;
  d.pose_ids = pose_ids;
  for (int j = 0; j < n; ++j) {
    d.names.push_back(std::string("q").append(std::to_string(j + 1)));  // not "q" + …: GCC 12 -Wrestrict false positive
    d.units.push_back("rad");
  }
  d.names.insert(d.names.end(), {"reach", "height"});
  d.units.insert(d.units.end(), {"m", "m"});
  // Joints 2 and 3 carry the arm's weight on a six-axis arm; a chain with
  // fewer joints gets the ones it has.
  const int gravity_joints = std::min(n, 3) - 1;
  for (int j = 1; j <= gravity_joints; ++j) {
    d.names.push_back(std::string("gravity_torque_j").append(std::to_string(j + 1)));
    d.units.push_back("Nm");
  }
  d.values.resize(static_cast<Eigen::Index>(pose_ids.size()), static_cast<Eigen::Index>(d.names.size()));
  for (size_t i = 0; i < pose_ids.size(); ++i) {
    const Eigen::VectorXd& q = PostureOf(postures, pose_ids[i]);
    const Eigen::Vector3d p_BT = kinematics::ForwardKinematics(model.chain(), q).translation();
    const Eigen::VectorXd G = dynamics::GravityTorque(model, q);
    const auto r = static_cast<Eigen::Index>(i);
    d.values.row(r).head(n) = q.transpose();
    d.values(r, n) = std::hypot(p_BT.x(), p_BT.y());
    d.values(r, n + 1) = p_BT.z();
    for (int j = 1; j <= gravity_joints; ++j) d.values(r, n + 1 + j) = G(j);
  }
  return d;
}

Eigen::VectorXd ErrorPerPosture(const ModelErrors& errors, const std::vector<std::string>& pose_ids) {
  std::map<std::string, std::pair<double, int>> acc;
  for (const CurveError& c : errors.curves) {
    acc[c.key.pose_id].first += c.rms_log_mag * c.rms_log_mag * c.lines;
    acc[c.key.pose_id].second += c.lines;
  }
  Eigen::VectorXd out(static_cast<Eigen::Index>(pose_ids.size()));
  for (size_t i = 0; i < pose_ids.size(); ++i) {
    const auto it = acc.find(pose_ids[i]);
    out(static_cast<Eigen::Index>(i)) =
        it != acc.end() && it->second.second > 0 ? std::sqrt(it->second.first / it->second.second) : NAN;
  }
  return out;
}

ModeErrorMap BuildModeErrorMap(const calibration::Comparison& comparison, const std::vector<std::string>& pose_ids) {
  ModeErrorMap m;
  m.pose_ids = pose_ids;
  m.matches = comparison.matches;
  std::set<int> modes;
  for (const auto& mm : comparison.matches) modes.insert(mm.model_mode + 1);
  m.modes.assign(modes.begin(), modes.end());
  const auto rows = static_cast<Eigen::Index>(pose_ids.size()), cols = static_cast<Eigen::Index>(m.modes.size());
  m.freq_error.setConstant(rows, cols, NAN);
  m.peak_error.setConstant(rows, cols, NAN);
  m.match.setConstant(rows, cols, -1);
  std::map<std::string, Eigen::Index> row_of;
  for (size_t i = 0; i < pose_ids.size(); ++i) row_of[pose_ids[i]] = static_cast<Eigen::Index>(i);
  for (size_t k = 0; k < comparison.matches.size(); ++k) {
    const calibration::ModeMatch& mm = comparison.matches[k];
    const auto rit = row_of.find(mm.key.pose_id);
    if (rit == row_of.end()) continue;
    const auto c = static_cast<Eigen::Index>(std::lower_bound(m.modes.begin(), m.modes.end(), mm.model_mode + 1) -
                                             m.modes.begin());
    int& cell = m.match(rit->second, c);
    if (cell >= 0 && comparison.matches[cell].measured_peak >= mm.measured_peak) continue;
    cell = static_cast<int>(k);
    m.freq_error(rit->second, c) = mm.freq_error();
    m.peak_error(rit->second, c) = mm.peak_error();
  }
  return m;
}

void ErrorPatternOptions::Validate() const {
  const auto fail = [](const std::string& field, const std::string& bound, double value) {
    throw OptionError(field, "ErrorPatternOptions: " + field + " must be " + bound + ", got " + std::to_string(value));
  };
  if (!(fmin_hz >= 0.0) || !(fmax_hz > fmin_hz)) {
    throw OptionError(fmin_hz >= 0.0 ? "fmax_hz" : "fmin_hz",
                      "ErrorPatternOptions: need 0 <= fmin_hz < fmax_hz, got fmin_hz = " + std::to_string(fmin_hz) +
                          ", fmax_hz = " + std::to_string(fmax_hz));
  }
  // MatchOptions' own checks (direction_weight finite too), its fields named
  // "matching.direction_weight".
  ValidateNested("matching", matching);
  if (!(significance_factor >= 1.0)) fail("significance_factor", ">= 1", significance_factor);
  if (!(significance_level > 0.0 && significance_level < 1.0)) {
    fail("significance_level", "in (0, 1)", significance_level);
  }
}

calibration::ModalFitOptions AuditModalFitOptions(const AuditOptions& options) {
  // RunAudit fits the measured modes with CalibrationOptions::modal_fit of
  // its whole-curve options: the defaults with the audit's band.
  calibration::ModalFitOptions m;
  m.fmin_hz = options.fmin_hz;
  m.fmax_hz = options.fmax_hz;
  return m;
}

namespace {

// The measured-mode indices of the comparison must refer to these
// features; a different modal fit would silently mislabel every mode.
void CheckFeaturesOfResult(const calibration::Comparison& cmp, const calibration::MeasuredFeatures& features) {
  for (const calibration::ModeMatch& m : cmp.matches) {
    if (m.measured < 0 || m.measured >= static_cast<int>(features.modes.size()) ||
        !(features.modes[m.measured].key == m.key) ||
        features.modes[m.measured].fit.freq_hz != m.measured_freq_hz) {
      throw std::invalid_argument("AnalyzeErrorPatterns: the measured features are not those of the audit result "
                                  "(match at " + m.key.ToString() + ", " + std::to_string(m.measured_freq_hz) +
                                  " Hz); extract them with AuditModalFitOptions of the audit's options");
    }
  }
  for (int i : cmp.unmatched_measured) {
    if (i < 0 || i >= static_cast<int>(features.modes.size())) {
      throw std::invalid_argument("AnalyzeErrorPatterns: unmatched measured mode " + std::to_string(i) +
                                  " is not in the measured features (" + std::to_string(features.modes.size()) +
                                  " modes)");
    }
  }
}

// ---- trends: the error per posture before and after the best candidate,
// and its correlation with each of out->descriptors (set before).
void ComputeTrends(const AuditResult& result, const std::vector<std::string>& pose_ids,
                   const ErrorPatternOptions& options, ErrorPatterns* out) {
  ErrorTrends& t = out->trends;
  t.pose_ids = pose_ids;
  t.n = static_cast<int>(pose_ids.size());
  t.significance_level = options.significance_level;
  t.critical_correlation = CriticalCorrelation(t.n, options.significance_level);
  t.error_before = ErrorPerPosture(result.errors_before, pose_ids);
  if (result.best >= 0) t.error_after = ErrorPerPosture(result.candidates.at(result.best).errors, pose_ids);
  const double limit = options.significance_factor * result.noise_floor;
  auto failing = [&](const Eigen::VectorXd& e) { return (e.array() > limit).any(); };
  t.failing_before = failing(t.error_before);
  t.failing_after = t.error_after.size() > 0 && failing(t.error_after);
  auto significant = [&](double r) { return std::isfinite(r) && std::abs(r) > t.critical_correlation; };
  for (size_t c = 0; c < out->descriptors.names.size(); ++c) {
    Trend tr;
    tr.descriptor = out->descriptors.names[c];
    tr.unit = out->descriptors.units[c];
    tr.values = out->descriptors.values.col(static_cast<Eigen::Index>(c));
    // Two postures always lie on a line (r = ±1): no trend below three.
    tr.correlation_before = t.n >= 3 ? PearsonCorrelation(tr.values, t.error_before) : NAN;
    tr.significant_before = t.failing_before && significant(tr.correlation_before);
    if (t.error_after.size() > 0) {
      tr.correlation_after = t.n >= 3 ? PearsonCorrelation(tr.values, t.error_after) : NAN;
      tr.significant_after = t.failing_after && significant(tr.correlation_after);
    }
    t.trends.push_back(std::move(tr));
  }
}

// What the matching left over in one FRF, with what the second pass
// compares: the model modes' visibility in the FRF's band (0 outside it)
// and the largest measured peak.
struct FrfLeftovers {
  const dynamics::FrfKey& key;
  const std::vector<dynamics::Mode>& modes;  // the model's at the FRF's posture
  std::vector<double> vis;
  double vis_max = 0.0;
  double meas_max = 0.0;
  const std::set<int>& matched;   // model modes the matching paired here
  const std::vector<int>& meas;   // measured modes it left here
};

// The model modes' visibility in the band [lo, hi] of the FRF, and the
// largest measured peak contribution in it.
void MeasureVisibility(FrfLeftovers& l, double lo, double hi, const calibration::MeasuredFeatures& features) {
  const std::vector<dynamics::Mode>& modes = l.modes;
  l.vis.assign(modes.size(), 0.0);
  for (size_t k = 0; k < modes.size(); ++k) {
    if (modes[k].freq_hz < lo || modes[k].freq_hz > hi) continue;
    l.vis[k] = calibration::ModelModeVisibility(modes[k], l.key);
    l.vis_max = std::max(l.vis_max, l.vis[k]);
  }
  for (const calibration::MeasuredMode& mm : features.modes) {
    if (mm.key == l.key) l.meas_max = std::max(l.meas_max, mm.fit.peak_contribution);
  }
}

// The measured (i) and model (k) modes the second pass paired.
struct WeakPairs {
  std::set<int> paired_i, paired_k;
};

// Second pass: greedy on |ln f ratio| + w |ln visibility ratio|, one to one.
// Each pair is counted in out->weak_pairs.
WeakPairs PairWeakModes(const FrfLeftovers& l, const calibration::MeasuredFeatures& features,
                        const calibration::MatchOptions& mo, ErrorPatterns* out) {
  const std::vector<dynamics::Mode>& modes = l.modes;
  const std::vector<double>& vis = l.vis;
  struct Pair {
    double cost;
    int i, k;
  };
  std::vector<Pair> pairs;
  for (int i : l.meas) {
    const calibration::FittedMode& fm = features.modes[i].fit;
    for (size_t k = 0; k < modes.size(); ++k) {
      if (!(vis[k] > 0.0) || l.matched.count(static_cast<int>(k))) continue;
      const double lf = std::abs(std::log(modes[k].freq_hz / fm.freq_hz));
      if (lf > mo.max_log_freq_ratio) continue;
      const double lv = fm.peak_contribution > 0.0 ? std::abs(std::log(vis[k] / fm.peak_contribution)) : 0.0;
      pairs.push_back({lf + mo.direction_weight * lv, i, static_cast<int>(k)});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.cost < b.cost; });
  WeakPairs w;
  for (const Pair& pr : pairs) {
    if (w.paired_i.count(pr.i) || w.paired_k.count(pr.k)) continue;
    w.paired_i.insert(pr.i);
    w.paired_k.insert(pr.k);
    ++out->weak_pairs;
  }
  return w;
}

// What stays unpaired in the FRF has no counterpart: every such measured
// mode, and the model modes that are visible by the matching's rule.
void RecordUnpaired(const FrfLeftovers& l, const WeakPairs& w, const calibration::MeasuredFeatures& features,
                    const calibration::MatchOptions& mo, ErrorPatterns* out) {
  const std::vector<dynamics::Mode>& modes = l.modes;
  const std::vector<double>& vis = l.vis;
  for (int i : l.meas) {
    if (w.paired_i.count(i)) continue;
    const calibration::MeasuredMode& mm = features.modes[i];
    UnmatchedMode u;
    u.key = l.key;
    u.freq_hz = mm.fit.freq_hz;
    u.damping_ratio = mm.fit.damping_ratio;
    u.peak_contribution = mm.fit.peak_contribution;
    u.relative_visibility = l.meas_max > 0.0 ? mm.fit.peak_contribution / l.meas_max : NAN;
    u.measured_mode = i;
    out->unmatched_measured.push_back(u);
  }
  for (size_t k = 0; k < modes.size(); ++k) {
    if (!(vis[k] > 0.0) || vis[k] < mo.min_relative_visibility * l.vis_max) continue;
    if (l.matched.count(static_cast<int>(k)) || w.paired_k.count(static_cast<int>(k))) continue;
    UnmatchedMode u;
    u.key = l.key;
    u.freq_hz = modes[k].freq_hz;
    u.damping_ratio = modes[k].damping_ratio;
    u.peak_contribution = vis[k];
    u.relative_visibility = vis[k] / l.vis_max;
    u.model_mode = static_cast<int>(k);
    out->unmatched_model.push_back(u);
  }
}

// ---- modes without a counterpart, FRF by FRF
//
// The matching tries only modes above its visibility rule on both sides
// (MatchOptions::min_relative_visibility against the largest in the FRF),
// so a weak mode it left alone may well have a counterpart: a high
// mode's receptance peak is naturally small, and a mode seen mostly in
// another direction is weak in this one. A second pass therefore pairs
// what the matching left over in the FRF (measured modes, and model modes
// inside the band) by the matching's own cost and frequency window but
// without the visibility rule. What stays unpaired has no counterpart:
// every such measured mode (the modal fit already dropped computational
// ones), and the model modes that are visible by the rule.
void FindUnmatchedModes(const calibration::Comparison& cmp, const std::shared_ptr<const dynamics::RobotModel>& model,
                        const calibration::PostureMap& postures, const dynamics::FrfSet& measured,
                        const calibration::MeasuredFeatures& features, const ErrorPatternOptions& options,
                        ErrorPatterns* out) {
  std::map<dynamics::FrfKey, std::set<int>> matched_model;
  for (const calibration::ModeMatch& m : cmp.matches) matched_model[m.key].insert(m.model_mode);
  std::map<dynamics::FrfKey, std::vector<int>> left_measured;
  for (int i : cmp.unmatched_measured) left_measured[features.modes[i].key].push_back(i);
  dynamics::PostureEvaluator evaluator(model);
  std::map<std::string, dynamics::PostureDynamics> dyn;
  const calibration::MatchOptions& mo = options.matching;
  for (const auto& [key, frf] : measured) {
    const auto fit = features.fits.find(key);
    if (fit == features.fits.end() || fit->second.status != SolverStatus::kConverged) {
      out->frfs_without_modal_fit.push_back(key);
      continue;
    }
    const dynamics::Frf band = frf.Band(options.fmin_hz, options.fmax_hz);
    if (band.size() == 0) continue;
    const double lo = band.freq_hz()(0), hi = band.freq_hz()(band.size() - 1);
    auto dit = dyn.find(key.pose_id);
    if (dit == dyn.end()) dit = dyn.emplace(key.pose_id, evaluator.Evaluate(PostureOf(postures, key.pose_id))).first;
    FrfLeftovers l{key, dit->second.modes, {}, 0.0, 0.0, matched_model[key], left_measured[key]};
    MeasureVisibility(l, lo, hi, features);
    const WeakPairs w = PairWeakModes(l, features, mo, out);
    RecordUnpaired(l, w, features, mo, out);
  }
  auto by_key_then_freq = [](const UnmatchedMode& a, const UnmatchedMode& b) {
    return std::tie(a.key, a.freq_hz) < std::tie(b.key, b.freq_hz);
  };
  std::stable_sort(out->unmatched_measured.begin(), out->unmatched_measured.end(), by_key_then_freq);
}

}  // namespace

ErrorPatterns AnalyzeErrorPatterns(const AuditResult& result,
                                   const std::shared_ptr<const dynamics::RobotModel>& model,
                                   const calibration::PostureMap& postures, const dynamics::FrfSet& measured,
                                   const calibration::MeasuredFeatures& features,
                                   const ErrorPatternOptions& options) {
  options.Validate();
  if (!model) throw std::invalid_argument("AnalyzeErrorPatterns: no model");
  const calibration::Comparison& cmp = result.modes_before;
  CheckFeaturesOfResult(cmp, features);

  ErrorPatterns out;
  const std::vector<std::string> pose_ids = measured.pose_ids();

  // ---- trends
  out.descriptors = DescribePostures(*model, postures, pose_ids);
  ComputeTrends(result, pose_ids, options, &out);

  // ---- error map
  out.mode_map = BuildModeErrorMap(cmp, pose_ids);

  // ---- modes without a counterpart, FRF by FRF (see FindUnmatchedModes)
  FindUnmatchedModes(cmp, model, postures, measured, features, options, &out);
  return out;
}

}  // namespace robomach::audit
