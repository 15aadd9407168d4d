#include "robomach/workflows/frf_synth.h"

#include <cctype>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "robomach/common/errors.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/number_format.h"
#include "robomach/dynamics/frf_prediction.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/posture_file.h"
#include "robomach/workflows/frf_predict.h"
#include "robomach/workflows/robot_config.h"

namespace robomach::workflows {
namespace {

// Plausible ranges of the options (docs/plausibility.md). Hammer tests of
// robots and machine tools: lines to 0.1 - 10 kHz, sampled at 1 - 200 kHz
// (Schmitz and Smith, "Machining Dynamics", ch. 2; the seed's 5120 Hz); hammer
// tips cut off at 0.5 kHz (soft) to 10 kHz and more (steel; PCB 086 series
// data sheets). Noise floors: tool-tip receptances are 1e-8 - 1e-5 m/N, a
// floor 1e-4 - 1e-2 of the peak (Ewins, "Modal Testing", §3); accelerometers
// resolve 1e-4 - 1e-2 m/s² under 10 - 1000 N impacts.
constexpr double kMinPlausibleSampleRateHz = 100.0, kMaxPlausibleSampleRateHz = 1e6;
constexpr double kMinPlausibleHammerCutoffHz = 50.0, kMaxPlausibleHammerCutoffHz = 50000.0;
constexpr double kMaxPlausibleNoiseMPerN = 1e-6;       // receptance floor
constexpr double kMaxPlausibleNoiseMPerSPerN = 1e-3;   // mobility floor
constexpr double kMaxPlausibleNoiseMPerS2PerN = 10.0;  // accelerance floor
constexpr double kMaxFrequencyHz = 1e9;                // refused above

}  // namespace

void FrfSynthOptions::Validate() const {
  const calibration::VirtualHammerOptions& h = hammer;
  const auto num = [](double v) { return FormatNumber(v, 7); };
  CheckOptionRange("block_samples", static_cast<double>(h.block_samples), 2, 1 << 22);
  CheckOptionRange("averages", h.averages, h.coherence ? 2 : 1, 100000);
  if (std::isinf(h.relative_noise)) {  // "1e400" reads as infinity
    throw OptionError("relative_noise",
                      "relative_noise " + num(h.relative_noise) +
                          ": expected a finite noise rms >= 0, as a fraction of the FRF (0.02 = 2 %)");
  }
  if (h.relative_noise > kMaxRelativeNoise) {
    throw OptionError("relative_noise",
                      "relative_noise " + num(h.relative_noise) +
                          ": expected the noise as a fraction of the FRF (0.02 = 2 %), at most 10; the noise would "
                          "bury the FRF " + num(h.relative_noise) + " times over: for 2 % give relative_noise 0.02");
  }
  for (const auto& [name, v] : {std::pair{"fmax_hz", h.fmax_hz}, std::pair{"hammer_cutoff_hz", h.hammer_cutoff_hz}}) {
    if (!(v >= 0.0 && v <= kMaxFrequencyHz)) {
      throw OptionError(name, std::string(name) + " " + num(v) + ": expected a frequency in [0, 1e9] Hz");
    }
  }
  // fmin_hz against the band here, where both are the options' (the Nyquist
  // check of fmax_hz needs the config's rate: VirtualHammerOptions').
  if (!(h.fmin_hz > 0.0 && h.fmin_hz <= kMaxFrequencyHz)) {
    throw OptionError("fmin_hz", "fmin_hz " + num(h.fmin_hz) + ": expected a frequency in (0, 1e9] Hz (the 0 Hz line is "
                                                               "not measured)");
  }
  if (!(h.fmin_hz < h.fmax_hz)) {
    throw OptionError("fmin_hz", "fmin_hz " + num(h.fmin_hz) + ": expected a frequency below fmax_hz " +
                                     num(h.fmax_hz) + " Hz");
  }
  // NaN: the config's rate; infinity is a value given (and refused).
  if (!std::isnan(h.sample_rate_hz) && !(h.sample_rate_hz > 0.0 && h.sample_rate_hz <= kMaxFrequencyHz)) {
    throw OptionError("sample_rate_hz", "sample_rate_hz " + num(h.sample_rate_hz) + ": expected a rate in (0, 1e9] Hz");
  }
  for (const auto& [name, v] : {std::pair{"absolute_noise_m_per_N", h.absolute_noise_m_per_N},
                                std::pair{"absolute_noise_m_per_s_per_N", h.absolute_noise_m_per_s_per_N},
                                std::pair{"absolute_noise_m_per_s2_per_N", h.absolute_noise_m_per_s2_per_N}}) {
    if (!(v >= 0.0) || !std::isfinite(v)) {
      throw OptionError(name, std::string(name) + " " + num(v) + ": expected a noise rms >= 0");
    }
  }
}

std::vector<std::string> FrfSynthOptions::UnitFindings() const {
  const calibration::VirtualHammerOptions& h = hammer;
  std::vector<std::string> out;
  const auto flag = [&](const std::string& m) {
    if (!m.empty()) out.push_back(m);
  };
  const std::string noise_rel = Name("relative_noise");
  if (h.relative_noise > kMaxPlausibleRelativeNoise) {
    out.push_back("implausible (unit mistake?): " + noise_rel + " " + FormatNumber(h.relative_noise, 7) +
                  " is a noise rms of " + FormatNumber(100.0 * h.relative_noise, 3) +
                  " % of the FRF; hammer tests have 0.1 to 10 % (plausible up to 50 %): a percentage typed for a "
                  "fraction? 2 % is " + noise_rel + " 0.02");
  }
  flag(ImplausibleOption(Name("fmax_hz"), h.fmax_hz, dynamics::kMinPlausibleFmaxHz, dynamics::kMaxPlausibleFmaxHz, "Hz",
                   "hammer tests (lines to 0.1 - 10 kHz)", "a frequency in kHz typed in the Hz option?",
                   "a frequency in mHz typed in the Hz option, or a line count?"));
  if (std::isfinite(h.sample_rate_hz)) {
    flag(ImplausibleOption(Name("sample_rate_hz"), h.sample_rate_hz, kMinPlausibleSampleRateHz, kMaxPlausibleSampleRateHz,
                     "Hz", "hammer-test acquisition (1 - 200 kHz)", "a rate in kHz typed in the Hz option?",
                     "a rate in mHz typed in the Hz option?"));
  }
  if (h.hammer_cutoff_hz > 0.0) {
    flag(ImplausibleOption(Name("hammer_cutoff_hz"), h.hammer_cutoff_hz, kMinPlausibleHammerCutoffHz,
                     kMaxPlausibleHammerCutoffHz, "Hz", "hammer tips (0.5 - 10 kHz; 0: flat)",
                     "a frequency in kHz typed in the Hz option?", "a frequency in mHz typed in the Hz option?"));
  }
  flag(ImplausibleOption(Name("absolute_noise_m_per_N"), h.absolute_noise_m_per_N, 0.0, kMaxPlausibleNoiseMPerN, "m/N",
                   "receptance noise floors (tool tips are 1e-8 - 1e-5 m/N)", "",
                   "a noise in mm/N or um/N typed in the m/N option?"));
  flag(ImplausibleOption(Name("absolute_noise_m_per_s_per_N"), h.absolute_noise_m_per_s_per_N, 0.0,
                   kMaxPlausibleNoiseMPerSPerN, "(m/s)/N", "mobility noise floors", "",
                   "a noise in (mm/s)/N typed in the (m/s)/N option?"));
  flag(ImplausibleOption(Name("absolute_noise_m_per_s2_per_N"), h.absolute_noise_m_per_s2_per_N, 0.0,
                   kMaxPlausibleNoiseMPerS2PerN, "(m/s²)/N",
                   "accelerance noise floors (accelerometers resolve 1e-4 - 1e-2 m/s² under 10 - 1000 N)", "",
                   "a noise in (mm/s²)/N typed in the (m/s²)/N option?"));
  return out;
}

FrfSynthSetup PrepareFrfSynth(const FrfSynthOptions& o, const MessageSink& tell) {
  o.Validate();
  FrfSynthSetup s;
  s.config = workflows::LoadRobotConfigChecked(o.robot_path);
  for (const std::string& w : s.config.implausible) Tell(tell, Message::Kind::kWarning, w);
  ApplyAddsAndSets(o.adds, o.sets, &s.config);
  s.hammer = o.hammer;
  if (!std::isfinite(o.hammer.sample_rate_hz)) {
    s.hammer.sample_rate_hz = calibration::ConfiguredSampleRateHz(s.config.description);
    const auto at = s.config.extra_value_locations.find("hammer_test.sample_rate_hz");
    if (at != s.config.extra_value_locations.end()) s.sample_rate_at = at->second.ToString();
  }
  return s;
}

FrfSynthRun RunFrfSynth(const FrfSynthOptions& o, FrfSynthSetup setup, const MessageSink& tell) {
  FrfSynthRun r;
  r.config = std::move(setup.config);
  r.hammer = std::move(setup.hammer);
  std::vector<std::string> option_findings = o.UnitFindings();  // not const: listed with posture_units below
  try {
    r.hammer.Validate();
  } catch (const std::invalid_argument& e) {
    // "VirtualHammerOptions: fmax_hz ...": the field is the first word. An
    // implausible option (a rate in kHz) is the likely cause: say so.
    const std::string m = e.what(), prefix = "VirtualHammerOptions: ";
    const size_t start = m.rfind(prefix, 0) == 0 ? prefix.size() : 0;
    std::string why;
    for (const std::string& w : option_findings) why += "; the likely cause, " + w;
    throw OptionError(m.substr(start, m.find_first_of(" :", start) - start), m + why);
  }
  const auto model = r.config.Build();
  std::vector<calibration::NamedPosture> postures;
  std::vector<std::string> posture_units;  // radians under _deg headers, ...
  for (const io::Posture& p : io::ReadPostureFile(o.postures_path, model->num_joints(), &posture_units)) {
    postures.push_back({p.id, p.q});
  }
  r.unit_findings = r.config.implausible;
  for (const auto* list : {&posture_units, &option_findings}) {
    for (const std::string& w : *list) Tell(tell, Message::Kind::kWarning, w);
    r.unit_findings.insert(r.unit_findings.end(), list->begin(), list->end());
  }
  r.frfs = calibration::SynthesizeHammerTest(model, postures, r.hammer);
  return r;
}

FrfSynthRun RunFrfSynth(const FrfSynthOptions& o, const MessageSink& tell) {
  return RunFrfSynth(o, PrepareFrfSynth(o, tell), tell);
}

FrfFileFormat FrfSynthOutputFormat(const std::string& path, const std::string& name, bool allow_stdout) {
  if (allow_stdout && path == "-") return FrfFileFormat::kCsv;
  // The format follows the extension: refuse one we do not write (a .png
  // would get CSV text).
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".uff" || ext == ".unv" || ext == ".uf") return FrfFileFormat::kUff58;
  if (ext != ".csv") {
    throw OptionError(name, name + " " + path +
                                ": expected a file name ending in .csv (the FRF CSV of docs/formats.md §3) or .uff, "
                                ".unv (UFF58)" +
                                (allow_stdout ? ", or '-' for standard output (CSV)" : ""));
  }
  return FrfFileFormat::kCsv;
}

