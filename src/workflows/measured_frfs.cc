#include "robomach/workflows/measured_frfs.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/io/file_kind.h"
#include "robomach/io/frf_files.h"

namespace robomach::workflows {
namespace {

// A missing or unreadable input file: io::MissingFileError (the tools'
// exit 66), named as the options name it.
void RequireReadable(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw io::MissingFileError({path, 0, 0}, what + " not found");
  if (fs::is_directory(path, ec)) throw io::MissingFileError({path, 0, 0}, what + " is a directory, expected a file");
  std::ifstream in(path);
  if (!in) throw io::MissingFileError({path, 0, 0}, what + " cannot be read");
}

}  // namespace

const char* ToString(NoiseModelChoice c) {
  switch (c) {
    case NoiseModelChoice::kAuto: return "auto";
    case NoiseModelChoice::kCoherence: return "coherence";
    case NoiseModelChoice::kScatter: return "scatter";
    case NoiseModelChoice::kNone: return "none";
  }
  return "?";
}

NoiseModelChoice ParseNoiseModelChoice(const std::string& name) {
  for (NoiseModelChoice c :
       {NoiseModelChoice::kAuto, NoiseModelChoice::kCoherence, NoiseModelChoice::kScatter, NoiseModelChoice::kNone}) {
    if (name == ToString(c)) return c;
  }
  throw OptionError("noise_model", "unknown noise model '" + name + "'; expected auto, coherence, scatter or none");
}

void MeasuredFrfOptions::Validate() const {
  if (!(min_snr >= 1e-3 && min_snr <= 1e6)) {
    throw OptionError("min_snr", "min_snr " + FormatNumber(min_snr) + " is outside [0.001, 1e6]");
  }
  if (averages < 0 || averages > 1000000) {
    throw OptionError("averages", "averages " + std::to_string(averages) + " is outside [0, 1000000]");
  }
}

dynamics::FrfSet MeasuredFrfs::FitData() const { return workflows::FitData(*this, noise); }

dynamics::FrfSet FitData(const MeasuredFrfs& data, const calibration::NoiseModels& noise) {
  if (noise.empty()) return data.frfs;
  dynamics::FrfSet out = calibration::UsableData(data.frfs, noise);
  if (out.empty()) {
    throw InputError({data.file.empty() ? std::string() : data.file.begin()->second, 0, 0},
                     "no measured FRF has a usable line (the noise model found none above the noise floor; see "
                     "--min-snr and docs/noise-model.md)");
  }
  return out;
}

MeasuredFrfs ReadMeasuredFrfFiles(const MeasuredFrfOptions& o, const MessageSink& on_message) {
  o.Validate();
  MeasuredFrfs all;
  auto add = [&](const std::string& path, const std::string& pose) {
    RequireReadable(path, o.what);
    const io::FrfReadResult r = io::ReadFrfFile(path, pose, o.keep_points);
    for (const std::string& w : r.warnings) Tell(on_message, Message::Kind::kWarning, w);
    for (const std::string& n : r.notes) Tell(on_message, Message::Kind::kNote, n);
    // On each FRF's usable band only (issue #34 item 5): a tap test's drift
    // lines are no measure of the unit.
    std::vector<std::string> unit_findings = io::FrequencyUnitFindings(r, path);
    // A frequency axis in kHz makes every receptance judgement moot.
    if (unit_findings.empty()) unit_findings = calibration::ReceptanceUnitFindings(r.frfs, path, r.averages, r.file_format);
    for (const std::string& f : unit_findings) {
      Tell(on_message, Message::Kind::kWarning, "implausible (unit mistake?): " + f);
      all.unit_findings.push_back(f);
    }
    for (const auto& [key, frf] : r.frfs) {
      if (key.pose_id.empty()) {
        throw InputError({path, 0, 0}, "the FRFs of this file name no posture: give it as " + o.pose_option +
                                           " P1=" + path +
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
  for (const std::string& f : o.files) add(f, o.default_pose);
  for (const auto& [pose, f] : o.posed_files) add(f, pose);
  // Files were given and read, but none held an FRF (a UFF with only other
  // datasets, a CSV with a header and no lines): bad input data, not a bad
  // command line.
  if (all.frfs.empty() && !(o.files.empty() && o.posed_files.empty())) {
    std::string names, first;
    auto name = [&](const std::string& f) {
      names += (names.empty() ? "" : ", ") + f;
      if (first.empty()) first = f;
    };
    for (const std::string& f : o.files) name(f);
    for (const auto& [pose, f] : o.posed_files) name(f);
    throw InputError({first, 0, 0}, "no " + o.what + " holds an FRF (read: " + names + ")");
  }
  return all;
}

calibration::NoiseModels EstimateNoiseModels(const MeasuredFrfs& data, const MeasuredFrfOptions& o,
                                             const MessageSink& on_message) {
  o.Validate();
  calibration::NoiseModels out;
  if (o.noise_model == NoiseModelChoice::kNone) return out;
  {
    std::ostringstream m;
    m << "noise model of " << data.frfs.size() << " FRFs (usable where |H| >= " << o.min_snr << " x floor)";
    Tell(on_message, Message::Kind::kInfo, m.str());
  }
  for (const auto& [key, frf] : data.frfs) {
    const std::string& file = data.file.at(key);
    calibration::NoiseOptions no;
    no.min_snr = o.min_snr;
    no.averages = o.averages > 0 ? o.averages : data.averages.at(key);
    no.use_coherence = o.noise_model != NoiseModelChoice::kScatter;
    no.wide_floor = o.drift_floor;
    no.global_modal_fit = o.global_modal_fit;
    if (o.noise_model == NoiseModelChoice::kCoherence) {
      if (!frf.coherence()) {
        throw OptionError("noise_model", key.ToString() + " (" + file +
                                             ") has no coherence; use the noise model scatter or auto");
      }
      if (no.averages == 0) {
        throw OptionError("averages", file +
                                              " does not say how many averages are behind its coherence "
                                              "('# averages: N'); give the number of averages");
      }
    }
    if (o.noise_model == NoiseModelChoice::kAuto && frf.coherence() && no.averages == 0) {
      Tell(on_message, Message::Kind::kWarning,
           key.ToString() + ": the coherence is not used because " + file +
               " does not give the number of averages ('# averages: N'; or --averages N); the noise is estimated "
               "from the scatter");
    }
    calibration::FrfNoise n =
        AtLocation({file, 0, 0}, key.ToString() + ": ", [&] { return calibration::EstimateFrfNoise(frf, no); });
    const bool points = key.response_point != 0 || key.excitation_point != 0;
    Tell(on_message, Message::Kind::kInfo,
         key.pose_id + " " + (points ? key.Label() : std::string{AxisName(key.response), AxisName(key.excitation)}) +
             ": " + n.description);
    if (n.usable_lines == 0) {
      std::ostringstream m;
      m << key.ToString() << ": no line reaches the signal-to-noise ratio " << o.min_snr << "; this FRF is not used";
      Tell(on_message, Message::Kind::kWarning, m.str());
    }
    out.emplace(key, std::move(n));
  }
  return out;
}

void AttachNoiseModels(MeasuredFrfs* data, const MeasuredFrfOptions& options, const MessageSink& on_message) {
  data->noise = EstimateNoiseModels(*data, options, on_message);
}

MeasuredFrfs ReadMeasuredFrfs(const MeasuredFrfOptions& options, const MessageSink& on_message) {
  MeasuredFrfs data = ReadMeasuredFrfFiles(options, on_message);
  AttachNoiseModels(&data, options, on_message);
  return data;
}

}  // namespace robomach::workflows
