#pragma once

// The report of frf-calibrate: the seed's Table 3 (natural frequency and
// peak amplitude per posture, model against measurement, relative error) as
// CSV and Markdown, one overlay PNG per posture, and a JSON summary.

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "robomach/calibration/frf_calibration.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/dynamics/posture_dynamics.h"

namespace robomach::report {

/// One row set of Table 3: the comparison after calibration, with the same
/// measured mode's comparison before calibration where it was matched then.
struct TableSet {
  std::string label;  // "fit" or "holdout"
  const calibration::MeasuredFeatures* features{nullptr};
  calibration::Comparison before;
  calibration::Comparison after;
};

/// Table 3 as CSV: pose_id, response, excitation, set, model_mode (1-based),
/// measured and model natural frequency [Hz] before and after with relative
/// errors [%], the same for the peak amplitude [m/N], damping ratios, and
/// the model mode's unit tool-tip shape ux, uy, uz (the matching shown).
/// Atomic.
void WriteTable3Csv(const std::string& path, const std::vector<TableSet>& sets);
/// The same as a Markdown table (frequency and amplitude, after calibration,
/// with the error before calibration), plus the unmatched measured modes.
void WriteTable3Markdown(const std::string& path, const std::vector<TableSet>& sets,
                         const std::string& title);

/// Measured FRFs and the model's before and after calibration for one posture.
struct PostureOverlay {
  std::string pose_id;
  std::vector<dynamics::FrfKey> keys;
  std::vector<Eigen::VectorXd> freq_hz;
  std::vector<Eigen::VectorXcd> measured, before, after;  // [m/N]; `after` may be empty
  /// The noise σ per line of each measured FRF [m/N] and its usable band
  /// (text); empty when no noise model is attached (AddNoise).
  std::vector<Eigen::VectorXd> noise_sigma;
  std::vector<std::string> usable;
  std::vector<double> mode_freq_hz;                       // model after calibration (else before)
};

/// The overlay of one posture: every measured FRF of `pose` with the model
/// `before` and `after` (e.g. calibration, or an added effect) on its grid.
PostureOverlay MakePostureOverlay(const std::string& pose, const dynamics::FrfSet& measured,
                                  const dynamics::PostureDynamics& before,
                                  const dynamics::PostureDynamics& after);
/// The same with one model only (`after` empty): measured against `model`.
PostureOverlay MakePostureOverlay(const std::string& pose, const dynamics::FrfSet& measured,
                                  const dynamics::PostureDynamics& model);

/// One PNG: a magnitude and a phase panel per direction pair. The measured
/// curve is drawn wide underneath the models, so that a model that fits it
/// does not hide it. `before_label` and `after_label` name the two models
/// in the legend.
/// The noise models for summary.json: the model option, the SNR threshold,
/// and per FRF its source, rel, floor range, usable bands and line counts.
nlohmann::json NoiseSummaryJson(const calibration::NoiseModels& noise, const std::string& model, double min_snr);

/// Attaches the noise models (σ per line, usable bands) of the overlay's FRFs.
void AddNoise(const calibration::NoiseModels& noise, PostureOverlay* overlay);

void WriteOverlayPng(const std::string& path, const PostureOverlay& overlay, const std::string& title,
                     const std::string& before_label = "model before",
                     const std::string& after_label = "model after");

/// The stabilisation diagrams of the modal fits of one posture's FRFs: one
/// panel per FRF, poles per model order against frequency (stable ones in
/// a second colour), the selected modes as vertical lines.
void WriteStabilisationPng(const std::string& path, const std::string& pose_id,
                           const calibration::MeasuredFeatures& features);

/// The JSON summary: objective, status and solver message, stages,
/// parameters (initial, value, 1-sigma, flags), per-posture errors before
/// and after (fit and holdout sets), the matching, and the modal fits.
nlohmann::json CalibrationSummaryJson(const calibration::CalibrationResult& result,
                                      const calibration::CalibrationOptions& options,
                                      const std::vector<TableSet>& sets);

/// frf-calibrate's summary.json but for the keys only the tool knows
/// (calibrated_config, uncertainty_out): CalibrationSummaryJson with the
/// run's misfit (workflows::FrfCalibrateRun::Misfit), the noise models of
/// the fit and held-out FRFs (holdout_noise only when there are some) and
/// the robot config's path. The tool and Python's run_frf_calibrate both
/// call it, so their summaries cannot drift apart.
nlohmann::json FrfCalibrateSummaryJson(const calibration::CalibrationResult& result,
                                       const calibration::CalibrationOptions& options,
                                       const std::vector<TableSet>& sets, const nlohmann::json& misfit,
                                       const calibration::NoiseModels& noise,
                                       const calibration::NoiseModels& holdout_noise,
                                       const std::string& noise_model, double min_snr,
                                       const std::string& robot_path);

}  // namespace robomach::report