void WriteFrfSynthOutput(const FrfSynthRun& run, const FrfSynthOptions& o, const std::string& path,
                         FrfFileFormat format, io::FrfQuantity quantity, const MessageSink& tell) {
  const calibration::VirtualHammerOptions& h = run.hammer;
  if (format == FrfFileFormat::kUff58 && path != "-") {
    if (h.coherence && h.averages > 1) {
      Tell(tell, Message::Kind::kWarning,
           "UFF58 has no field for the number of averages: give " + o.Name("averages") + " " +
               std::to_string(h.averages) + " to the tools that read " + path);
    }
    io::WriteUff58(path, run.frfs, quantity);
  } else {
    io::WriteFrfCsv(path, run.frfs, quantity, h.coherence ? h.averages : 0);
  }
}

nlohmann::json FrfSynthRun::Summary(const FrfSynthOptions& o) const {
  const calibration::VirtualHammerOptions& h = hammer;
  nlohmann::json j;
  j["robot"] = o.robot_path;
  j["postures"] = o.postures_path;
  j["sets"] = o.sets;
  j["adds"] = o.adds;
  j["sample_rate_hz"] = h.sample_rate_hz;
  j["block_samples"] = h.block_samples;
  j["line_spacing_hz"] = h.sample_rate_hz / h.block_samples;
  j["fmin_hz"] = h.fmin_hz;
  j["fmax_hz"] = h.fmax_hz;
  j["noise_rel"] = h.relative_noise;
  j["noise_abs_m_per_N"] = h.absolute_noise_m_per_N;
  j["noise_abs_m_per_s_per_N"] = h.absolute_noise_m_per_s_per_N;
  j["noise_abs_m_per_s2_per_N"] = h.absolute_noise_m_per_s2_per_N;
  j["hammer_cutoff_hz"] = h.hammer_cutoff_hz;
  j["averages"] = h.averages;
  j["coherence"] = h.coherence;
  j["seed"] = h.seed;
  j["frf_count"] = frfs.size();
  // Per FRF: the line of largest |H| (receptance, with the noise, as written).
  nlohmann::json list = nlohmann::json::array();
  for (const auto& [key, frf] : frfs) {
    Eigen::Index k = 0;
    const double peak = frf.receptance().cwiseAbs().maxCoeff(&k);
    list.push_back({{"pose_id", key.pose_id},
                    {"response", std::string(1, AxisName(key.response))},
                    {"excitation", std::string(1, AxisName(key.excitation))},
                    {"lines", frf.size()},
                    {"freq_min_hz", frf.freq_hz()(0)},
                    {"freq_max_hz", frf.freq_hz()(frf.size() - 1)},
                    {"peak_freq_hz", frf.freq_hz()(k)},
                    {"peak_receptance_m_per_N", peak}});
  }
  j["frfs"] = list;
  j["flagged"] = flagged();
  return j;
}

}  // namespace robomach::workflows
