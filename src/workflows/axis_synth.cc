#include "robomach/workflows/axis_synth.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/compensation_file.h"
#include "robomach/io/counts_file.h"
#include "robomach/io/number_format.h"
#include "robomach/io/program_file.h"
#include "robomach/io/temperature_log.h"
#include "robomach/machine/compensation.h"

namespace robomach::workflows {

void AxisSynthOptions::Validate() const {
  CheckOptionRange("feed_mm_min", feed_mm_min, 1e-3, 1e6);
  CheckOptionRange("sample_rate_hz", sample_rate_hz, 1.0, 1e8);
  CheckOptionRange("dwell_s", dwell_s, 0.0, 1e5);
  CheckOptionRange("start_b_deg", start_b_deg, -720.0, 720.0);
  CheckOptionRange("glitch_probability", glitch_probability, 0.0, 1.0);
  CheckOptionRange("max_rows", static_cast<double>(max_rows), 2.0, 1e9);
  CheckOptionRange("capture_every", capture_every, 1, 100000);
  if (capture_settle < 0 || capture_settle >= capture_every) {
    throw OptionError("capture_settle", "capture_settle: expected a value in [0, capture_every " +
                                            std::to_string(capture_every) + "), got " + std::to_string(capture_settle));
  }
}

std::vector<std::string> AxisSynthOptions::UnitFindings() const {
  // Plausible ranges (docs/plausibility.md): feeds of machine tools 10 -
  // 100 000 mm/min (HSC rapids to 100 m/min), controller traces 100 Hz -
  // 100 kHz (840D sl servo trace: 8 kHz at most in the IPO/servo cycle).
  std::vector<std::string> out;
  for (const std::string& w :
       {ImplausibleOption(Name("feed_mm_min"), feed_mm_min, 10.0, 100000.0, "mm/min",
                    "machine tool feeds (up to 100 m/min rapids)", "a feed in m/min typed in the mm/min option?",
                    "a feed in um/min typed in the mm/min option?"),
        ImplausibleOption(Name("sample_rate_hz"), sample_rate_hz, 10.0, 1e6, "Hz", "position traces (100 Hz - 100 kHz)",
                    "a rate in kHz typed in the Hz option?", "a rate in mHz typed in the Hz option?"),
        ImplausibleOption(Name("dwell_s"), dwell_s, 0.0, 600.0, "s", "dwells before a measured move (under a minute)", "",
                    "a dwell in ms typed in the s option?")}) {
    if (!w.empty()) out.push_back(w);
  }
  // start_b_deg, the only angle: a nutating head's B within a turn either
  // way (the inverse kinematics repeats every turn).
  if (std::string w = RadiansInDegreeOption(Name("start_b_deg"), start_b_deg); !w.empty()) {
    out.push_back(std::move(w));
  } else if (std::string b = ImplausibleOption(Name("start_b_deg"), start_b_deg, -360.0, 360.0, "deg",
                                         "a nutating head's B (within a turn of 0)",
                                         "an angle in gradians (400 a turn) or a turn too many typed?",
                                         "an angle in gradians (400 a turn) or a turn too many typed?");
             !b.empty()) {
    out.push_back(std::move(b));
  }
  return out;
}

machine::CaptureSynthesizer AxisSynthRun::Capture(const AxisSynthOptions& o) const {
  std::vector<std::string> names;
  for (const auto& a : machine.machine.axes) names.push_back(a.name);
  return machine::CaptureSynthesizer(static_cast<int>(machine.machine.axes.size()), o.capture_every, o.capture_settle,
                                     o.glitch_probability, o.seed, names);
}

AxisSynthRun::CaptureCounts AxisSynthRun::WriteCapture(const AxisSynthOptions& o, const std::string& path) const {
  machine::CaptureSynthesizer cap = Capture(o);
  const size_t n = machine.machine.axes.size();
  io::WriteFileAtomically(path, [&](std::ostream& out) {
    std::vector<std::uint16_t> words;
    auto flush = [&]() {
      if constexpr (std::endian::native == std::endian::big) {
        for (auto& w : words) w = static_cast<std::uint16_t>((w >> 8) | (w << 8));
      }
      out.write(reinterpret_cast<const char*>(words.data()), static_cast<std::streamsize>(words.size() * 2));
      words.clear();
    };
    cap.Start(record.counts.data(), &words);
    for (long r = 1; r < record.rows(); ++r) {
      try {
        cap.Next(record.counts.data() + r * n, &words);
      } catch (const std::invalid_argument& e) {
        // The fields by their own names: a tool's FromFields words them as
        // its options (and decides the exit code by them).
        throw OptionError("capture_every", "capture_every " + std::to_string(o.capture_every) + ": " + e.what() +
                                               "; raise capture_every or lower feed_mm_min");
      }
      if (words.size() > (1u << 16)) flush();
    }
    flush();
  });
  return {(record.rows() - 1) * o.capture_every + 1, cap.glitches()};
}

void AxisSynthRun::WriteCounts(const AxisSynthOptions& o, const std::string& path,
                               const std::string& machine_out) const {
  const std::vector<std::pair<std::string, std::string>> meta{
      {"generator", "axis-synth (robomach)"},
      {"machine", machine_out.empty() ? o.machine_path : machine_out},
      {"program", o.program_path},
      {"sample_rate_hz", io::FormatDouble(o.sample_rate_hz)}};
  const size_t n = machine.machine.axes.size();
  io::WriteFileAtomically(path, [&](std::ostream& out) {
    io::CountsWriter w(out, machine.machine.axes, meta);
    for (long r = 0; r < record.rows(); ++r) w.Row(record.t_s[r], record.counts.data() + r * n);
  });
}

AxisSynthRun RunAxisSynth(const AxisSynthOptions& o, const MessageSink& tell) {
  o.Validate();
  AxisSynthRun r;
  r.unit_findings = o.UnitFindings();
  r.machine = io::ReadMachineFile(o.machine_path);
  const machine::ProgrammedPath path = io::ReadProgramFile(o.program_path);
  io::CompensationTables tables;
  if (!o.compensation_path.empty()) {
    // The reader names the option only when there is one (the tool's).
    tables = io::ReadCompensationFile(o.compensation_path, r.machine,
                                      o.names.count("compensation_path") ? o.Name("compensation_path") : "");
  }
  std::vector<machine::TemperatureCompensation> temps;
  std::vector<std::string> temp_implausible;
  if (!o.temperature_path.empty()) temps = io::ReadTemperatureLog(o.temperature_path, r.machine, &temp_implausible);
  for (const auto* found : {&r.machine.implausible, &tables.implausible, &temp_implausible}) {
    for (const std::string& w : *found) Tell(tell, Message::Kind::kWarning, w);
    r.unit_findings.insert(r.unit_findings.end(), found->begin(), found->end());
  }
  machine::Machine& m = r.machine.machine;
  const machine::Compensation comp(static_cast<int>(m.axes.size()), tables.encoder, tables.cross_axis, temps);
  const machine::Compensation* comp_ptr = comp.empty() ? nullptr : &comp;

  machine::SynthesisOptions s;
  s.feed = MmToM(o.feed_mm_min) / 60.0;
  s.sample_rate_hz = o.sample_rate_hz;
  s.dwell = o.dwell_s;
  s.initial_guess.assign(m.kinematic_axis.size(), 0.0);
  s.initial_guess[3] = DegToRad(o.start_b_deg);  // B of the nutating head (X, Y, Z, B, C)

  // A slow feed at a servo rate is a long record (33 mm/min on the cone
  // frustum: 4.1 M rows, 184 MB): said before anything is computed.
  if (const long rows = machine::SynthesisRows(path, s); rows > o.max_rows) {
    throw OptionError("max_rows",
                      "feed_mm_min " + FormatDouble(o.feed_mm_min) + " at sample_rate_hz " +
                          FormatDouble(o.sample_rate_hz) + ": the path's " + FormatNumber(MToMm(path.length()), 4) +
                          " mm take " + FormatNumber(static_cast<double>(rows) / o.sample_rate_hz, 4) + " s, " +
                          std::to_string(rows) + " rows (about " + FormatNumber(static_cast<double>(rows) * 45e-6, 3) +
                          " MB), more than max_rows " + std::to_string(o.max_rows) +
                          ": raise feed_mm_min, lower sample_rate_hz, or raise max_rows");
  }
  std::vector<double> origin(m.axes.size());
  for (size_t a = 0; a < origin.size(); ++a) origin[a] = m.axes[a].origin;
  if (o.origins_at_start) {
    origin = machine::StartMeasured(m, comp_ptr, path, s);
    for (size_t a = 0; a < origin.size(); ++a) m.axes[a].origin = origin[a];
  }
  machine::SynthesisResult res = machine::SynthesizeCounts(m, comp_ptr, path, s, origin);
  if (!res.ok) throw InputError({o.program_path, 0, 0}, "the machine cannot follow the path " + res.message);
  const size_t n = m.axes.size();
  for (size_t a = 0; a < n; ++a) {
    if (res.record.counts[a] != 0) {
      const auto& ax = m.axes[a];
      const bool linear = ax.kind == machine::AxisKind::kLinear;
      const double scale = linear ? 1e3 : 180.0 / kPi;
      throw InputError({o.machine_path, 0, 0},
                       "axis " + ax.name + ": the path starts at measured " +
                           FormatNumber(res.start_measured[a] * scale, 7) + (linear ? " mm" : " deg") + ", " +
                           std::to_string(res.record.counts[a]) + " counts from origin " +
                           FormatDouble(ax.origin * scale) +
                           "; the first counts row must be the reference position (docs/formats.md §8.1): set the "
                           "origins to the start position or pass " + o.Name("origins_at_start"));
    }
  }
  r.record = std::move(res.record);
  return r;
}

}  // namespace robomach::workflows
