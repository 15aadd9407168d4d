// Calibration against measured FRFs (calibration/frf_calibration.h) and
// joint-stiffness identification from load tests
// (identification/joint_stiffness.h, io/tracker_file.h) and its D-optimal
// test plan (identification/test_plan.h, io/kq_files.h). Results are plain
// objects with read-only attributes.
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>

#include <optional>

#include "bindings.h"
#include "robomach/io/frf_quantity.h"
#include "robomach/common/units.h"
#include "robomach/io/prediction_files.h"
#include "robomach/io/posture_file.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/calibration/frf_calibration.h"
#include "robomach/calibration/modal_fit.h"
#include "robomach/calibration/modal_analysis.h"
#include "robomach/identification/joint_stiffness.h"
#include "robomach/identification/load_case.h"
#include "robomach/identification/test_plan.h"
#include "robomach/io/kq_files.h"
#include "robomach/io/robot_config.h"
#include "robomach/io/tracker_file.h"
#include "robomach/common/number_format.h"
#include "robomach/report/calibration_report.h"
#include "robomach/workflows/frf_calibrate.h"
#include "robomach/workflows/kq_identify.h"
#include "robomach/workflows/tracker_synth.h"
#include "robomach/workflows/frf_synth.h"
#include "robomach/io/frf_files.h"

