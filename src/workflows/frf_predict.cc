#include "robomach/workflows/frf_predict.h"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <stdexcept>
#include <utility>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/uncertainty_file.h"
#include "robomach/workflows/robot_config.h"

namespace robomach::workflows {
void ApplyAddsAndSets(const std::vector<std::string>& adds, const std::vector<std::string>& sets,
                      io::RobotConfig* cfg) {
  for (const std::string& name : adds) {
    try {
      std::tie(cfg->description, cfg->parameters) = dynamics::WithEffect(cfg->description, cfg->parameters, name);
    } catch (const std::invalid_argument& e) {
      throw OptionError("adds", "adds " + name + ": " + e.what());
    }
  }
  for (const std::string& s : sets) {
    const size_t eq = s.find('=');
    double v = 0.0;
    if (eq == std::string::npos || eq == 0 || !io::ParseFiniteNumber(s.substr(eq + 1), &v)) {
      throw OptionError("sets", "sets " + s + ": expected NAME=VALUE with a number, e.g. m6_kg=30");
    }
    try {
      cfg->parameters.Set(s.substr(0, eq), v);
    } catch (const std::invalid_argument& e) {
      throw OptionError("sets", "sets " + s + ": " + e.what());
    }
  }
}

std::optional<dynamics::ParameterUncertainty> UseUncertaintyFiles(const std::vector<std::string>& files,
                                                                  const std::vector<std::string>& sets,
                                                                  io::RobotConfig* config, const MessageSink& tell) {
  if (files.empty()) return std::nullopt;
  dynamics::ParameterUncertainty u = io::ReadParameterUncertainties(files);
  for (const std::string& set : sets) {
    const std::string name = set.substr(0, set.find('='));
    for (const auto& up : u.parameters) {
      if (up.name == name) {
        throw OptionError("sets", "sets " + name + " and uncertainty_paths (" + u.source + ") both give " + name +
                                      ": the file's estimate goes with its covariance; drop one of the two");
      }
    }
  }
  const std::string changed = dynamics::UseEstimates(u, &config->parameters);
  if (!changed.empty()) Tell(tell, Message::Kind::kNote, changed);
  return u;
}

Eigen::VectorXd FrequencyGrid(double fmin_hz, double fmax_hz, double df_hz) {
  if (!(fmin_hz >= 0.0) || !(fmax_hz > fmin_hz) || !(df_hz > 0.0) || !std::isfinite(fmax_hz) || !std::isfinite(df_hz)) {
    throw OptionError("fmin_hz", "expected finite 0 <= fmin_hz < fmax_hz and df_hz > 0, got fmin_hz " +
                                     FormatNumber(fmin_hz, 7) + ", fmax_hz " + FormatNumber(fmax_hz, 7) + ", df_hz " +
                                     FormatNumber(df_hz, 7));
  }
  // Count in double first: a tiny step would overflow the integer.
  const double lines = std::floor((fmax_hz - fmin_hz) / df_hz + 1e-9) + 1.0;
  if (lines > dynamics::kMaxFrequencyLines) {
    const std::string why = fmax_hz > dynamics::kMaxPlausibleFmaxHz
                                ? "; fmax_hz " + FormatNumber(fmax_hz, 7) + " Hz is beyond the " +
                                      FormatNumber(dynamics::kMaxPlausibleFmaxHz, 7) +
                                      " Hz of hammer tests (a frequency in mHz, or a line count, typed in the Hz option?)"
                                : "";
    throw OptionError("fmin_hz", "fmin_hz " + FormatNumber(fmin_hz, 7) + " to fmax_hz " + FormatNumber(fmax_hz, 7) +
                                     " in steps of df_hz " + FormatNumber(df_hz, 7) + " is " + FormatNumber(lines, 7) +
                                     " frequency lines, more than the " +
                                     FormatNumber(dynamics::kMaxFrequencyLines, 7) +
                                     " allowed (FFT analysers give 400 - 25 600)" + why +
                                     ": raise df_hz or lower fmax_hz");
  }
  // One line is no FRF (nothing to plot, no peak, no mode to fit).
  if (lines < 2.0) {
    throw OptionError("df_hz", "df_hz " + FormatNumber(df_hz, 7) + ": leaves 1 frequency line in fmin_hz " +
                                   FormatNumber(fmin_hz, 7) + " to fmax_hz " + FormatNumber(fmax_hz, 7) +
                                   " Hz; expected a step of at most " + FormatNumber(fmax_hz - fmin_hz, 7) +
                                   " Hz (2 lines or more)");
  }
  const long n = static_cast<long>(lines);
  return Eigen::VectorXd::LinSpaced(n, fmin_hz, fmin_hz + static_cast<double>(n - 1) * df_hz);
}

Eigen::VectorXd ReadFrequencyFile(const std::string& path) {
  const io::CsvTable t = io::CsvTable::ReadFile(path);
  t.RequireColumn("freq_hz");
  Eigen::VectorXd f(t.num_rows());
  for (int r = 0; r < t.num_rows(); ++r) {
    f(r) = t.Number(r, "freq_hz");
    if (f(r) < 0.0) throw t.ErrorAt(r, "freq_hz", "expected a frequency >= 0");
    if (r > 0 && !(f(r) > f(r - 1))) throw t.ErrorAt(r, "freq_hz", "frequencies must be strictly increasing");
  }
  if (f.size() == 0) throw InputError({path, 0, 0}, "no frequency lines");
  return f;
}

void FrfPredictOptions::Validate() const {
  if (robot_path.empty()) throw OptionError("robot_path", "robot_path: a robot config is required");
  if (postures_path.empty()) throw OptionError("postures_path", "postures_path: a posture file is required");
  if (freq_hz.size() == 0) throw OptionError("freq_hz", "freq_hz: expected at least one frequency line");
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    if (!(freq_hz(i) >= 0.0) || !std::isfinite(freq_hz(i)) || (i > 0 && !(freq_hz(i) > freq_hz(i - 1)))) {
      throw OptionError("freq_hz", "freq_hz: expected finite lines >= 0, strictly increasing, got " +
                                       FormatNumber(freq_hz(i)) + " at line " + std::to_string(i + 1) +
                                       (i > 0 ? " after " + FormatNumber(freq_hz(i - 1)) : std::string()));
    }
  }
  if (method != "modal" && method != "direct") {
    throw OptionError("method", "method: expected modal or direct, got '" + method + "'");
  }
  uncertainty.Validate();  // its fields are the tool's (confidence ...): unprefixed
}

