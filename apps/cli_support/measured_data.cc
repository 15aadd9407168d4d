#include "measured_data.h"

#include <CLI/CLI.hpp>

#include <iostream>
#include <sstream>

#include "cli_support.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/common/errors.h"
#include "robomach/common/messages.h"
#include "robomach/io/uncertainty_file.h"

namespace robomach::apps {

namespace {


workflows::MeasuredFrfOptions LibraryOptions(const NoiseCliOptions& o) {
  CheckOptionRange("--min-snr", o.min_snr, 1e-3, 1e6);
  CheckOptionRange("--averages", o.averages, 0, 1e6);
  workflows::MeasuredFrfOptions w;
  w.noise_model = workflows::ParseNoiseModelChoice(o.model);  // CLI11 checked the name
  w.min_snr = o.min_snr;
  w.averages = o.averages;
  w.drift_floor = o.drift_floor;
  w.global_modal_fit = o.global_modal_fit;
  return w;
}

}  // namespace

MeasuredData ReadMeasuredFiles(const std::string& tool, const std::vector<std::string>& files,
                               const std::vector<std::string>& pose_files, const std::string& what,
                               const std::string& pose_option, bool keep_points, const std::string& default_pose) {
  workflows::MeasuredFrfOptions o;
  o.files = files;
  for (const std::string& a : pose_files) {
    const auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == a.size()) {
      throw UsageError(pose_option + " '" + a + "': expected ID=file.uff, e.g. " + pose_option + " P1=p1.uff");
    }
    o.posed_files.push_back({a.substr(0, eq), a.substr(eq + 1)});
  }
  o.default_pose = default_pose;
  o.what = what;
  o.pose_option = pose_option;
  o.keep_points = keep_points;
  return workflows::ReadMeasuredFrfFiles(o, MessagePrinter(tool));
}

void AddNoiseOptions(CLI::App& app, NoiseCliOptions* o) {
  app.add_option("--noise-model", o->model,
                 "noise of each measured FRF: auto (from the coherence when the file has one and the number of "
                 "averages is known, else estimated from the scatter of the data), coherence, scatter, or none "
                 "(every line, weights 1/|H|: no noise model)")
      ->check(OneOf({"auto", "coherence", "scatter", "none"}))
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
                 "number of averaged impacts behind the coherence, for files without '# averages: N' (UFF58)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            // 0 is the library's "not known"; typed, it is a mistake (issue #35).
            long n = 0;
            std::istringstream in(text);
            if (!(in >> n) || !in.eof() || n < 1 || n > 1000000) {
              return "expected the number of averaged impacts, a whole number from 1 to 1000000, got " + text +
                     " (leave --averages out when the file gives '# averages: N' or the number is not known)";
            }
            return "";
          },
          "N >= 1"));
}

calibration::NoiseModels EstimateNoiseModels(const std::string& tool, const MeasuredData& data,
                                             const NoiseCliOptions& o) {
  const workflows::MeasuredFrfOptions w = LibraryOptions(o);
  try {
    return workflows::EstimateNoiseModels(data, w, MessagePrinter(tool));
  } catch (const OptionError& e) {
    throw NoiseOptionError(o, e);
  }
}

UsageError NoiseOptionError(const NoiseCliOptions& o, const OptionError& e) {
  // The data cannot meet an option: the option, and what to give.
  return UsageError((e.field() == "averages" ? "--noise-model " + o.model + " needs --averages N: "
                                             : "--noise-model " + o.model + ": ") +
                    std::string(e.what()));
}

nlohmann::json WriteFittedUncertainty(const std::string& tool, const std::string& path,
                                      const calibration::CalibrationResult& result, const std::string& source) {
  if (path.empty()) return nullptr;
  const calibration::FittedUncertainty fu = calibration::FittedParameterUncertainty(result, source);
  std::string left_out;
  for (const std::string& w : fu.left_out) left_out += (left_out.empty() ? "" : "; ") + w;
  if (fu.uncertainty.parameters.empty()) {
    const std::string w = "--uncertainty-out " + path + " not written: no fitted parameter has a covariance (" +
                          left_out + ")";
    Warn(tool, w);
    return {{"file", path}, {"written", false}, {"left_out", fu.left_out}, {"warning", w}};
  }
  io::WriteParameterUncertainty(path, fu.uncertainty);
  nlohmann::json names = nlohmann::json::array();
  for (const auto& p : fu.uncertainty.parameters) names.push_back(p.name);
  std::ostringstream m;
  m << tool << ": wrote the covariance of " << fu.uncertainty.parameters.size() << " fitted parameter"
    << (fu.uncertainty.parameters.size() == 1 ? "" : "s") << " to " << path;
  if (!left_out.empty()) m << "; left out (taken as exact by the tools that read it): " << left_out;
  std::cerr << m.str() << '\n';
  return {{"file", path}, {"written", true}, {"parameters", names}, {"left_out", fu.left_out}};
}

}  // namespace robomach::apps
