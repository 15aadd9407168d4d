// Measured FRFs (dynamics/measured_frf.h), their files (io/frf_files.h: the
// long CSV of docs/formats.md §3 and UFF58), the noise model
// (calibration/frf_noise.h) and frf-estimate's call (FRFs from raw hammer
// records: io/hammer_records.h, calibration/frf_estimate.h).
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings.h"
#include "robomach/workflows/frf_estimate.h"
#include "robomach/calibration/frf_estimate.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/hammer_records.h"
#include "robomach/workflows/measured_frfs.h"

namespace robomach::python {
namespace {

using calibration::FrfNoise;
using calibration::NoiseOptions;
using dynamics::Frf;
using dynamics::FrfKey;
using dynamics::FrfSet;

// Lines that may quote a file's own text, which need not be UTF-8 (a
// Latin-1 UFF header): undecodable bytes become U+FFFD instead of a
// UnicodeDecodeError that would lose the whole result.
py::list TextLines(const std::vector<std::string>& lines) {
  py::list out;
  for (const std::string& s : lines) {
    PyObject* u = PyUnicode_DecodeUTF8(s.data(), static_cast<Py_ssize_t>(s.size()), "replace");
    if (u == nullptr) throw py::error_already_set();
    out.append(py::reinterpret_steal<py::str>(u));
  }
  return out;
}

py::dict ReadResultDict(const io::FrfReadResult& r) {
  py::dict d;
  d["frfs"] = r.frfs;
  d["quantity"] = io::ToString(r.file_quantity);
  d["averages"] = r.averages;
  d["warnings"] = TextLines(r.warnings);
  d["notes"] = TextLines(r.notes);
  return d;
}

// One of the io readers, the file checked first (FileNotFoundError) and the
// GIL released while it reads.
template <class Reader>
py::dict ReadFrfs(const std::string& path, Reader&& read) {
  RequireReadableFile(path);
  io::FrfReadResult r;
  {
    py::gil_scoped_release release;
    r = read();
  }
  return ReadResultDict(r);
}

constexpr char kReadResultDoc[] =
    " Returns a dict: frfs (FrfSet, receptance [m/N]; mobility and accelerance are converted), "
    "quantity (the file's: 'receptance', 'mobility', 'accelerance'), averages (from '# averages: "
    "N', 0 if absent), warnings and notes (lists of 'path:line: ...' strings the tools print). "
    "FileNotFoundError for a missing file, InputError (path:line:col) for bad content. Releases "
    "the GIL.";

NoiseOptions MakeNoiseOptions(double min_snr, int averages, bool use_coherence, double knots_per_octave,
                              int max_gap_lines, int min_run_lines, bool refine_with_modal_fit, bool wide_floor,
                              bool global_modal_fit) {
  NoiseOptions o;
  o.min_snr = min_snr;
  o.averages = averages;
  o.use_coherence = use_coherence;
  o.knots_per_octave = knots_per_octave;
  o.max_gap_lines = max_gap_lines;
  o.min_run_lines = min_run_lines;
  o.refine_with_modal_fit = refine_with_modal_fit;
  o.wide_floor = wide_floor;
  o.global_modal_fit = global_modal_fit;
  o.Validate();
  return o;
}

// frf-estimate's call: read the records, key the channels, estimate, judge.
py::dict EstimateFrfs(const std::vector<std::string>& records, const std::string& pose_id,
                      const std::string& excitation, const std::map<std::string, std::string>& directions,
                      const std::string& estimator, int min_hits, calibration::FrfEstimateOptions o,
                      const std::map<std::string, double>& response_range) {
  // frf-estimate's own call (workflows::RunFrfEstimate): the same checks,
  // the sample rate's among them.
  workflows::FrfEstimateRunOptions w;
  w.record_paths = records;
  w.pose_id = pose_id;
  w.excitation = excitation;
  w.directions = directions;
  w.response_ranges = response_range;
  w.estimator = estimator;
  w.min_hits = min_hits;
  w.estimate = o;
  w.Validate();
  for (const std::string& r : records) RequireReadableFile(r);
  workflows::FrfEstimateRun run;
  {
    py::gil_scoped_release release;
    run = workflows::RunFrfEstimate(w);
  }
  const calibration::FrfEstimateResult& r = run.result;
  py::dict d;
  const bool estimated = !run.every_hit_rejected();
  d["status"] = estimated ? robomach::ToString(run.verdict.status()) : "no_estimate";
  std::vector<std::string> findings = FindingMessages(run.verdict);
  if (!estimated) findings.insert(findings.begin(), "every hit was rejected: no estimate (summary['hits'] says why)");
  d["findings"] = findings;
  d["averages"] = r.averages;
  if (run.frfs) {
    d["frfs"] = run.frfs->frfs;
    d["labels"] = run.frfs->labels;
  } else {
    d["frfs"] = py::none();
    d["labels"] = std::vector<std::string>{};
  }
  // frf-estimate's --summary but for tool, records and exit_code, as a dict.
  d["summary"] = py::module_::import("json").attr("loads")(run.Summary(estimator).dump());
  return d;
}

}  // namespace

void BindFrf(py::module_& m) {
  py::class_<Frf>(m, "Frf",
                  "One tool-tip FRF: receptance H(f) [m/N] in the base frame B on a strictly increasing "
                  "frequency grid [Hz], with optional coherence [-] and noise sigma [m/N]. Immutable.")
      .def(py::init([](Eigen::VectorXd f, Eigen::VectorXcd h, std::optional<Eigen::VectorXd> coherence) {
             return Frf::FromSamples(std::move(f), std::move(h), std::move(coherence));
           }),
           py::arg("freq_hz"), py::arg("receptance"), py::arg("coherence") = py::none(),
           "freq_hz [Hz] finite, >= 0, strictly increasing; receptance [m/N] complex, finite, same "
           "length; coherence in [0, 1]. ValueError naming the first bad line.")
      .def_property_readonly("freq_hz", [](const Frf& f) { return Eigen::VectorXd(f.freq_hz()); }, "[Hz]")
      .def_property_readonly("receptance", [](const Frf& f) { return Eigen::VectorXcd(f.receptance()); }, "[m/N]")
      .def_property_readonly("coherence", [](const Frf& f) { return f.coherence(); }, "[-] or None")
      .def_property_readonly("noise_sigma", [](const Frf& f) { return f.noise_sigma(); },
                             "per-line noise sigma [m/N] (E|H_measured - H_true|^2 = sigma^2) or None")
      .def("with_noise", &Frf::WithNoise, py::arg("sigma_m_per_N"), "A copy with the per-line noise sigma [m/N].")
      .def("band", &Frf::Band, py::arg("fmin_hz"), py::arg("fmax_hz"), "The lines with f in [fmin_hz, fmax_hz].")
      .def("select", &Frf::Select, py::arg("lines"), "A copy of the given 0-based lines (strictly increasing).")
      .def_property_readonly("evenly_spaced", &Frf::evenly_spaced)
      .def("__len__", &Frf::size)
      .def("__repr__", [](const Frf& f) { return "<Frf " + std::to_string(f.size()) + " lines>"; });

  py::class_<FrfSet>(m, "FrfSet",
                     "The FRFs of one test campaign, keyed by (pose_id, response, excitation), directions "
                     "'x', 'y', 'z' in the base frame B; iterates over keys in order (posture id, "
                     "response, excitation).")
      .def(py::init<>())
      .def("__len__", &FrfSet::size)
      .def("__contains__", [](const FrfSet& s, const KeyTuple& k) { return s.contains(ToKey(k)); })
      .def("__getitem__", [](const FrfSet& s, const KeyTuple& k) {
        const FrfKey key = ToKey(k);
        if (!s.contains(key)) throw py::key_error("no FRF for " + key.ToString());
        return s.at(key);
      })
      .def("__setitem__", [](FrfSet& s, const KeyTuple& k, const Frf& f) { s.Insert(ToKey(k), f); },
           "Inserts an FRF; ValueError if the key is already there.")
      .def("keys", [](const FrfSet& s) {
        std::vector<KeyTuple> k;
        for (const auto& key : s.keys()) k.push_back(FromKey(key));
        return k;
      })
      .def("items", [](const FrfSet& s) {
        std::vector<std::pair<KeyTuple, Frf>> out;
        for (const auto& [k, f] : s) out.emplace_back(FromKey(k), f);
        return out;
      })
      .def("__iter__", [](const FrfSet& s) {
        std::vector<KeyTuple> k;
        for (const auto& key : s.keys()) k.push_back(FromKey(key));
        return py::iter(py::cast(k));
      })
      .def("pose_ids", &FrfSet::pose_ids)
      .def("for_pose", &FrfSet::ForPose, py::arg("pose_id"))
      .def("merge", [](FrfSet& s, const FrfSet& o) { s.Merge(o); }, py::arg("other"),
           "Adds all FRFs of other; ValueError on a duplicate key.")
      .def("__repr__", [](const FrfSet& s) { return "<FrfSet " + std::to_string(s.size()) + " FRFs>"; });

  m.def("read_frf_csv", [](const std::string& path) {
    return ReadFrfs(path, [&] { return io::ReadFrfCsv(path); });
  }, py::arg("path"), (std::string("Reads a measured-FRF CSV (docs/formats.md §3).") + kReadResultDoc).c_str());
  m.def("read_uff58", [](const std::string& path, const std::string& default_pose_id) {
    return ReadFrfs(path, [&] { return io::ReadUff58(path, default_pose_id); });
  }, py::arg("path"), py::arg("default_pose_id") = "",
     (std::string("Reads the FRFs of a Universal File Format file (dataset 58/58b; 164 units). "
                  "default_pose_id is the posture of records without 'pose=ID' (the tools' --pose ID=file.uff).") +
      kReadResultDoc).c_str());
  m.def("read_frf_file", [](const std::string& path, const std::string& default_pose_id, bool keep_points) {
    return ReadFrfs(path, [&] { return io::ReadFrfFile(path, default_pose_id, keep_points); });
  }, py::arg("path"), py::arg("default_pose_id") = "", py::arg("keep_points") = false,
     (std::string("Reads a measured-FRF file: UFF58 by extension (.uff .unv .uf .ufb) or content, else CSV. "
                  "keep_points=True keeps the point numbers (UFF nodes, the CSV's response_point/"
                  "excitation_point): the keys of numbered FRFs are then (pose_id, response, excitation, "
                  "response_point, excitation_point), a roving test for analyse_modes' mode shapes, as "
                  "frf-modes reads it; without it a posture must hold one point pair (the tool-tip tools).") +
      kReadResultDoc).c_str());
  m.def("write_frf_csv", [](const std::string& path, const FrfSet& frfs, const std::string& quantity, int averages) {
    const io::FrfQuantity q = io::ParseFrfQuantity(quantity);
    py::gil_scoped_release release;
    io::WriteFrfCsv(path, frfs, q, averages);
  }, py::arg("path"), py::arg("frfs"), py::arg("quantity") = "receptance", py::arg("averages") = 0,
     "Writes FRFs (receptance [m/N] in the set) as the CSV of docs/formats.md §3 in `quantity` "
     "('receptance' [m/N], 'mobility' [(m/s)/N], 'accelerance' [(m/s^2)/N]), with coherence if "
     "every FRF has one and '# averages: N' if averages > 0. Numbers read back exactly. Atomic; "
     "OutputError if it cannot be written.");
  m.def("write_uff58", [](const std::string& path, const FrfSet& frfs, const std::string& quantity) {
    const io::FrfQuantity q = io::ParseFrfQuantity(quantity);
    py::gil_scoped_release release;
    io::WriteUff58(path, frfs, q);
  }, py::arg("path"), py::arg("frfs"), py::arg("quantity") = "receptance",
     "Writes one ASCII dataset 58 record per FRF (4E20.12, 13 significant digits; the abscissa in "
     "E13.5 keeps 6 digits of f_min and df), 'pose=ID' in ID line 1, a coherence record where "
     "present. Atomic.");
  m.def("round_to_uff_precision", &io::RoundToUffPrecision, py::arg("value"),
        "Rounds to 13 significant digits, the precision of UFF58's E20.12 field.");

  py::class_<NoiseOptions>(m, "NoiseOptions", "Options of the FRF noise model (calibration/frf_noise.h).")
      .def(py::init(&MakeNoiseOptions), py::arg("min_snr") = 3.0, py::arg("averages") = 0,
           py::arg("use_coherence") = true, py::arg("knots_per_octave") = 1.0, py::arg("max_gap_lines") = 3,
           py::arg("min_run_lines") = 8, py::arg("refine_with_modal_fit") = true, py::arg("wide_floor") = false,
           py::arg("global_modal_fit") = false,
           "min_snr: a line is usable where |H|/floor reaches it; averages: number of averages "
           "behind the coherence (0 = unknown: the scatter is used); wide_floor: also take the "
           "floor from wide second differences (integrated-accelerometer drift); global_modal_fit: "
           "the pass about a modal fit uses the common-pole fitter, as frf-modes does (analyse_modes "
           "gives the tool's result with this noise model); the other tools use the single-FRF "
           "fitter. ValueError naming the field for a bad value.")
      .def_readonly("min_snr", &NoiseOptions::min_snr)
      .def_readonly("averages", &NoiseOptions::averages)
      .def_readonly("use_coherence", &NoiseOptions::use_coherence)
      .def_readonly("knots_per_octave", &NoiseOptions::knots_per_octave)
      .def_readonly("max_gap_lines", &NoiseOptions::max_gap_lines)
      .def_readonly("min_run_lines", &NoiseOptions::min_run_lines)
      .def_readonly("refine_with_modal_fit", &NoiseOptions::refine_with_modal_fit)
      .def_readonly("wide_floor", &NoiseOptions::wide_floor)
      .def_readonly("global_modal_fit", &NoiseOptions::global_modal_fit);

  py::class_<FrfNoise>(m, "FrfNoise",
                       "The noise model of one FRF, sigma(f)^2 = (rel |H|)^2 + floor(f)^2 [m/N]^2, per line.")
      .def_property_readonly("source", [](const FrfNoise& n) { return calibration::ToString(n.source); },
                             "'coherence' or 'scatter'")
      .def_readonly("averages", &FrfNoise::averages)
      .def_readonly("relative", &FrfNoise::relative, "rel [-]")
      .def_readonly("floor_m_per_N", &FrfNoise::floor_m_per_N, "additive floor per line [m/N]")
      .def_readonly("sigma_m_per_N", &FrfNoise::sigma_m_per_N, "sigma per line [m/N]")
      .def_readonly("snr", &FrfNoise::snr, "|H| (5-line running median) / floor, per line [-]")
      .def_property_readonly("usable", [](const FrfNoise& n) {
        Eigen::Array<bool, Eigen::Dynamic, 1> u(n.usable.size());
        for (size_t i = 0; i < n.usable.size(); ++i) u(i) = n.usable[i] != 0;
        return u;
      }, "bool per line")
      .def_readonly("usable_bands", &FrfNoise::usable_bands, "list of (f_lo_hz, f_hi_hz)")
      .def_readonly("usable_lines", &FrfNoise::usable_lines)
      .def_readonly("iterations", &FrfNoise::iterations)
      .def_property_readonly("status", [](const FrfNoise& n) { return robomach::ToString(n.status); },
                             "how the scatter fit ended: 'converged' or 'not_converged' (its iteration limit)")
      .def_readonly("modal_refined", &FrfNoise::modal_refined)
      .def_readonly("description", &FrfNoise::description)
      .def("describe_usable", [](const FrfNoise& n) { return calibration::DescribeUsable(n); })
      .def("__repr__", [](const FrfNoise& n) { return "<FrfNoise " + n.description + ">"; });

  m.def("estimate_frf_noise", [](const Frf& frf, const std::optional<NoiseOptions>& options) {
    py::gil_scoped_release release;
    return calibration::EstimateFrfNoise(frf, options.value_or(NoiseOptions{}));
  }, py::arg("frf"), py::arg("options") = py::none(),
     "The noise model of one FRF: from the coherence when it has one and options.averages is known, "
     "else from the scatter of the data. ValueError for fewer than 8 lines. Releases the GIL.");
  m.def("estimate_noise", [](const FrfSet& frfs, const std::optional<NoiseOptions>& options) {
    calibration::NoiseModels n;
    {
      py::gil_scoped_release release;
      n = calibration::EstimateNoise(frfs, options.value_or(NoiseOptions{}));
    }
    std::map<KeyTuple, FrfNoise> out;
    for (auto& [k, v] : n) out.emplace(FromKey(k), std::move(v));
    return out;
  }, py::arg("frfs"), py::arg("options") = py::none(),
     "estimate_frf_noise for every FRF: {(pose_id, response, excitation): FrfNoise}.");
  m.def("usable_data", [](const FrfSet& frfs, const std::map<KeyTuple, FrfNoise>& noise) {
    calibration::NoiseModels n;
    for (const auto& [k, v] : noise) n.emplace(ToKey(k), v);
    return calibration::UsableData(frfs, n);
  }, py::arg("frfs"), py::arg("noise"),
     "The usable lines of every FRF with their sigma attached: what the calibration fits. FRFs "
     "with no usable line are left out; ValueError if an FRF has no noise model.");

  // The measured-FRF route of the tools (workflows/measured_frfs.h): the
  // same reading, unit checks, noise model and usable lines as
  // frf-calibrate, model-audit and frf-modes.
  py::class_<workflows::MeasuredFrfs>(
      m, "MeasuredFrfs",
      "Measured FRFs read the way the tools read them: frfs (all lines, receptance), the file, "
      "'# averages: N' and quantity power (0 receptance, 1 mobility, 2 accelerance) of each, the "
      "unit findings, the noise model of each FRF and fit_data (its usable lines with sigma).")
      .def_readonly("frfs", &workflows::MeasuredFrfs::frfs)
      .def_property_readonly("file", [](const workflows::MeasuredFrfs& d) {
        std::map<KeyTuple, std::string> out;
        for (const auto& [k, v] : d.file) out.emplace(FromKey(k), v);
        return out;
      })
      .def_property_readonly("averages", [](const workflows::MeasuredFrfs& d) {
        std::map<KeyTuple, int> out;
        for (const auto& [k, v] : d.averages) out.emplace(FromKey(k), v);
        return out;
      })
      .def_property_readonly("file_power", [](const workflows::MeasuredFrfs& d) {
        std::map<KeyTuple, int> out;
        for (const auto& [k, v] : d.file_power) out.emplace(FromKey(k), v);
        return out;
      })
      .def_readonly("unit_findings", &workflows::MeasuredFrfs::unit_findings)
      .def_property_readonly("noise", [](const workflows::MeasuredFrfs& d) {
        std::map<KeyTuple, FrfNoise> out;
        for (const auto& [k, v] : d.noise) out.emplace(FromKey(k), v);
        return out;
      }, "{(pose_id, response, excitation): FrfNoise}; empty for noise_model='none'")
      .def_property_readonly("fit_data", &workflows::MeasuredFrfs::FitData,
                             "the usable lines with sigma (all lines without a noise model): what the fits use")
      .def("__repr__", [](const workflows::MeasuredFrfs& d) {
        return "<MeasuredFrfs " + std::to_string(d.frfs.size()) + " FRFs, " + std::to_string(d.noise.size()) +
               " noise models>";
      });
  m.def("read_measured_frfs",
        [](const std::vector<std::string>& files, const std::map<std::string, std::string>& posed_files,
           const std::string& default_pose, const std::string& noise_model, double min_snr, int averages,
           bool drift_floor, bool global_modal_fit) {
          for (const std::string& f : files) RequireReadableFile(f);
          for (const auto& [pose, f] : posed_files) RequireReadableFile(f);
          workflows::MeasuredFrfOptions o;
          o.files = files;
          for (const auto& [pose, f] : posed_files) o.posed_files.push_back({pose, f});
          o.default_pose = default_pose;
          o.pose_option = "posed_files";
          o.noise_model = workflows::ParseNoiseModelChoice(noise_model);
          o.min_snr = min_snr;
          o.averages = averages;
          o.drift_floor = drift_floor;
          o.global_modal_fit = global_modal_fit;
          std::vector<std::pair<std::string, std::string>> said;
          workflows::MeasuredFrfs out;
          {
            py::gil_scoped_release release;
            out = workflows::ReadMeasuredFrfs(o, [&](const Message& msg) {
              if (msg.kind == Message::Kind::kWarning) said.push_back({"warning", msg.text});
            });
          }
          // The readers' and the noise model's warnings as Python warnings
          // (a unit mistake as UnitWarning), as the tools print them.
          for (const auto& [kind, text] : said) {
            if (text.rfind("implausible (unit mistake?)", 0) == 0) {
              WarnUnit(text);
            } else if (PyErr_WarnEx(PyExc_UserWarning, text.c_str(), 1) != 0) {
              throw py::error_already_set();
            }
          }
          return out;
        },
        py::arg("files"), py::arg("posed_files") = std::map<std::string, std::string>{},
        py::arg("default_pose") = "", py::arg("noise_model") = "auto", py::arg("min_snr") = 3.0,
        py::arg("averages") = 0, py::arg("drift_floor") = false, py::arg("global_modal_fit") = false,
        "Reads hammer-test files (CSV of docs/formats.md §3 or UFF58) as frf-calibrate, model-audit and "
        "frf-modes do: posed_files {pose_id: file.uff} for UFF records without a posture (default_pose "
        "for every such file instead); noise_model 'auto', 'coherence', 'scatter' or 'none'; min_snr and "
        "averages as --min-snr and --averages; drift_floor as --drift-floor. Returns MeasuredFrfs; "
        "warnings (unit mistakes as UnitWarning) as the tools print them. FileNotFoundError for a missing "
        "file, InputError for a bad one, ValueError for a bad option.");

  // The library's defaults, so that Python and frf-estimate cannot drift apart.
  const calibration::FrfEstimateOptions kEstimate;
  m.def("estimate_frf",
        [](const std::vector<std::string>& records, const std::string& pose_id, const std::string& excitation,
           const std::optional<std::map<std::string, std::string>>& directions, const std::string& estimator,
           int min_hits, double fmax_hz, double force_window_s, double force_window_pre_s,
           double force_window_taper_s, double exponential_tau_s, double double_hit_fraction,
           double trigger_fraction, int flat_top_samples, double force_range_N,
           const std::map<std::string, double>& response_range) {
          calibration::FrfEstimateOptions o;
          o.fmax_hz = fmax_hz;
          o.force_window_s = force_window_s;
          o.force_window_pre_s = force_window_pre_s;
          o.force_window_taper_s = force_window_taper_s;
          o.exponential_tau_s = exponential_tau_s;
          o.double_hit_fraction = double_hit_fraction;
          o.trigger_fraction = trigger_fraction;
          o.flat_top_samples = flat_top_samples;
          o.force_range_N = force_range_N;
          return EstimateFrfs(records, pose_id, excitation, directions.value_or(std::map<std::string, std::string>{}),
                              estimator, min_hits, o, response_range);
        },
        py::arg("records"), py::arg("pose_id") = "P1", py::arg("excitation") = "x", py::arg("directions") = py::none(),
        py::arg("estimator") = "h1", py::arg("min_hits") = 3, py::arg("fmax_hz") = kEstimate.fmax_hz,
        py::arg("force_window_s") = kEstimate.force_window_s, py::arg("force_window_pre_s") = kEstimate.force_window_pre_s,
        py::arg("force_window_taper_s") = kEstimate.force_window_taper_s,
        py::arg("exponential_tau_s") = kEstimate.exponential_tau_s,
        py::arg("double_hit_fraction") = kEstimate.double_hit_fraction,
        py::arg("trigger_fraction") = kEstimate.trigger_fraction, py::arg("flat_top_samples") = kEstimate.flat_top_samples,
        py::arg("force_range_N") = kEstimate.force_range_N,
        py::arg("response_range") = std::map<std::string, double>{},
        "frf-estimate's call: tool-tip FRFs from raw impact-hammer records (files of docs/formats.md §10: "
        "time_s, force_N, responses <name>_m / _m_per_s / _m_per_s2, optional hit). Each response channel's "
        "direction comes from `directions` ({name: 'x'|'y'|'z'}) or its name (..._x, ..._y, ..._z); "
        "excitation is the hammer's direction. H1 (or H2) averaged over the accepted hits; hits with a double "
        "hit or an overload are rejected. Windows in seconds as frf-estimate's options (0: automatic; a "
        "negative force_window_s: none); fmax_hz 0: sample rate / 2.56; force_range_N 0: unknown; response_range {name: range in the "
        "channel's SI unit} (frf-estimate's --response-range; a sample at or beyond it is an overload). Returns "
        "{'status': 'ok', 'flagged' (fewer accepted hits than min_hits, leakage, an implausible receptance) "
        "or 'no_estimate' (every hit rejected), 'findings': [str], 'averages': int, 'frfs': FrfSet "
        "(receptance [m/N] with the coherence; None without an estimate), 'labels': [str], 'summary': dict "
        "(frf-estimate's --summary without the tool's fields: hits, channels, windows, warnings)}. "
        "FileNotFoundError for a missing file, InputError (path:line:col) for a bad record, ValueError for bad "
        "options or channel directions. Releases the GIL.");
}

}  // namespace robomach::python
