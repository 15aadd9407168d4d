#include "robomach/workflows/frf_estimate.h"

#include <cctype>
#include <sstream>

#include "robomach/common/frames.h"
#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"

namespace robomach::workflows {
namespace {

Axis ParseExcitation(const std::string& text) {
  try {
    return ParseAxis(text);
  } catch (const std::invalid_argument& e) {
    throw OptionError("excitation", std::string("excitation: ") + e.what());
  }
}

}  // namespace

void FrfEstimateRunOptions::Validate() const {
  if (record_paths.empty()) throw OptionError("record_paths", "record_paths: give at least one hammer record file");
  ParseExcitation(excitation);
  if (estimator != "h1" && estimator != "h2") {
    throw OptionError("estimator", "estimator: expected h1 or h2, got '" + estimator + "'");
  }
  if (!(min_hits >= 1 && min_hits <= 1000000)) {
    throw OptionError("min_hits", "min_hits " + std::to_string(min_hits) + " is outside [1, 1000000]");
  }
  estimate.Validate();
}

nlohmann::json FrfEstimateRun::Summary(const std::string& estimator) const {
  nlohmann::json j = io::FrfEstimateSummaryJson(result, records, keys);
  j["estimator"] = estimator == "h1" ? "H1" : "H2";
  std::vector<std::string> flags;
  for (const Finding& f : verdict.findings) flags.push_back(f.message);
  j["flags"] = flags;
  return j;
}

std::string FrfEstimateRun::Outcome() const {
  const calibration::FrfEstimateResult& r = result;
  std::ostringstream m;
  m << r.averages << " of " << r.hits.size() << " hits averaged";
  std::vector<std::string> rejected;
  for (const auto& h : r.hits) {
    if (h.status != calibration::HitStatus::kAccepted) {
      rejected.push_back(h.id + " (" + calibration::ToString(h.status) + ")");
    }
  }
  if (!rejected.empty()) {
    m << " (rejected: ";
    for (size_t i = 0; i < rejected.size(); ++i) m << (i ? ", " : "") << rejected[i];
    m << ")";
  }
  m << "; " << (frfs ? frfs->frfs.size() : 0) << " FRF(s) of " << r.freq_hz.size() << " lines, "
    << FormatNumber(r.freq_hz(0)) << " to " << FormatNumber(r.freq_hz(r.freq_hz.size() - 1), 6) << " Hz";
  return m.str();
}

std::map<std::string, std::string> ParseDirections(const std::vector<std::string>& texts) {
  std::map<std::string, std::string> out;
  for (const std::string& d : texts) {
    const size_t eq = d.find('=');
    if (eq == std::string::npos || eq == 0) throw OptionError("directions", "directions: expected NAME=AXIS, got '" + d + "'");
    out[d.substr(0, eq)] = d.substr(eq + 1);
  }
  return out;
}

FrfEstimateRun RunFrfEstimate(const FrfEstimateRunOptions& o, const MessageSink& on_message) {
  o.Validate();
  const Axis exc = ParseExcitation(o.excitation);
  FrfEstimateRun run;
  run.records = io::ReadHammerRecords(o.record_paths);
  const io::HammerRecords& rec = run.records;
  // Keys before the work, so that a naming problem is reported at once.
  try {
    run.keys = io::ChannelKeys(rec, o.pose_id, exc, o.directions);
  } catch (const std::invalid_argument& e) {
    throw OptionError("directions", std::string("directions ") + e.what());
  }
  calibration::FrfEstimateOptions est = o.estimate;
  try {
    est.response_range = io::ResponseRanges(rec, o.response_ranges);
  } catch (const std::invalid_argument& e) {
    throw OptionError("response_range", std::string("response_range ") + e.what());
  }
  // Options that the records' sample rate decides (docs/frf-estimate.md).
  const double fs = rec.hits.front().sample_rate_hz;
  if (est.fmax_hz > 0.5 * fs) {
    throw OptionError("fmax_hz", "fmax_hz " + FormatNumber(est.fmax_hz, 7) + ": above the Nyquist frequency " +
                                     FormatNumber(0.5 * fs, 7) + " Hz of the records (sample rate " +
                                     FormatNumber(fs, 7) + " Hz): the highest line is at most fs/2 (0, the default: "
                                     "fs/2.56 = " + FormatNumber(fs / 2.56, 7) + " Hz)");
  }
  if (est.exponential_tau_s > 0.0 && est.exponential_tau_s < calibration::kMinExponentialWindowSamples / fs) {
    const double f_hi = est.fmax_hz > 0.0 ? est.fmax_hz : fs / 2.56;
    throw OptionError(
        "exponential_tau_s",
        "exponential_tau_s " + FormatNumber(est.exponential_tau_s, 7) + ": shorter than " +
            FormatNumber(calibration::kMinExponentialWindowSamples, 3) + " sample periods (" +
            FormatNumber(calibration::kMinExponentialWindowSamples / fs, 3) + " s at " + FormatNumber(fs, 7) +
            " Hz): the window would add a damping ratio 1/(tau omega) of " +
            FormatNumber(1.0 / (est.exponential_tau_s * 2.0 * kPi * f_hi), 3) + " even at " +
            FormatNumber(f_hi, 6) + " Hz, more at lower lines; choose tau near the record length / 4.6 "
            "(docs/frf-estimate.md)");
  }
  {
    std::ostringstream m;
    m << rec.hits.size() << " hit(s) at " << FormatNumber(fs, 7) << " Hz; pose " << o.pose_id << ", excitation "
      << AxisName(exc) << ", responses";
    for (size_t c = 0; c < run.keys.size(); ++c) {
      m << (c ? ", " : " ") << rec.channel_columns[c] << " -> " << AxisName(run.keys[c].response);
    }
    m << " (--pose-id, --excitation, --direction)";
    Tell(on_message, Message::Kind::kInfo, m.str());
  }
  run.result = calibration::EstimateFrf(rec.hits, rec.channels, est);
  for (const auto& h : run.result.hits) {
    if (h.status == calibration::HitStatus::kAccepted) continue;
    for (const std::string& note : h.notes) {
      Tell(on_message, Message::Kind::kInfo,
           "hit " + h.id + " (" + h.source + ", hit at t = " + FormatNumber(h.hit_time_s, 6) + " s) rejected: " + note);
    }
  }
  for (const std::string& w : run.result.warnings) Tell(on_message, Message::Kind::kWarning, w);
  run.verdict = calibration::JudgeFrfEstimate(run.result, o.min_hits, o.min_hits_name);
  for (const Finding& f : run.verdict.findings) Tell(on_message, Message::Kind::kWarning, "result flagged: " + f.message);
  if (!run.every_hit_rejected()) run.frfs = io::ToEstimatedFrfs(run.result, rec, run.keys, o.estimator == "h2");
  return run;
}

}  // namespace robomach::workflows