namespace robomach::python {
namespace {

using calibration::CalibrationOptions;
using calibration::CalibrationResult;
using calibration::MeasuredFeatures;
using calibration::ModeMatch;
using calibration::ParameterEstimate;
using calibration::StageSummary;
using identification::CaseResidual;
using identification::JointStiffnessResult;
using identification::LoadCase;

/// A plan with the options it was made with: the plan file records them.
struct PyTestPlan {
  identification::TestPlan plan;
  identification::PlanOptions options;
};

std::map<std::string, double> ParameterDict(const dynamics::ParameterSet& p) {
  std::map<std::string, double> out;
  for (const auto& s : p.specs()) out[s.name] = p.Get(s.name);
  return out;
}


calibration::PostureMap Postures(const std::map<std::string, Eigen::VectorXd>& p) {
  return calibration::PostureMap(p.begin(), p.end());
}

MeasuredFeatures Features(const dynamics::FrfSet& measured, double fmin_hz, double fmax_hz) {
  calibration::ModalFitOptions o;
  o.fmin_hz = fmin_hz;
  o.fmax_hz = fmax_hz;
  return calibration::ExtractFeatures(measured, o);
}

}  // namespace

void BindCalibration(py::module_& m) {
  // frf-modes' call (calibration::AnalyseModes, issue #34 §3).
  m.def(
      "analyse_modes",
      [](const dynamics::FrfSet& frfs, const std::map<KeyTuple, calibration::FrfNoise>& noise, double fmin_hz,
         double fmax_hz, int max_order, bool per_frf, const std::string& weights, int file_power) {
        if (weights != "noise" && weights != "quantity") {
          throw py::value_error("weights: expected 'noise' or 'quantity', got '" + weights + "'");
        }
        if (file_power < 0 || file_power > 2) throw py::value_error("file_power: expected 0, 1 or 2");
        calibration::NoiseModels n;
        for (const auto& [k, v] : noise) n.emplace(ToKey(k), v);
        calibration::ModalAnalysisOptions o;
        o.fit.fmin_hz = fmin_hz;
        o.fit.fmax_hz = fmax_hz;
        o.fit.max_order = max_order;
        o.per_frf = per_frf;
        o.weights_in_file_quantity = weights == "quantity";
        const auto poses = calibration::AnalyseModes(frfs, n, o, file_power);
        py::list out;
        for (const calibration::PoseModes& p : poses) {
          py::list fits;
          for (const calibration::ModalGroup& g : p.groups) {
            py::list frf_list, modes;
            for (size_t i = 0; i < g.keys.size(); ++i) {
              py::dict f;
              f["frf"] = FromKey(g.keys[i]);
              f["misfit_relative"] = i < g.misfit.size() ? g.misfit[i] : NAN;
              f["misfit_noise_sigmas"] = i < g.fit.misfit_in_noise.size() ? g.fit.misfit_in_noise[i] : NAN;
              f["model_error_rms"] = i < g.fit.model_error.size() ? g.fit.model_error[i] : 0.0;
              f["model_error_unit"] = io::QuantityUnit(static_cast<io::FrfQuantity>(file_power));
              f["misfit_noise_sigmas_noise_weights"] =
                  i < g.fit.misfit_in_noise_weights_alone.size() ? g.fit.misfit_in_noise_weights_alone[i] : NAN;
              py::list constants;
              if (i < g.fit.per_frf.size()) {
                for (const auto& md : g.fit.per_frf[i].modes) constants.append(md.modal_constant);
              }
              f["modal_constants"] = constants;
              frf_list.append(f);
            }
            for (const auto& md : g.fit.modes) {
              py::dict d;
              d["freq_hz"] = md.freq_hz;
              d["damping_ratio"] = md.damping_ratio;
              d["stable_orders"] = md.stable_orders;
              modes.append(d);
            }
            py::dict gd;
            gd["frfs"] = frf_list;
            gd["modes"] = modes;
            gd["ok"] = g.fit.status == SolverStatus::kConverged;
            gd["message"] = g.fit.message;
            // A roving test's shapes (frf-modes --mode-shapes): None with the
            // reason otherwise.
            std::string why;
            if (const auto rs = calibration::ShapesOfRovingTest(g, &why)) {
              py::dict sd;
              sd["roving"] = rs->roving;
              sd["fixed_point"] = rs->fixed_point;
              sd["fixed_direction"] = robomach::ToString(rs->fixed_direction);
              sd["points"] = rs->points;
              std::vector<std::string> dirs;
              for (Axis a : rs->directions) dirs.push_back(robomach::ToString(a));
              sd["directions"] = dirs;
              sd["shapes"] = Eigen::MatrixXcd(rs->shapes);
              sd["mass_normalised"] = rs->mass_normalised;
              gd["shapes"] = sd;
            } else {
              gd["shapes"] = py::none();
              gd["shapes_why_not"] = why;
            }
            fits.append(gd);
          }
          py::list tips;
          for (const calibration::TipMode& t : p.tip_modes) {
            py::dict d;
            d["freq_hz"] = t.freq_hz;
            d["damping_ratio"] = t.damping_ratio;
            d["modal_mass_kg"] = t.modal_mass_kg;
            d["shape"] = Eigen::Vector3d(t.shape);
            d["directions"] = t.directions;
            tips.append(d);
          }
          py::dict pd;
          pd["pose_id"] = p.pose_id;
          pd["fits"] = fits;
          pd["tip_modes"] = tips;
          pd["warnings"] = p.warnings;
          out.append(pd);
        }
        return out;
      },
      py::arg("frfs"), py::arg("noise") = std::map<KeyTuple, calibration::FrfNoise>{}, py::arg("fmin_hz") = 0.0,
      py::arg("fmax_hz") = std::numeric_limits<double>::infinity(), py::arg("max_order") = 100,
      py::arg("per_frf") = false, py::arg("weights") = "noise", py::arg("file_power") = 0,
      "frf-modes' modal analysis: per posture, its FRFs fitted with common poles; returns a list of "
      "{pose_id, fits: [{frfs: [{frf, misfit_relative, misfit_noise_sigmas, modal_constants}], modes: "
      "[{freq_hz, damping_ratio, stable_orders}], ok, message, shapes}], tip_modes: [{freq_hz, damping_ratio, "
      "modal_mass_kg, shape, directions}], warnings}. noise: estimate_noise(frfs, NoiseOptions(global_modal_fit=True)), as the tool takes it (the fit's weights and usable "
      "lines); weights 'noise' or 'quantity' (every line of the file's quantity alike, file_power 0 "
      "receptance, 1 mobility, 2 accelerance). shapes: for a roving test (FRFs read with "
      "read_frf_file(..., keep_points=True) sharing one end) {roving: 'excitation' or 'response', fixed_point, "
      "fixed_direction, points, directions, shapes (complex, rows the FRFs, columns the modes; mass-normalised "
      "[1/sqrt(kg)] when the driving point is among them), mass_normalised}, as frf-modes --mode-shapes; "
      "else None and shapes_why_not.");
  m.def("modal_assurance_criterion", &calibration::ModalAssuranceCriterion, py::arg("a"), py::arg("b"),
        "MAC matrix between the columns of two complex shape matrices (same rows), in [0, 1].");

  // ------------------------------------------------------ calibration --
  py::class_<MeasuredFeatures>(m, "MeasuredFeatures",
                               "Modal fits of every measured FRF (extract_features): the modes the "
                               "modal objectives match.")
      .def_property_readonly("modes", [](const MeasuredFeatures& f) {
        std::vector<py::dict> out;
        for (const auto& mm : f.modes) {
          py::dict d;
          d["key"] = FromKey(mm.key);
          d["freq_hz"] = mm.fit.freq_hz;
          d["damping_ratio"] = mm.fit.damping_ratio;
          d["peak_freq_hz"] = mm.peak_freq_hz;
          d["peak_magnitude_m_per_N"] = mm.peak_magnitude;
          d["peak_kind"] = mm.peak_kind == calibration::PeakKind::kShoulder ? "shoulder" : "maximum";
          out.push_back(d);
        }
        return out;
      }, "list of dicts: key (pose_id, response, excitation), freq_hz [Hz], damping_ratio [-], "
         "peak_freq_hz [Hz], peak_magnitude_m_per_N [m/N] (the maximum of the fitted curve within the mode's "
         "own half-power band, cut at the midpoints to the other modes of the FRF), peak_kind 'maximum' or "
         "'shoulder' (no maximum of its own in that window, on a stronger neighbour's flank: the peak is then "
         "|H| at the mode's own resonance f_n sqrt(1 - 2 zeta^2))")
      .def_property_readonly("fit_status", [](const MeasuredFeatures& f) {
        std::map<KeyTuple, std::string> out;
        for (const auto& [k, r] : f.fits) {
          out[FromKey(k)] = r.status == SolverStatus::kConverged
                                ? std::string(robomach::ToString(r.status))
                                : std::string(robomach::ToString(r.status)) + ": " + r.message;
        }
        return out;
      }, "{key: 'converged' | 'failed: <why>' (no stable pole, too few lines)} per FRF");
  m.def("extract_features", [](const dynamics::FrfSet& measured, double fmin_hz, double fmax_hz) {
    py::gil_scoped_release release;
    return Features(measured, fmin_hz, fmax_hz);
  }, py::arg("measured"), py::arg("fmin_hz") = 0.0, py::arg("fmax_hz") = std::numeric_limits<double>::infinity(),
     "Fits the modes of every FRF in the band [fmin_hz, fmax_hz] [Hz] (LSCF with a stabilisation "
     "diagram). Releases the GIL.");

  py::class_<ParameterEstimate>(m, "ParameterEstimate", "One calibrated parameter, in its unit (SI).")
      .def_readonly("name", &ParameterEstimate::name)
      .def_readonly("unit", &ParameterEstimate::unit)
      .def_readonly("initial", &ParameterEstimate::initial)
      .def_readonly("value", &ParameterEstimate::value)
      .def_readonly("std_dev", &ParameterEstimate::std_dev, "1 sigma from the covariance (NaN if none)")
      .def_readonly("weakly_identified", &ParameterEstimate::weakly_identified)
      .def_readonly("at_bound", &ParameterEstimate::at_bound)
      .def_readonly("stage", &ParameterEstimate::stage)
      .def("__repr__", [](const ParameterEstimate& e) {
        return "<ParameterEstimate " + e.name + " = " + std::to_string(e.value) + " " + e.unit + ">";
      });
  py::class_<StageSummary>(m, "StageSummary", "One solver stage of a calibration.")
      .def_readonly("name", &StageSummary::name)
      .def_readonly("parameters", &StageSummary::parameters)
      .def_readonly("termination", &StageSummary::termination)
      .def_readonly("message", &StageSummary::message, "Ceres' summary message, verbatim")
      .def_readonly("iterations", &StageSummary::iterations)
      .def_readonly("num_residuals", &StageSummary::num_residuals)
      .def_readonly("initial_cost", &StageSummary::initial_cost)
      .def_readonly("final_cost", &StageSummary::final_cost)
      .def_readonly("covariance_ok", &StageSummary::covariance_ok);
  py::class_<ModeMatch>(m, "ModeMatch", "A measured mode paired with a model mode of the same posture.")
      .def_property_readonly("key", [](const ModeMatch& x) { return FromKey(x.key); })
      .def_readonly("model_mode", &ModeMatch::model_mode, "0-based index in PostureDynamics.modes")
      .def_readonly("measured_freq_hz", &ModeMatch::measured_freq_hz)
      .def_readonly("model_freq_hz", &ModeMatch::model_freq_hz)
      .def_readonly("measured_peak", &ModeMatch::measured_peak, "[m/N]")
      .def_readonly("model_peak", &ModeMatch::model_peak, "[m/N]")
      .def_readonly("measured_damping", &ModeMatch::measured_damping)
      .def_readonly("model_damping", &ModeMatch::model_damping)
      .def_property_readonly("freq_error", &ModeMatch::freq_error, "model/measured - 1")
      .def_property_readonly("peak_error", &ModeMatch::peak_error, "model/measured - 1");
  py::class_<CalibrationResult>(m, "CalibrationResult", "What calibrate() found; never raises for a poor fit.")
      .def_property_readonly("status", [](const CalibrationResult& r) { return robomach::ToString(r.status); },
                             "'converged', 'not_converged', 'failed' or 'not_improved' (no start fitted better: the start "
                             "values are kept), as frf-calibrate's summary writes it")
      .def_readonly("message", &CalibrationResult::message)
      .def_property_readonly("parameters", [](const CalibrationResult& r) { return ParameterDict(r.parameters); },
                             "{name: value} of the full set with calibrated values (SI)")
      .def_readonly("estimates", &CalibrationResult::estimates)
      .def_readonly("stages", &CalibrationResult::stages)
      .def_readonly("weakly_identified", &CalibrationResult::weakly_identified)
      .def_readonly("matches_before", &CalibrationResult::matches_before)
      .def_readonly("matches_after", &CalibrationResult::matches_after)
      .def_readonly("misfit_start", &CalibrationResult::misfit_start, "whole-curve chi^2 at the start values")
      .def_readonly("misfit_final", &CalibrationResult::misfit_final, "whole-curve chi^2 of the result")
      .def_readonly("start_used", &CalibrationResult::start_used)
      .def_readonly("starts_tried", &CalibrationResult::starts_tried)
      .def_readonly("covariance", &CalibrationResult::covariance,
                    "covariance of the free parameters' values (estimates order, SI units; NaN rows for a parameter "
                    "without one; block-diagonal over the two-stage objective's stages)")
      .def("uncertainty", [](const CalibrationResult& r, const std::string& source) {
        calibration::FittedUncertainty fu = calibration::FittedParameterUncertainty(r, source);
        return py::make_tuple(fu.uncertainty, fu.left_out);
      }, py::arg("source") = "robomach calibrate",
         "(ParameterUncertainty, left_out): what frf-calibrate --uncertainty-out writes (log scale; parameters "
         "without a covariance or with sigma above their value left out, named with why)")
      .def("__repr__", [](const CalibrationResult& r) {
        return std::string("<CalibrationResult ") + robomach::ToString(r.status) + ">";
      });

  m.def("calibrate", [](const io::RobotConfig& config, const std::map<std::string, Eigen::VectorXd>& postures,
                        const dynamics::FrfSet& measured, const std::string& objective,
                        const std::vector<std::string>& free_parameters, double fmin_hz, double fmax_hz,
                        int max_iterations, bool extra_starts, const MeasuredFeatures* features) {
    CalibrationOptions o;
    o.objective = calibration::ParseObjective(objective);
    o.free_parameters = free_parameters;
    o.fmin_hz = fmin_hz;
    o.fmax_hz = fmax_hz;
    o.modal_fit.fmin_hz = fmin_hz;
    o.modal_fit.fmax_hz = fmax_hz;
    o.max_iterations = max_iterations;
    o.extra_starts = extra_starts;
    if (o.free_parameters.empty()) throw std::invalid_argument("free_parameters: expected at least one name");
    if (max_iterations < 1) throw std::invalid_argument("max_iterations: expected >= 1");
    py::gil_scoped_release release;
    const MeasuredFeatures own = features ? MeasuredFeatures{} : calibration::ExtractFeatures(measured, o.modal_fit);
    return calibration::Calibrate(config.description, config.parameters, Postures(postures), measured,
                                  features ? *features : own, o);
  }, py::arg("config"), py::arg("postures"), py::arg("measured"), py::arg("objective") = "modal-two-stage",
     py::arg("free_parameters") = std::vector<std::string>{"m6_kg", "d6_m", "alpha_s", "beta_per_s"},
     py::arg("fmin_hz") = 0.0, py::arg("fmax_hz") = std::numeric_limits<double>::infinity(),
     py::arg("max_iterations") = 100, py::arg("extra_starts") = true, py::arg("features") = nullptr,
     "Calibrates free_parameters of `config` (RobotConfig; its values are the start) against "
     "`measured` (FrfSet, receptance [m/N]; usable_data(...) of it to fit with the noise model, as "
     "frf-calibrate does) at `postures` ({pose_id: q [rad]}). objective: 'modal-two-stage', "
     "'modal-joint' or 'whole-curve'; band [fmin_hz, fmax_hz] [Hz]. features: extract_features() "
     "of measured (computed here if None). Returns a CalibrationResult; a poor fit is a status, not "
     "an exception. ValueError for an unknown parameter or a measured posture missing from "
     "postures. Releases the GIL (it can take seconds to minutes).");
  // The library's defaults (frf-synth's), so that the two cannot drift apart.
  const calibration::VirtualHammerOptions kHammer;
  m.def("synthesize_hammer_test",
        [](const io::RobotConfig& config, const std::vector<io::Posture>& postures, std::optional<double> sample_rate_hz,
           int block_samples, double fmin_hz, double fmax_hz, const std::string& directions, double noise_rel,
           double noise_abs_m_per_N, double noise_abs_m_per_s_per_N, double noise_abs_m_per_s2_per_N,
           double hammer_cutoff_hz, int averages, unsigned seed, bool coherence) {
          calibration::VirtualHammerOptions o;
          o.sample_rate_hz = sample_rate_hz ? *sample_rate_hz : calibration::ConfiguredSampleRateHz(config.description);
          o.block_samples = block_samples;
          o.fmin_hz = fmin_hz;
          o.fmax_hz = fmax_hz;
          o.directions.clear();
          for (const auto& [r, e] : io::ParseDirectionPairs(directions)) {
            o.directions.emplace_back(static_cast<Axis>(r), static_cast<Axis>(e));
          }
          o.relative_noise = noise_rel;
          o.absolute_noise_m_per_N = noise_abs_m_per_N;
          o.absolute_noise_m_per_s_per_N = noise_abs_m_per_s_per_N;
          o.absolute_noise_m_per_s2_per_N = noise_abs_m_per_s2_per_N;
          o.hammer_cutoff_hz = hammer_cutoff_hz;
          o.averages = averages;
          o.seed = seed;
          o.coherence = coherence;
          o.Validate();
          const auto model = config.Build();
          std::vector<calibration::NamedPosture> named;
          for (const io::Posture& p : postures) named.push_back({p.id, p.q});
          py::gil_scoped_release release;
          return calibration::SynthesizeHammerTest(model, named, o);
        },
        py::arg("config"), py::arg("postures"), py::arg("sample_rate_hz") = py::none(),
        py::arg("block_samples") = kHammer.block_samples, py::arg("fmin_hz") = kHammer.fmin_hz,
        py::arg("fmax_hz") = kHammer.fmax_hz, py::arg("directions") = "xx,yy",
        py::arg("noise_rel") = kHammer.relative_noise, py::arg("noise_abs_m_per_N") = kHammer.absolute_noise_m_per_N,
        py::arg("noise_abs_m_per_s_per_N") = kHammer.absolute_noise_m_per_s_per_N,
        py::arg("noise_abs_m_per_s2_per_N") = kHammer.absolute_noise_m_per_s2_per_N,
        py::arg("hammer_cutoff_hz") = kHammer.hammer_cutoff_hz, py::arg("averages") = kHammer.averages,
        py::arg("seed") = kHammer.seed, py::arg("coherence") = kHammer.coherence,
        "frf-synth's call: a virtual hammer test with known truth. The tool-tip receptance [m/N] of the "
        "config's model at `postures` (a list of Posture, as read_posture_file gives; their order fixes the "
        "noise) on the grid k*fs/N within [fmin_hz, fmax_hz], with seeded noise H (1 + noise_rel n1) + floor(f) "
        "n2 (floors flat in receptance, mobility, accelerance, raised above hammer_cutoff_hz). sample_rate_hz "
        "None: the config's hammer_test.sample_rate_hz, else 5120. coherence: the H1 coherence of that noise "
        "for `averages` impacts. Returns an FrfSet; write_frf_csv(path, frfs, quantity, averages if coherence "
        "else 0) writes what frf-synth writes. ValueError for bad options. Releases the GIL.");
  m.def("judge_calibration", [](const CalibrationResult& result, const dynamics::FrfSet& measured, double fmin_hz,
                                double fmax_hz) {
    CalibrationOptions o;
    o.fmin_hz = fmin_hz;
    o.fmax_hz = fmax_hz;
    const calibration::CalibrationVerdict v = calibration::JudgeCalibration(result, measured, o);
    py::dict d;
    d["status"] = robomach::ToString(v.status());
    d["findings"] = FindingMessages(v.verdict);
    d["residuals"] = v.residuals;
    d["rms_per_residual_in_noise_units"] = v.rms_per_residual_in_noise_units;
    return d;
  }, py::arg("result"), py::arg("measured"), py::arg("fmin_hz") = 0.0,
     py::arg("fmax_hz") = std::numeric_limits<double>::infinity(),
     "frf-calibrate's verdict on a CalibrationResult of calibrate(..., measured, fmin_hz, fmax_hz): "
     "{'status': 'ok' or 'flagged', 'findings': [str], 'residuals', 'rms_per_residual_in_noise_units'}. Flagged "
     "when no start improved on the config, a stage did not converge, a parameter is weakly identified, or (every "
     "FRF with its noise model, as usable_data gives) the rms residual exceeds 1.3 times the noise. frf-calibrate "
     "exits 3 then.");
  m.def("whole_curve_misfit", [](const io::RobotConfig& config, const std::map<std::string, Eigen::VectorXd>& postures,
                                 const dynamics::FrfSet& measured, double fmin_hz, double fmax_hz) {
    py::gil_scoped_release release;
    return calibration::WholeCurveMisfit(config.description, config.parameters, Postures(postures), measured,
                                         fmin_hz, fmax_hz);
  }, py::arg("config"), py::arg("postures"), py::arg("measured"), py::arg("fmin_hz") = 0.0,
     py::arg("fmax_hz") = std::numeric_limits<double>::infinity(),
     "Sum over lines of the squared log-magnitude and phase residuals (in units of the noise when "
     "the FRFs carry sigma): the chi^2 a calibration lowers; inf if the model cannot be evaluated.");

  // ------------------------------------------ joint stiffness (kq) --
  py::class_<LoadCase>(m, "LoadCase",
                       "One load case of a laser-tracker test: posture q [rad], force F in B [N], "
                       "measured target displacement D in B [m]; load point and target in the tip "
                       "frame [m] (None = the TCP).")
      .def(py::init([](std::string case_id, Eigen::VectorXd q, Eigen::Vector3d force, Eigen::Vector3d displacement,
                       std::optional<Eigen::Vector3d> p_load_tip, std::optional<Eigen::Vector3d> p_target_tip,
                       std::string pose_id) {
             LoadCase c;
             c.case_id = std::move(case_id);
             c.pose_id = std::move(pose_id);
             c.q = std::move(q);
             c.force = force;
             c.displacement = displacement;
             c.p_load_tip = p_load_tip;
             c.p_target_tip = p_target_tip;
             return c;
           }),
           py::arg("case_id"), py::arg("q"), py::arg("force_N"), py::arg("displacement_m"),
           py::arg("p_load_tip_m") = py::none(), py::arg("p_target_tip_m") = py::none(), py::arg("pose_id") = "")
      .def_readonly("case_id", &LoadCase::case_id)
      .def_readonly("pose_id", &LoadCase::pose_id)
      .def_property_readonly("q", [](const LoadCase& c) { return Eigen::VectorXd(c.q); }, "[rad]")
      .def_property_readonly("force_N", [](const LoadCase& c) { return Eigen::Vector3d(c.force); })
      .def_property_readonly("displacement_m", [](const LoadCase& c) { return Eigen::Vector3d(c.displacement); })
      .def_readonly("p_load_tip_m", &LoadCase::p_load_tip)
      .def_readonly("p_target_tip_m", &LoadCase::p_target_tip)
      .def_readonly("line", &LoadCase::line);
  m.def("read_tracker_file", [](const std::string& path, int num_joints) {
    RequireReadableFile(path);
    py::gil_scoped_release release;
    const io::TrackerFile tf = io::ReadTrackerFile(path, num_joints);
    std::vector<LoadCase> cases;
    for (const auto& meas : tf.measurements) cases.push_back(identification::ToLoadCase(meas));
    return cases;
  }, py::arg("path"), py::arg("num_joints"),
     "Reads a laser-tracker load-test file (docs/formats.md §2; force or rope form) into LoadCases "
     "(SI, radians). InputError with file:line:col.");

  py::class_<CaseResidual>(m, "CaseResidual", "The residual of one load case at the solution [m, in B].")
      .def_readonly("case_id", &CaseResidual::case_id)
      .def_property_readonly("measured", [](const CaseResidual& c) { return Eigen::Vector3d(c.measured); })
      .def_property_readonly("predicted", [](const CaseResidual& c) { return Eigen::Vector3d(c.predicted); })
      .def_property_readonly("residual", [](const CaseResidual& c) { return Eigen::Vector3d(c.residual); })
      .def_readonly("norm", &CaseResidual::norm, "[m]")
      .def_readonly("normalized", &CaseResidual::normalized, "|residual| / sigma_D [-]")
      .def_readonly("outlier", &CaseResidual::outlier);
  py::class_<JointStiffnessResult>(m, "JointStiffnessResult", "What identify_joint_stiffness() found.")
      .def_property_readonly("status", [](const JointStiffnessResult& r) { return std::string(robomach::ToString(r.status)); },
                             "'converged', 'not_converged' or 'failed', as kq-identify's summary writes it")
      .def_readonly("solver_message", &JointStiffnessResult::solver_message)
      .def_readonly("num_cases", &JointStiffnessResult::num_cases)
      .def_readonly("joint_stiffness", &JointStiffnessResult::joint_stiffness,
                    "[N·m/rad]; a not-determined joint keeps the prior")
      .def_readonly("std_dev", &JointStiffnessResult::std_dev, "1 sigma [N·m/rad]; inf for a joint held at the prior")
      .def_readonly("lower_95", &JointStiffnessResult::lower_95, "[N·m/rad]")
      .def_readonly("upper_95", &JointStiffnessResult::upper_95, "[N·m/rad]")
      .def_readonly("relative_std", &JointStiffnessResult::relative_std, "sigma(log k) [-]")
      .def_readonly("correlation", &JointStiffnessResult::correlation)
      .def_property_readonly("determination", [](const JointStiffnessResult& r) {
        std::vector<std::string> out;
        for (auto d : r.determination) out.emplace_back(identification::ToString(d));
        return out;
      }, "per joint: 'determined', 'weak' or 'not determined'")
      .def_readonly("weakly_identified", &JointStiffnessResult::weakly_identified, "0-based joint indices")
      .def_readonly("not_determined", &JointStiffnessResult::not_determined, "0-based joint indices")
      .def_readonly("advice", &JointStiffnessResult::advice)
      .def_readonly("residuals", &JointStiffnessResult::residuals)
      .def_readonly("outliers", &JointStiffnessResult::outliers)
      .def_readonly("rms_residual", &JointStiffnessResult::rms_residual, "over inliers [m]")
      .def_readonly("reduced_chi2", &JointStiffnessResult::reduced_chi2)
      .def_readonly("condition_number", &JointStiffnessResult::condition_number)
      .def_readonly("linear_start", &JointStiffnessResult::linear_start, "[N·m/rad]")
      .def_readonly("iterations", &JointStiffnessResult::iterations)
      .def_readonly("outliers_in_fit", &JointStiffnessResult::outliers_in_fit,
                    "outliers found and, without a robust loss, kept in the fit")
      .def_property_readonly("flagged", &JointStiffnessResult::flagged,
                             "kq-identify's exit 3: not converged, a joint weakly or not determined, or outliers "
                             "kept in the fit");
  const identification::IdentificationOptions id_defaults;
  m.def("identify_joint_stiffness", [](const std::shared_ptr<dynamics::RobotModel>& model,
                                       const std::vector<LoadCase>& cases, double tracker_noise_m,
                                       const std::string& loss, double loss_scale, double outlier_false_alarm,
                                       double weak_relative_std, int max_iterations) {
    identification::IdentificationOptions o;
    o.tracker_noise = tracker_noise_m;
    o.loss = identification::ParseRobustLoss(loss.empty() ? "none" : loss);
    o.loss_scale = loss_scale;
    o.outlier_false_alarm = outlier_false_alarm;
    o.weak_relative_std = weak_relative_std;
    o.max_iterations = max_iterations;
    o.Validate();
    py::gil_scoped_release release;
    return identification::IdentifyJointStiffness(*model, cases, o);
  }, py::arg("model"), py::arg("cases"), py::arg("tracker_noise_m") = id_defaults.tracker_noise,
     py::arg("loss") = "none", py::arg("loss_scale") = id_defaults.loss_scale,
     py::arg("outlier_false_alarm") = id_defaults.outlier_false_alarm,
     py::arg("weak_relative_std") = id_defaults.weak_relative_std, py::arg("max_iterations") = id_defaults.max_iterations,
     "Identifies the diagonal joint stiffness [N·m/rad] from load cases (kq-identify's library "
     "call); the model's stiffness is the prior. tracker_noise_m: 1 sigma per measured coordinate "
     "[m]; loss: 'none', 'huber', 'cauchy'. Numerical trouble is a status in the result. Releases "
     "the GIL.");

  m.def("run_kq_identify", [](const std::string& robot, const std::string& tracker, double noise_mm,
                              const std::string& robust) {
    workflows::KqIdentifyOptions o;
    o.robot_path = robot;
    o.tracker_path = tracker;
    o.noise_mm = noise_mm;
    o.robust = robust;
    o.Validate();
    RequireReadableFile(robot);
    RequireReadableFile(tracker);
    CollectedMessages said;
    workflows::KqIdentifyResult run;
    {
      py::gil_scoped_release release;
      run = workflows::RunKqIdentify(o, said.Sink());
    }
    for (const std::string& f : run.config.implausible) WarnUnit(f);
    for (const std::string& f : run.unit_findings) WarnUnit(f);
    py::dict d;
    d["fit"] = run.fit;
    d["messages"] = said.List();
    d["unit_findings"] = run.unit_findings;
    d["flagged"] = run.flagged();
    d["report"] = workflows::KqReportLines(run.fit);
    d["summary"] = py::module_::import("json").attr("loads")(run.Summary().dump());
    return d;
  }, py::arg("robot"), py::arg("tracker"), py::arg("noise_mm") = workflows::KqIdentifyOptions{}.noise_mm,
     py::arg("robust") = "",
     "kq-identify as one call (workflows::RunKqIdentify): a robot config and a tracker file (formats.md §2), the "
     "tool's --noise-mm and --robust ('', 'cauchy', 'huber'). Returns a dict: fit (JointStiffnessResult), "
     "messages (dicts {kind, text}: the warnings the tool prints before its table), unit_findings (also as "
     "UnitWarning, with the config's), flagged (the tool's exit 3), report (the table's lines) and summary (the "
     "tool's --summary JSON but for tool, exit_code and warnings). ValueError naming the option; "
     "FileNotFoundError, InputError for files. Releases the GIL.");

  const workflows::FrfCalibrateOptions kCal;  // frf-calibrate's defaults
  m.def("run_frf_calibrate",
        [](const std::string& robot, const std::string& postures, const std::vector<std::string>& measured,
           const std::vector<std::string>& pose, const std::vector<std::string>& validate,
           const std::vector<std::string>& validate_pose, const std::optional<std::string>& out,
           const std::vector<std::string>& frees, bool only_free, const std::map<std::string, double>& sets,
           const std::vector<std::string>& adds, const std::string& objective, double fmin_hz, double fmax_hz,
           int max_iterations, double robust_loss_sigma, const std::string& noise_model, double min_snr,
           int averages, bool drift_floor) {
          workflows::FrfCalibrateOptions o;
          o.robot_path = robot;
          o.postures_path = postures;
          o.measured_files = measured;
          o.pose_files = pose;
          o.validate_files = validate;
          o.validate_pose_files = validate_pose;
          o.pose_files_name = "pose";
          o.validate_pose_files_name = "validate_pose";
          o.out_path = out.value_or("");
          o.frees = frees;
          o.only_free = only_free;
          for (const auto& [name, value] : sets) o.sets.push_back(name + "=" + FormatNumber(value, 17));
          o.adds = adds;
          o.objective = objective;
          o.fmin_hz = fmin_hz;
          o.fmax_hz = fmax_hz;
          o.max_iterations = max_iterations;
          o.robust_loss_sigma = robust_loss_sigma;
          o.noise = {noise_model, min_snr, averages, drift_floor};
          o.Validate();
          RequireReadableFile(robot);
          RequireReadableFile(postures);
          for (const std::string& f : measured) RequireReadableFile(f);
          for (const std::string& f : validate) RequireReadableFile(f);
          for (const std::vector<std::string>* v : {&pose, &validate_pose}) {
            for (const std::string& f : *v) {
              if (f.find('=') != std::string::npos) RequireReadableFile(f.substr(f.find('=') + 1));
            }
          }
          CollectedMessages said;
          workflows::FrfCalibrateRun run;
          nlohmann::json summary;
          {
            py::gil_scoped_release release;
            run = workflows::RunFrfCalibrate(o, said.Sink());
            // frf-calibrate's summary.json, as the tool composes it.
            std::vector<report::TableSet> sets_out = {{"fit", &run.features, run.fit_before, run.fit_after}};
            if (!run.holdout.empty()) {
              sets_out.push_back({"holdout", &run.holdout_features, run.holdout_before, run.holdout_after});
            }
            summary = report::FrfCalibrateSummaryJson(run.result, run.options, sets_out, run.Misfit(), run.noise,
                                                      run.holdout_noise, o.noise.noise_model, o.noise.min_snr,
                                                      o.robot_path);
          }
          for (const std::string& f : run.config.implausible) WarnUnit(f);
          for (const std::string& f : run.measured_read.unit_findings) WarnUnit(f);
          for (const std::string& f : run.holdout_read.unit_findings) WarnUnit(f);
          py::dict d;
          d["result"] = run.result;
          d["parameters"] = ParameterDict(run.result.parameters);
          d["config_text"] = run.config_text;
          d["result_lines"] = run.ResultLines();
          d["messages"] = said.List();
          d["flags"] = run.flags;
          d["findings"] = FindingMessages(run.verdict.verdict);
          d["status"] = robomach::ToString(run.status());
          d["flagged"] = run.status() == RunStatus::kFlagged;
          d["summary"] = py::module_::import("json").attr("loads")(summary.dump());
          return d;
        },
        py::arg("robot"), py::arg("postures"), py::arg("measured") = std::vector<std::string>{},
        py::arg("pose") = std::vector<std::string>{}, py::arg("validate") = std::vector<std::string>{},
        py::arg("validate_pose") = std::vector<std::string>{}, py::arg("out") = py::none(),
        py::arg("frees") = kCal.frees, py::arg("only_free") = kCal.only_free,
        py::arg("sets") = std::map<std::string, double>{}, py::arg("adds") = kCal.adds,
        py::arg("objective") = kCal.objective, py::arg("fmin_hz") = kCal.fmin_hz, py::arg("fmax_hz") = kCal.fmax_hz,
        py::arg("max_iterations") = kCal.max_iterations, py::arg("robust_loss_sigma") = kCal.robust_loss_sigma,
        py::arg("noise_model") = kCal.noise.noise_model, py::arg("min_snr") = kCal.noise.min_snr,
        py::arg("averages") = kCal.noise.averages, py::arg("drift_floor") = kCal.noise.drift_floor,
        "frf-calibrate as one call (workflows::RunFrfCalibrate): a robot config, a posture file and measured FRF "
        "files (measured: CSV or UFF58; pose: 'ID=file.uff' of one posture; validate, validate_pose: held out), the "
        "tool's options under their names without dashes (frees: --free, sets: {name: value} for --set, adds: "
        "--add). Returns a dict: result (CalibrationResult), parameters ({name: value}, calibrated), config_text (the "
        "calibrated config, its relative urdf path made valid from `out`'s folder; not written), result_lines (what "
        "the tool prints last), messages ({kind, text}), flags (what flags the run), findings (the verdict's), "
        "status, flagged (the tool's exit 3 but for --uncertainty-out) and summary (the report's summary.json but "
        "for calibrated_config, uncertainty_out and warnings). Unit findings are UnitWarnings too. ValueError naming "
        "the option; FileNotFoundError, InputError for files. Releases the GIL (seconds to minutes).");

  const workflows::TrackerSynthOptions kTracker;  // tracker-synth's defaults
  m.def("run_tracker_synth",
        [](const std::string& robot, const std::optional<std::string>& postures,
           const std::optional<std::string>& plan_file, int num_postures, double min_reach_mm,
           const std::string& masses_kg, const std::vector<std::string>& pulley_mm,
           const std::optional<std::string>& load_point_mm, const std::optional<std::string>& target_mm,
           double noise_mm, int outliers, double outlier_mm, const std::string& form, unsigned seed,
           const std::map<std::string, double>& sets, const std::optional<std::string>& out) {
          workflows::TrackerSynthOptions o;
          o.robot_path = robot;
          o.postures_path = postures.value_or("");
          o.plan_path = plan_file.value_or("");
          o.num_postures = num_postures;
          o.min_reach_mm = min_reach_mm;
          o.masses_kg = masses_kg;
          o.pulley_mm = pulley_mm;
          o.load_point_mm = load_point_mm;
          o.target_mm = target_mm;
          o.noise_mm = noise_mm;
          o.outliers = outliers;
          o.outlier_mm = outlier_mm;
          o.form = form;
          o.seed = seed;
          for (const auto& [name, value] : sets) o.sets.push_back(name + "=" + FormatNumber(value, 17));
          o.Validate();
          for (const std::string* p : {&o.robot_path, &o.postures_path, &o.plan_path}) {
            if (!p->empty()) RequireReadableFile(*p);
          }
          CollectedMessages said;
          workflows::TrackerSynthRun run;
          {
            py::gil_scoped_release release;
            run = workflows::RunTrackerSynth(o, said.Sink());
            if (out) io::WriteTrackerFile(*out, run.measurements, run.Metadata(o));
          }
          for (const std::string& f : run.config.implausible) WarnUnit(f);
          for (const std::string& f : run.unit_findings) WarnUnit(f);
          std::vector<LoadCase> cases;
          for (const auto& meas : run.measurements) cases.push_back(identification::ToLoadCase(meas));
          py::dict d;
          d["cases"] = cases;
          d["pose_ids"] = run.pose_ids;
          d["postures_source"] = run.postures_source;
          d["outlier_cases"] = run.outlier_cases;
          d["counts"] = run.CountsLine();
          d["messages"] = said.List();
          d["unit_findings"] = run.unit_findings;
          d["status"] = robomach::ToString(run.status());
          d["flagged"] = run.flagged();
          d["summary"] = py::module_::import("json").attr("loads")(run.Summary(o).dump());
          return d;
        },
        py::arg("robot"), py::arg("postures") = py::none(), py::arg("plan_file") = py::none(),
        py::arg("num_postures") = kTracker.num_postures, py::arg("min_reach_mm") = kTracker.min_reach_mm,
        py::arg("masses_kg") = kTracker.masses_kg, py::arg("pulley_mm") = kTracker.pulley_mm,
        py::arg("load_point_mm") = py::none(), py::arg("target_mm") = py::none(),
        py::arg("noise_mm") = kTracker.noise_mm, py::arg("outliers") = kTracker.outliers,
        py::arg("outlier_mm") = kTracker.outlier_mm, py::arg("form") = kTracker.form, py::arg("seed") = kTracker.seed,
        py::arg("sets") = std::map<std::string, double>{}, py::arg("out") = py::none(),
        "tracker-synth as one call (workflows::RunTrackerSynth): a robot config (its joint stiffness the truth), "
        "postures from a posture file, a plan_file (kq-identify --plan) or random, the tool's options under their "
        "names without dashes as the tool takes them (masses_kg 'm1,m2,...', pulley_mm ['x,y,z', ...], "
        "load_point_mm/target_mm 'x,y,z' or 'tcp', None: the plan's or the defaults; sets {name: value}); out: "
        "write the tracker file there as the tool's --out. Returns a dict: cases (LoadCase per measurement), pose_ids, "
        "postures_source, outlier_cases, counts (the line the tool prints), messages ({kind, text}), unit_findings "
        "(also as UnitWarning, with the config's), status, flagged (the tool's exit 3) and summary (the tool's "
        "--summary but for tool, out and warnings). ValueError naming the option; FileNotFoundError, InputError for "
        "files. Releases the GIL.");

  const workflows::FrfSynthOptions kFrfSynth;  // frf-synth's defaults
  std::string frf_synth_directions;  // "xx,yy": the default directions as --directions spells them
  for (const auto& [r, e] : kFrfSynth.hammer.directions) {
    frf_synth_directions += (frf_synth_directions.empty() ? "" : ",") + robomach::ToString(r) + robomach::ToString(e);
  }
  m.def("run_frf_synth",
        [](const std::string& robot, const std::string& postures, const std::optional<std::string>& out,
           const std::map<std::string, double>& sets, const std::vector<std::string>& adds,
           const std::string& directions, const std::optional<double>& sample_rate_hz, int block_samples,
           double fmin_hz, double fmax_hz, double noise_rel, double noise_abs_m_per_N,
           double noise_abs_m_per_s_per_N, double noise_abs_m_per_s2_per_N, double hammer_cutoff_hz, int averages,
           unsigned seed, bool coherence, const std::string& quantity) {
          workflows::FrfSynthOptions o;
          o.robot_path = robot;
          o.postures_path = postures;
          for (const auto& [name, value] : sets) o.sets.push_back(name + "=" + FormatNumber(value, 17));
          o.adds = adds;
          calibration::VirtualHammerOptions& h = o.hammer;
          if (sample_rate_hz) h.sample_rate_hz = *sample_rate_hz;  // None: the config's, else 5120 Hz
          h.block_samples = block_samples;
          h.fmin_hz = fmin_hz;
          h.fmax_hz = fmax_hz;
          h.relative_noise = noise_rel;
          h.absolute_noise_m_per_N = noise_abs_m_per_N;
          h.absolute_noise_m_per_s_per_N = noise_abs_m_per_s_per_N;
          h.absolute_noise_m_per_s2_per_N = noise_abs_m_per_s2_per_N;
          h.hammer_cutoff_hz = hammer_cutoff_hz;
          h.averages = averages;
          h.seed = seed;
          h.coherence = coherence;
          // The unit findings name the keywords whose names are not the fields'.
          o.names = {{"relative_noise", "noise_rel"},
                     {"absolute_noise_m_per_N", "noise_abs_m_per_N"},
                     {"absolute_noise_m_per_s_per_N", "noise_abs_m_per_s_per_N"},
                     {"absolute_noise_m_per_s2_per_N", "noise_abs_m_per_s2_per_N"}};
          o.Validate();
          h.directions.clear();
          for (const auto& [r, e] : io::ParseDirectionPairs(directions)) {
            h.directions.emplace_back(static_cast<Axis>(r), static_cast<Axis>(e));
          }
          const io::FrfQuantity q = io::ParseFrfQuantity(quantity);
          // The format follows out's extension, as the tool's --out (OptionError: ValueError).
          const workflows::FrfFileFormat format =
              out ? workflows::FrfSynthOutputFormat(*out, "out", /*allow_stdout=*/false) : workflows::FrfFileFormat::kCsv;
          RequireReadableFile(o.robot_path);
          RequireReadableFile(o.postures_path);
          CollectedMessages said;
          workflows::FrfSynthRun run;
          std::string sample_rate_at;
          {
            py::gil_scoped_release release;
            workflows::FrfSynthSetup setup = workflows::PrepareFrfSynth(o, said.Sink());
            sample_rate_at = setup.sample_rate_at;
            run = workflows::RunFrfSynth(o, std::move(setup), said.Sink());
            if (out) workflows::WriteFrfSynthOutput(run, o, *out, format, q, said.Sink());
          }
          for (const std::string& f : run.unit_findings) WarnUnit(f);  // the config's among them
          py::dict d;
          d["frfs"] = run.frfs;
          d["sample_rate_hz"] = run.hammer.sample_rate_hz;
          d["sample_rate_at"] = sample_rate_at;
          d["lines"] = calibration::HammerTestGrid(run.hammer).size();
          d["messages"] = said.List();
          d["unit_findings"] = run.unit_findings;
          d["status"] = robomach::ToString(run.status());
          d["flagged"] = run.flagged();
          d["summary"] = py::module_::import("json").attr("loads")(run.Summary(o).dump());
          return d;
        },
        py::arg("robot"), py::arg("postures"), py::arg("out") = py::none(),
        py::arg("sets") = std::map<std::string, double>{}, py::arg("adds") = kFrfSynth.adds,
        py::arg("directions") = frf_synth_directions, py::arg("sample_rate_hz") = py::none(),
        py::arg("block_samples") = kFrfSynth.hammer.block_samples, py::arg("fmin_hz") = kFrfSynth.hammer.fmin_hz,
        py::arg("fmax_hz") = kFrfSynth.hammer.fmax_hz, py::arg("noise_rel") = kFrfSynth.hammer.relative_noise,
        py::arg("noise_abs_m_per_N") = kFrfSynth.hammer.absolute_noise_m_per_N,
        py::arg("noise_abs_m_per_s_per_N") = kFrfSynth.hammer.absolute_noise_m_per_s_per_N,
        py::arg("noise_abs_m_per_s2_per_N") = kFrfSynth.hammer.absolute_noise_m_per_s2_per_N,
        py::arg("hammer_cutoff_hz") = kFrfSynth.hammer.hammer_cutoff_hz,
        py::arg("averages") = kFrfSynth.hammer.averages, py::arg("seed") = kFrfSynth.hammer.seed,
        py::arg("coherence") = kFrfSynth.hammer.coherence,
        py::arg("quantity") = io::ToString(io::FrfQuantity::kReceptance),
        "frf-synth as one call (workflows::PrepareFrfSynth, RunFrfSynth): a virtual hammer test of a robot config "
        "(adds, sets {name: value} applied) at the postures of a posture file, the tool's options under their names "
        "without dashes (defaults: FrfSynthOptions; sample_rate_hz None: the config's hammer_test.sample_rate_hz, "
        "else 5120 Hz); out: write the FRFs there as the tool's --out (.csv, or .uff/.unv for UFF58) in `quantity`. "
        "Returns a dict: frfs (FrfSet, receptance [m/N]), sample_rate_hz (as used), sample_rate_at (the config's "
        "file:line:col when it came from there, else ''), lines (of the grid), messages ({kind, text}), "
        "unit_findings (also as UnitWarning, with the config's and the posture file's), status, flagged (the tool's "
        "exit 3) and summary (the tool's --summary but for tool, out, format, quantity, exit_code and warnings). "
        "ValueError naming the option; FileNotFoundError, InputError for files. Releases the GIL.");

  py::class_<identification::PlannedLoad>(m, "PlannedLoad", "One planned rope direction at one posture [SI, in B].")
      .def_readonly("pose_id", &identification::PlannedLoad::pose_id)
      .def_property_readonly("q", [](const identification::PlannedLoad& l) { return Eigen::VectorXd(l.q); }, "[rad]")
      .def_property_readonly("rope_direction", [](const identification::PlannedLoad& l) {
        return Eigen::Vector3d(l.rope_direction);
      }, "unit vector from the load point to the pulley")
      .def_property_readonly("p_load_m", [](const identification::PlannedLoad& l) { return Eigen::Vector3d(l.p_load); })
      .def_property_readonly("p_pulley_m", [](const identification::PlannedLoad& l) {
        return Eigen::Vector3d(l.p_pulley);
      }, "where the rope meets the floor [m]");
  py::class_<PyTestPlan>(m, "TestPlan", "What plan_load_tests() chose (kq-identify --plan).")
      .def_property_readonly("loads", [](const PyTestPlan& p) { return p.plan.loads; },
                             "num_postures x directions_per_posture PlannedLoads")
      .def_property_readonly("cases", [](const PyTestPlan& p) { return p.plan.cases; },
                             "the loads with every mass, as LoadCases without displacement")
      .def_property_readonly("log_det_information", [](const PyTestPlan& p) { return p.plan.log_det_information; },
                             "D-optimality index, log det of the Fisher information of log k")
      .def_property_readonly("expected_relative_std", [](const PyTestPlan& p) { return p.plan.expected_relative_std; },
                             "per joint, sigma(log k) the plan promises [-]; inf where not determined")
      .def_property_readonly("expected_std_dev", [](const PyTestPlan& p) { return p.plan.expected_std_dev; },
                             "per joint [N·m/rad], at the model's stiffness")
      .def_property_readonly("expected_determination", [](const PyTestPlan& p) {
        std::vector<std::string> out;
        for (auto d : p.plan.expected_determination) out.emplace_back(identification::ToString(d));
        return out;
      }, "per joint: 'determined', 'weak' or 'not determined'")
      .def_property_readonly("num_candidates", [](const PyTestPlan& p) { return p.plan.num_candidates; },
                             "feasible candidate postures found")
      .def_property_readonly("findings", [](const PyTestPlan& p) { return FindingMessages(p.plan.verdict); },
                             "one sentence per joint the plan cannot determine")
      .def_property_readonly("flagged", [](const PyTestPlan& p) { return p.plan.verdict.flagged(); },
                             "kq-identify --plan's exit 3: a joint the plan cannot determine, or a target band "
                             "out of reach")
      .def_property_readonly("expected_target_relative_std", [](const PyTestPlan& p) {
        return p.plan.expected_target_relative_std;
      }, "with target_gradients: each target's relative standard deviation with the whole plan")
      .def_property_readonly("target_half_width_by_postures", [](const PyTestPlan& p) {
        return p.plan.target_half_width_by_postures;
      }, "the worst target's relative half-width with the plan's first k postures, k = 1..num_postures")
      .def_property_readonly("postures_for_target_width", [](const PyTestPlan& p) {
        return p.plan.postures_for_target_width;
      }, "the fewest first postures reaching target_half_width (0: the plan does not)")
      .def_property_readonly("postures_for_target_width_estimate", [](const PyTestPlan& p) {
        return p.plan.postures_for_target_width_estimate;
      }, "when the plan does not: about how many postures would");
  m.def("log_stiffness_information", [](const std::shared_ptr<dynamics::RobotModel>& model,
                                        const std::vector<identification::LoadCase>& cases, const Eigen::VectorXd& kq,
                                        double sigma_displacement_m) {
    return identification::LogStiffnessInformation(*model, cases, kq, sigma_displacement_m);
  }, py::arg("model"), py::arg("cases"), py::arg("kq_Nm_per_rad"), py::arg("sigma_displacement_m"),
     "Fisher information of log k of load cases (their forces, no displacement needed) with displacement noise "
     "sigma per coordinate [m]: its inverse is the covariance of log k a campaign of them gives "
     "(identification::LogStiffnessInformation).");
  const identification::PlanOptions plan_defaults;
  m.def("plan_load_tests", [](const std::shared_ptr<dynamics::RobotModel>& model, int num_postures,
                              double tracker_noise_m, const std::vector<double>& masses_kg,
                              const std::optional<Eigen::Vector3d>& p_load_tip_m,
                              const std::optional<Eigen::Vector3d>& p_target_tip_m, double max_rope_angle_rad,
                              int directions_per_posture, unsigned seed, int num_candidate_postures,
                              const std::optional<Eigen::MatrixXd>& target_gradients, double target_half_width) {
    PyTestPlan p;
    identification::PlanOptions& o = p.options;
    o.num_postures = num_postures;
    o.tracker_noise = tracker_noise_m;
    o.masses_kg = masses_kg;
    o.p_load_tip = p_load_tip_m;
    o.p_target_tip = p_target_tip_m;
    o.max_rope_angle = max_rope_angle_rad;
    o.directions_per_posture = directions_per_posture;
    o.seed = seed;
    o.num_candidate_postures = num_candidate_postures;
    if (target_gradients) o.target_gradients = *target_gradients;
    o.target_half_width = target_half_width;
    o.Validate();
    py::gil_scoped_release release;
    p.plan = identification::PlanLoadTests(*model, o);
    return p;
  }, py::arg("model"), py::arg("num_postures") = plan_defaults.num_postures,
     py::arg("tracker_noise_m") = plan_defaults.tracker_noise, py::arg("masses_kg") = plan_defaults.masses_kg,
     py::arg("p_load_tip_m") = py::none(), py::arg("p_target_tip_m") = py::none(),
     py::arg("max_rope_angle_rad") = plan_defaults.max_rope_angle,
     py::arg("directions_per_posture") = plan_defaults.directions_per_posture, py::arg("seed") = plan_defaults.seed,
     py::arg("num_candidate_postures") = plan_defaults.num_candidate_postures,
     py::arg("target_gradients") = py::none(), py::arg("target_half_width") = 0.0,
     "Plans load tests (kq-identify --plan's library call): postures within the joint limits and "
     "rope directions that maximise log det of the Fisher information of log-stiffness at the "
     "model's stiffness (D-optimal), or with target_gradients (joints x targets: d ln y / d ln k, as "
     "kq-identify --target-postures computes them) minimise the targets' summed relative variance; "
     "target_half_width: the relative 95 % half-width wanted. p_load_tip_m, p_target_tip_m: load point and tracker target "
     "in the tip frame [m], None = the TCP. num_candidate_postures 0 = max(400, 4 num_postures). "
     "Deterministic for a seed. Releases the GIL.");
  m.def("write_load_test_plan_csv", [](const std::string& path, const PyTestPlan& p, const std::string& robot_config) {
    io::LoadTestPlanHeader h;
    h.num_postures = p.options.num_postures;
    h.robot_config = robot_config;
    h.tracker_noise_mm = MToMm(p.options.tracker_noise);
    h.masses_kg = p.options.masses_kg;
    h.load_point = p.options.p_load_tip;
    h.target = p.options.p_target_tip;
    py::gil_scoped_release release;
    io::WriteLoadTestPlanCsv(path, p.plan, h);
  }, py::arg("path"), py::arg("plan"), py::arg("robot_config") = "",
     "Writes the plan CSV of kq-identify --plan (docs/kq-identify.md; tracker-synth --plan reads it). "
     "robot_config: the config path its header names. Atomic.");
}

}  // namespace robomach::python