nlohmann::json FrfPredictRun::Summary(const FrfPredictOptions& o, const std::string& method_name) const {
  nlohmann::json j;
  j["robot"] = o.robot_path;
  nlohmann::json params;
  for (const auto& s : model->parameters().specs()) params[s.name] = model->parameters().Get(s.name);
  j["parameters"] = params;
  j["postures"] = nlohmann::json::array();
  for (size_t p = 0; p < postures.size(); ++p) {
    j["postures"].push_back(io::PostureToJson(postures[p].id, dynamics[p]));
    if (p < intervals.size()) j["postures"].back()["mode_intervals"] = io::ModeIntervalsToJson(intervals[p]);
  }
  if (uncertainty && !intervals.empty()) {
    j["uncertainty"] = {{"files", uncertainty_files},
                        {"confidence", o.uncertainty.confidence},
                        {"method", method_name},
                        {"parameters", io::ParameterUncertaintyToJson(*uncertainty)}};
  }
  return j;
}

FrfPredictRun RunFrfPredict(const FrfPredictOptions& o, const MessageSink& tell, const StageProgress& progress) {
  o.Validate();
  FrfPredictRun r;
  r.config = workflows::LoadRobotConfigChecked(o.robot_path);
  for (const std::string& w : r.config.implausible) {
    Tell(tell, Message::Kind::kWarning, w);
    r.unit_findings.push_back(w);
  }
  ApplyAddsAndSets(o.adds, o.sets, &r.config);
  // The config's `uncertainty:` files serve the outputs that carry intervals.
  if (o.intervals || o.band_postures > 0) {
    r.uncertainty_files = o.uncertainty_paths.empty() ? r.config.uncertainty_files : o.uncertainty_paths;
  }
  r.uncertainty = UseUncertaintyFiles(r.uncertainty_files, o.sets, &r.config, tell);
  r.model = r.config.Build();
  std::vector<std::string> posture_units;  // radians under _deg headers, ...
  r.postures = io::ReadPostureFile(o.postures_path, r.model->num_joints(), &posture_units);
  for (const std::string& w : posture_units) {
    Tell(tell, Message::Kind::kWarning, w);
    r.unit_findings.push_back(w);
  }
  // Everything is computed before anything is written (no partial
  // outputs), so bound the memory: 3×3 complex values per line and posture.
  const double values = static_cast<double>(r.postures.size()) * static_cast<double>(o.freq_hz.size());
  if (values > kMaxFrfPredictLines) {
    // About 60 bytes per direction pair and line in the CSV (formats.md §3).
    const double csv_gb = values * static_cast<double>(o.direction_pairs) * 60e-9;
    throw OptionError("postures_path", "postures_path: " + std::to_string(r.postures.size()) + " postures × " +
                                           std::to_string(o.freq_hz.size()) + " frequency lines is more than " +
                                           FormatNumber(kMaxFrfPredictLines, 7) + " FRF lines (a CSV of about " +
                                           FormatNumber(csv_gb, 2) +
                                           " GB): split the posture file or coarsen the grid");
  }
  std::vector<dynamics::NamedPosture> named;
  for (const io::Posture& p : r.postures) named.push_back({p.id, p.q});
  dynamics::PredictOptions po;
  po.method = dynamics::ParseReceptanceMethod(o.method);
  if (progress) po.progress = [&](long done, long total) { progress("postures", done, total); };
  dynamics::FrfPredictionResult result = dynamics::PredictFrfs(r.model, named, o.freq_hz, po);
  r.prediction_status = result.status();
  for (const Finding& f : result.verdict.findings) {
    r.warnings.push_back(o.postures_path + ":" + std::to_string(r.postures[f.input_index].line) + ": " + f.message);
    Tell(tell, Message::Kind::kWarning, r.warnings.back());
  }
  for (dynamics::PosturePredictionResult& p : result.postures) {
    r.predictions.push_back({p.id, o.freq_hz, std::move(p.H)});
    r.dynamics.push_back(std::move(p.dynamics));
  }
  if (!r.uncertainty) return r;
  const long n = static_cast<long>(r.postures.size());
  if (o.intervals) {
    for (long p = 0; p < n; ++p) {
      r.intervals.push_back(dynamics::ModalIntervals(r.config.description, r.config.parameters,
                                                     r.postures[static_cast<size_t>(p)].q, *r.uncertainty,
                                                     o.uncertainty));
      if (progress) progress("postures' intervals", p + 1, n);
    }
    for (long p = 0; p < n; ++p) {
      Tell(tell, Message::Kind::kInfo,
           dynamics::IntervalLine(r.postures[static_cast<size_t>(p)].id, r.intervals[static_cast<size_t>(p)],
                                  o.uncertainty.confidence));
    }
  }
  // The |H| bands of the postures drawn (issue #37 §3).
  const long drawn = static_cast<long>(std::min(r.postures.size(), o.band_postures));
  for (long p = 0; p < drawn; ++p) {
    r.bands.push_back(dynamics::DirectReceptanceBand(r.config.description, r.config.parameters,
                                                     r.postures[static_cast<size_t>(p)].q, *r.uncertainty,
                                                     r.predictions[static_cast<size_t>(p)].freq_hz, o.uncertainty));
    if (progress) progress("|H| bands", p + 1, drawn);
  }
  if (!r.bands.empty()) {
    Tell(tell, Message::Kind::kInfo,
         "the plots show the " + FormatNumber(100.0 * o.uncertainty.confidence, 3) + " % band of |H| (" +
             r.bands.front().propagation.reason + ")");
  }
  return r;
}

}  // namespace robomach::workflows
