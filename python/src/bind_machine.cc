// Python bindings of the five-axis machine tools (docs/python.md): the
// acquisition of axis-acquire (counts -> compensated axes -> tool pose, the
// contour error against a programmed path) and the ISO 230-2 evaluation of
// axis-accuracy.
#include <bit>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "robomach/common/errors.h"
#include "robomach/io/acquired_path_file.h"
#include "robomach/workflows/acquisition_inputs.h"
#include "robomach/common/number_format.h"
#include "robomach/io/atomic_file.h"
#include "robomach/workflows/capture_decoding.h"
#include "robomach/io/counts_file.h"
#include "robomach/io/machine_file.h"
#include "robomach/workflows/iso_evaluation.h"
#include "robomach/machine/iso230.h"
#include "robomach/workflows/axis_synth.h"

namespace robomach::python {

void BindMachine(py::module_& m) {
  const workflows::AxisSynthOptions kAxisSynth;  // axis-synth's defaults
  m.def("run_axis_synth",
        [](const std::string& machine_path, const std::string& program, const std::optional<std::string>& out,
           const std::optional<std::string>& compensation, const std::optional<std::string>& temperature,
           double feed_mm_min, double sample_rate_hz, double dwell_s, double start_b_deg,
           const std::optional<std::string>& machine_out, const std::optional<std::string>& capture,
           int capture_every, int capture_settle, double glitch_probability, unsigned seed, long max_rows) {
          workflows::AxisSynthOptions o;
          o.machine_path = machine_path;
          o.program_path = program;
          o.compensation_path = compensation.value_or("");
          o.temperature_path = temperature.value_or("");
          o.feed_mm_min = feed_mm_min;
          o.sample_rate_hz = sample_rate_hz;
          o.dwell_s = dwell_s;
          o.start_b_deg = start_b_deg;
          o.origins_at_start = machine_out.has_value();  // as the tool: --machine-out
          o.capture_every = capture_every;
          o.capture_settle = capture_settle;
          o.glitch_probability = glitch_probability;
          o.seed = seed;
          o.max_rows = max_rows;
          // The messages name the keywords whose names are not the fields'.
          o.names = {{"compensation_path", "compensation"}, {"origins_at_start", "machine_out"}};
          o.Validate();
          for (const std::string* p : {&o.machine_path, &o.program_path, &o.compensation_path, &o.temperature_path}) {
            if (!p->empty()) RequireReadableFile(*p);
          }
          CollectedMessages said;
          // Said before the files are read, as the tool does; the run flags them.
          for (const std::string& w : o.UnitFindings()) said.messages.push_back({Message::Kind::kWarning, w});
          workflows::AxisSynthRun run;
          long capture_samples = 0, capture_glitches = 0;
          {
            py::gil_scoped_release release;
            run = workflows::RunAxisSynth(o, said.Sink());
            // The tool's outputs, in its order: the capture (it can fail on too
            // fast a move), the machine file, the counts.
            if (capture) {
              const auto written = run.WriteCapture(o, *capture);
              capture_samples = written.samples;
              capture_glitches = written.glitches;
            }
            if (machine_out) io::WriteMachineFile(*machine_out, run.machine);
            if (out) run.WriteCounts(o, *out, machine_out.value_or(""));
          }
          for (const std::string& f : run.unit_findings) WarnUnit(f);
          const machine::CountsRecord& rec = run.record;
          const int n = static_cast<int>(run.machine.machine.axes.size());
          Eigen::Matrix<std::int64_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> counts(rec.rows(), n);
          for (long r = 0; r < rec.rows(); ++r) {
            for (int a = 0; a < n; ++a) counts(r, a) = rec.counts[r * n + a];
          }
          std::vector<std::string> names;
          std::vector<double> origins;
          for (const auto& a : run.machine.machine.axes) {
            names.push_back(a.name);
            origins.push_back(a.origin);
          }
          py::dict d;
          d["axis_names"] = names;
          d["t_s"] = rec.t_s;
          d["counts"] = counts;
          d["origins_si"] = origins;
          d["rows"] = rec.rows();
          d["duration_s"] = rec.t_s.empty() ? 0.0 : rec.t_s.back();
          if (capture) {
            d["capture_samples"] = capture_samples;
            d["capture_glitches"] = capture_glitches;
          }
          d["messages"] = said.List();
          d["unit_findings"] = run.unit_findings;
          d["status"] = robomach::ToString(run.status());
          d["flagged"] = run.flagged();
          return d;
        },
        py::arg("machine"), py::arg("program"), py::arg("out") = py::none(), py::arg("compensation") = py::none(),
        py::arg("temperature") = py::none(), py::arg("feed_mm_min") = kAxisSynth.feed_mm_min,
        py::arg("sample_rate_hz") = kAxisSynth.sample_rate_hz, py::arg("dwell_s") = kAxisSynth.dwell_s,
        py::arg("start_b_deg") = kAxisSynth.start_b_deg, py::arg("machine_out") = py::none(),
        py::arg("capture") = py::none(), py::arg("capture_every") = kAxisSynth.capture_every,
        py::arg("capture_settle") = kAxisSynth.capture_settle,
        py::arg("glitch_probability") = kAxisSynth.glitch_probability, py::arg("seed") = kAxisSynth.seed,
        py::arg("max_rows") = kAxisSynth.max_rows,
        "axis-synth as one call (workflows::RunAxisSynth): a machine file, a programmed path and optionally the "
        "controller's compensation tables and temperature log -> the encoder counts the machine would record, the "
        "tool's options under their names without dashes (defaults: AxisSynthOptions). out, machine_out, capture: "
        "write the tool's --out (counts, docs/formats.md §8.1), --machine-out (the machine file with the measured "
        "start as origins; given, the origins are that start, as the tool's) and --capture (the raw quadrature "
        "capture, §8.2). Returns a dict: axis_names, t_s, counts (rows × axes, int64; the first row all zero), "
        "origins_si (per axis, [m, rad], as used), rows, duration_s, with capture capture_samples and "
        "capture_glitches, messages ({kind, text}), unit_findings (the options' then the files'; also as "
        "UnitWarning), status and flagged (the tool's exit 3). ValueError naming the option; FileNotFoundError, "
        "InputError for files. Releases the GIL.");

  m.def("acquire", [](const std::string& machine_path, const std::string& counts_path,
                      const std::optional<std::string>& compensation, const std::optional<std::string>& temperature,
                      const std::optional<std::string>& program, const std::optional<std::string>& out) {
    for (const auto& p : {std::optional<std::string>(machine_path), std::optional<std::string>(counts_path), compensation,
                          temperature, program}) {
      if (p) RequireReadableFile(*p);
    }
    const workflows::AcquisitionInputs in = workflows::ReadAcquisitionInputs(machine_path, counts_path, compensation.value_or(""),
                                                                temperature.value_or(""), program.value_or(""));
    // axis-acquire's exit 3 (docs/plausibility.md): a UnitWarning per finding
    // of the machine file, the tables, the temperature log and the counts.
    for (const std::string& w : in.implausible()) WarnUnit(w);
    const io::MachineFile& mf = in.machine;
    const std::optional<machine::ProgrammedPath>& path = in.program;
    const machine::CountsRecord& rec = in.counts;
    const long rows = rec.rows();
    const int n = rec.num_axes;
    Eigen::MatrixXd axes(rows, n), tip(rows, 3), tool_axis(rows, 3);
    std::vector<machine::ContourError> contour;
    {
      py::gil_scoped_release release;
      machine::Acquisition acq(mf.machine, in.applied());
      std::optional<machine::ContourTracker> tracker;
      if (path) tracker.emplace(*path);
      for (long r = 0; r < rows; ++r) {
        const machine::AcquiredSample& s = acq.Process(rec.t_s[r], rec.counts.data() + r * n);
        for (int a = 0; a < n; ++a) axes(r, a) = s.real[a];
        tip.row(r) = s.pose.p_W.transpose();
        tool_axis.row(r) = s.pose.k_W.transpose();
        if (tracker) contour.push_back(tracker->Next(s.pose));
      }
      if (out) {
        // axis-acquire's --out: the same rows through the file's writer.
        machine::Acquisition again(mf.machine, in.applied());
        std::optional<machine::ContourTracker> t2;
        if (path) t2.emplace(*path);
        io::WriteFileAtomically(*out, [&](std::ostream& os) {
          workflows::WriteAcquiredPath(os, rec, mf.machine.axes, &again, t2 ? &*t2 : nullptr);
        });
      }
    }
    py::dict d;
    std::vector<std::string> names;
    for (const auto& a : mf.machine.axes) names.push_back(a.name);
    d["axis_names"] = names;
    d["t_s"] = rec.t_s;
    d["axes_si"] = axes;
    d["tip_m"] = tip;
    d["tool_axis"] = tool_axis;
    if (path) {
      Eigen::VectorXd dist(rows), ang(rows), s(rows);
      for (long r = 0; r < rows; ++r) {
        dist(r) = contour[r].distance;
        ang(r) = contour[r].axis_angle;
        s(r) = contour[r].s;
      }
      d["contour_error_m"] = dist;
      d["axis_error_rad"] = ang;
      d["path_s_m"] = s;
      d["unit_findings"] = machine::ContourUnitFindings(contour, *path);
    }
    return d;
  }, py::arg("machine"), py::arg("counts"), py::arg("compensation") = py::none(), py::arg("temperature") = py::none(),
     py::arg("program") = py::none(), py::arg("out") = py::none(),
     "axis-acquire's call: encoder counts (docs/formats.md §8.1) through the machine file's scales, the controller's "
     "compensation tables and temperature log, to compensated axis positions [m, rad] and the tool tip and axis in "
     "workpiece coordinates; with a programmed path, the contour error of every sample (and axis-acquire's unit "
     "findings). A UnitWarning per value of the input files outside its plausible range (docs/plausibility.md), "
     "where axis-acquire exits 3. out: also write axis-acquire's --out file. Returns a dict of arrays (rows first): axes_si holds "
     "each axis in SI (m or rad). The GIL is "
     "released while it runs.");

  m.def("decode_capture", [](const std::string& machine_path, const std::string& capture, double sample_rate_hz,
                             long every, int glitch_filter, const std::optional<std::string>& out) {
    RequireReadableFile(machine_path);
    RequireReadableFile(capture);
    if (!(sample_rate_hz > 0.0) || !std::isfinite(sample_rate_hz) || every < 1 || glitch_filter < 0 ||
        glitch_filter > 1000000) {
      throw std::invalid_argument("expected (axis-decode's ranges) a finite sample_rate_hz > 0, every >= 1, "
                                  "glitch_filter in [0, 1000000]");
    }
    const io::MachineFile mf = io::ReadMachineFile(machine_path);
    // axis-decode's exit 3: a UnitWarning per finding of the machine file.
    for (const std::string& w : mf.implausible) WarnUnit(w);
    const int n = static_cast<int>(mf.machine.axes.size());
    std::vector<double> t;
    std::vector<std::int64_t> counts;
    workflows::CaptureDecoding d;
    {
      py::gil_scoped_release release;
      d = workflows::DecodeCaptureFile(capture, mf, sample_rate_hz, every, glitch_filter, [&](double t_s, const std::int64_t* c) {
        t.push_back(t_s);
        counts.insert(counts.end(), c, c + n);
      });
      if (out) {
        // axis-decode's --out: the same rows through the counts writer.
        io::WriteFileAtomically(*out, [&](std::ostream& os) {
          io::CountsWriter writer(os, mf.machine.axes,
                                  {{"generator", "axis-decode (robomach)"},
                                   {"capture", capture},
                                   {"sample_rate_hz", FormatDouble(sample_rate_hz)},
                                   {"every", std::to_string(every)},
                                   {"glitch_filter", std::to_string(glitch_filter)}});
          for (size_t r = 0; r < t.size(); ++r) writer.Row(t[r], counts.data() + r * n);
        });
      }
    }
    Eigen::Matrix<std::int64_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> c(static_cast<Eigen::Index>(t.size()), n);
    for (size_t r = 0; r < t.size(); ++r) {
      for (int a = 0; a < n; ++a) c(static_cast<Eigen::Index>(r), a) = counts[r * n + a];
    }
    std::vector<std::string> names;
    for (const auto& a : mf.machine.axes) names.push_back(a.name);
    py::dict res;
    res["axis_names"] = names;
    res["t_s"] = t;
    res["counts"] = c;
    res["samples"] = d.samples;
    res["error_events"] = d.error_events;
    res["final_counts"] = d.final_counts;
    res["status"] = robomach::ToString(d.status());
    res["findings"] = FindingMessages(d.verdict);
    return res;
  }, py::arg("machine"), py::arg("capture"), py::arg("sample_rate_hz"), py::arg("every") = 1, py::arg("glitch_filter") = 0,
     py::arg("out") = py::none(),
     "axis-decode's call: a raw quadrature capture (docs/formats.md §8.2) decoded to counts at samples 0, every, "
     "2 every, ... A UnitWarning per machine-file value outside its plausible range (axis-decode's exit 3). "
     "Returns a dict: t_s, counts (rows × axes, int64), samples, error_events and final_counts per axis, status "
     "('flagged' with error events: axis-decode's exit 3) and findings; out: also write axis-decode's --out file. "
     "The GIL is released while it runs.");

  m.def("iso230_evaluate", [](const std::string& runs_path) {
    RequireReadableFile(runs_path);
    const workflows::IsoEvaluation eval = workflows::EvaluateIsoRunsFile(runs_path);
    py::dict axes;
    for (const auto& [axis, r] : eval.results) {
      py::dict a;
      a["A"] = r.A;
      a["A_up"] = r.A_up;
      a["A_down"] = r.A_down;
      a["E"] = r.E;
      a["E_up"] = r.E_up;
      a["E_down"] = r.E_down;
      a["M"] = r.M;
      a["R"] = r.R;
      a["R_up"] = r.R_up;
      a["R_down"] = r.R_down;
      a["B"] = r.B;
      a["B_mean"] = r.B_mean;
      py::list targets;
      for (const auto& t : r.targets) {
        py::dict td;
        td["target"] = t.target;
        td["runs_up"] = t.runs_up;
        td["runs_down"] = t.runs_down;
        td["mean_up"] = t.mean_up;
        td["mean_down"] = t.mean_down;
        td["s_up"] = t.s_up;
        td["s_down"] = t.s_down;
        td["mean"] = t.mean;
        td["B"] = t.reversal;
        td["R"] = t.R;
        targets.append(td);
      }
      a["targets"] = targets;
      axes[py::str(axis)] = a;
    }
    py::dict d;
    d["unit"] = eval.runs.rotary ? "deg" : "mm";
    d["axes"] = axes;
    d["unit_findings"] = eval.unit_findings;
    d["min_runs"] = eval.min_runs;
    d["status"] = robomach::ToString(eval.status());
    d["findings"] = FindingMessages(eval.verdict);
    return d;
  }, py::arg("runs"),
     "axis-accuracy's evaluation: ISO 230-2 accuracy A, systematic error E, mean error M, repeatability R, "
     "reversal B per axis of a runs file (docs/formats.md §8.6), in the file's unit (mm or deg), with the "
     "per-target statistics, the unit plausibility findings, status ('flagged': axis-accuracy's exit 3) and "
     "findings.");
}

}  // namespace robomach::python
