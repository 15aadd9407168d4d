#include "measured_data.h"

#include <CLI/CLI.hpp>

#include <iostream>
#include <sstream>

#include "cli_support.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/common/errors.h"
#include "robomach/io/frf_files.h"

namespace robomach::apps {

MeasuredData ReadMeasuredFiles(const std::string& tool, const std::vector<std::string>& files,
                               const std::vector<std::string>& pose_files, const std::string& what,
                               const std::string& pose_option, bool keep_points) {
  MeasuredData all;
  auto add = [&](const std::string& path, const std::string& pose) {
    RequireReadableFile(path, what);
    const io::FrfReadResult r = io::ReadFrfFile(path, pose, keep_points);
    for (const std::string& w : r.warnings) Warn(tool, w);
    for (const std::string& n : r.notes) Note(tool, n);
    // On each FRF's usable band only (issue #34 item 5): a tap test's drift
    // lines are no measure of the unit.
    for (const std::string& f : calibration::ReceptanceUnitFindings(r.frfs, path, r.averages, r.file_format)) {
      Warn(tool, "implausible (unit mistake?): " + f);
      all.unit_findings.push_back(f);
    }
    for (const auto& [key, frf] : r.frfs) {
      if (key.pose_id.empty()) {
        throw InputError({path, 0, 0}, "the FRFs of this file name no posture: give it as " + pose_option + " P1=" + path +
                                           " (P1 a pose_id of the posture file), or put pose=P1 in ID line 1 of "
                                           "each UFF58 record");
      }
      if (all.frfs.contains(key)) {
        throw InputError({path, 0, 0}, "FRF " + key.ToString() + " was already read from " + all.file.at(key));
      }
      all.frfs.Insert(key, frf);
      all.averages[key] = r.averages;
      all.file[key] = path;
      all.file_power[key] = r.file_quantity == io::FrfQuantity::kReceptance  ? 0
                            : r.file_quantity == io::FrfQuantity::kMobility ? 1
                                                                            : 2;
    }
  };
  for (const std::string& f : files) add(f, "");
  for (const std::string& a : pose_files) {
    const auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == a.size()) {
      throw UsageError(pose_option + " '" + a + "': expected ID=file.uff, e.g. " + pose_option + " P1=p1.uff");
    }
    add(a.substr(eq + 1), a.substr(0, eq));
  }
  // Files were given and read, but none held an FRF (a UFF with only other
  // datasets, a CSV with a header and no lines): bad input data, exit 65,
  // not a command-line error.
  if (all.frfs.empty() && !(files.empty() && pose_files.empty())) {
    std::string names;
    std::string first;
    for (const std::string& f : files) {
      names += (names.empty() ? "" : ", ") + f;
      if (first.empty()) first = f;
    }
    for (const std::string& a : pose_files) {
      const std::string f = a.substr(a.find('=') + 1);
      names += (names.empty() ? "" : ", ") + f;
      if (first.empty()) first = f;
    }
    throw InputError({first, 0, 0}, "no " + what + " holds an FRF (read: " + names + ")");
  }
  return all;
}

void AddNoiseOptions(CLI::App& app, NoiseCliOptions* o) {
  app.add_option("--noise-model", o->model,
                 "noise of each measured FRF: auto (from the coherence when the file has one and the number of "
                 "averages is known, else estimated from the scatter of the data), coherence, scatter, or none "
                 "(every line, weights 1/|H|: no noise model)")
      ->check(CLI::IsMember({"auto", "coherence", "scatter", "none"}))
      ->capture_default_str();
  app.add_option("--min-snr", o->min_snr,
                 "a line is used where |H| is at least this many times the additive noise floor (3: the "
                 "log-magnitude and phase residuals are unbiased there; see docs/noise-model.md)")
      ->capture_default_str();
  app.add_flag("--drift-floor", o->drift_floor,
               "tap tests whose integrated accelerometer drifts at low frequency: the noise floor also from "
               "second differences over 8 and 16 lines of the residual about the modal fit, so that no mode is "
               "fitted in the drift (off by default: it can also count a smooth model misfit as noise)");
  app.add_option("--averages", o->averages,
                 "number of averaged impacts behind the coherence, for files without '# averages: N' (UFF58)");
}

calibration::NoiseModels EstimateNoiseModels(const std::string& tool, const MeasuredData& data,
                                             const NoiseCliOptions& o) {
  CheckOptionRange("--min-snr", o.min_snr, 1e-3, 1e6);
  CheckOptionRange("--averages", o.averages, 0, 1e6);
  calibration::NoiseModels out;
  if (o.model == "none") return out;
  std::cerr << tool << ": noise model of " << data.frfs.size() << " FRFs (usable where |H| >= " << o.min_snr
            << " x floor)\n";
  int none_usable = 0;
  for (const auto& [key, frf] : data.frfs) {
    calibration::NoiseOptions no;
    no.min_snr = o.min_snr;
    no.averages = o.averages > 0 ? o.averages : data.averages.at(key);
    no.use_coherence = o.model != "scatter";
    no.wide_floor = o.drift_floor;
    no.global_modal_fit = o.global_modal_fit;
    if (o.model == "coherence") {
      if (!frf.coherence()) {
        throw UsageError("--noise-model coherence: " + key.ToString() + " (" + data.file.at(key) +
                         ") has no coherence; use --noise-model scatter or auto");
      }
      if (no.averages == 0) {
        throw UsageError("--noise-model coherence: " + data.file.at(key) +
                         " does not say how many averages are behind its coherence ('# averages: N'); "
                         "give --averages N");
      }
    }
    if (o.model == "auto" && frf.coherence() && no.averages == 0) {
      Warn(tool, key.ToString() + ": the coherence is not used because " + data.file.at(key) +
                     " does not give the number of averages ('# averages: N'; or --averages N); the noise is "
                     "estimated from the scatter");
    }
    calibration::FrfNoise n;
    try {
      n = calibration::EstimateFrfNoise(frf, no);
    } catch (const std::invalid_argument& e) {
      throw InputError({data.file.at(key), 0, 0}, key.ToString() + ": " + e.what());
    }
    const bool points = key.response_point != 0 || key.excitation_point != 0;
    std::cerr << tool << ": " << key.pose_id << " "
              << (points ? key.Label() : std::string{AxisName(key.response), AxisName(key.excitation)}) << ": "
              << n.description << '\n';
    if (n.usable_lines == 0) {
      ++none_usable;
      Warn(tool, key.ToString() + ": no line reaches the signal-to-noise ratio " + std::to_string(o.min_snr) +
                     "; this FRF is not used");
    }
    out.emplace(key, std::move(n));
  }
  return out;
}

dynamics::FrfSet FitData(const MeasuredData& data, const calibration::NoiseModels& noise) {
  if (noise.empty()) return data.frfs;
  dynamics::FrfSet out = calibration::UsableData(data.frfs, noise);
  if (out.empty()) {
    throw InputError({data.file.begin()->second, 0, 0},
                     "no measured FRF has a usable line (signal-to-noise ratio below --min-snr everywhere)");
  }
  return out;
}

}  // namespace robomach::apps
