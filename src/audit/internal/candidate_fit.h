#pragma once

// The audit's candidate fits (issue #5, #18, #33): the whole-curve cost of a
// model against the banded data, the start-value scan, the
// identifiability screen and the fit of one candidate (an effect added to
// the model, or model parameters freed) with its further starts. Private to
// src/audit.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/audit/model_audit.h"
#include "robomach/calibration/frf_calibration.h"
#include "robomach/common/errors.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/dynamics/parameters.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::audit::internal {

// What the whole-curve residuals need of the data, cut to the band once:
// the parts of every candidate's cost evaluation that depend neither on the
// posture's dynamics nor on the parameters (the band's lines, their
// measured receptance and noise weights). The scans of one audit evaluate
// the cost thousands of times; each evaluation used to copy the band out
// of every FRF and recompute its weights.
struct BandedFitData {
  struct Curve {
    int response{0}, excitation{0};
    Eigen::VectorXd freq_hz, weight;
    Eigen::VectorXcd receptance;
  };
  struct Pose {
    Eigen::VectorXd q;
    std::vector<Curve> curves;
  };
  std::vector<Pose> poses;  // FrfSet order: pose_ids(), then ForPose()
  Eigen::Index residuals{0};
  bool missing_posture{false};  // a pose of the data without a posture: no residuals
};

// What every candidate fit shares.
struct FitContext {
  const calibration::PostureMap& postures;
  const dynamics::FrfSet& fit_data;   // decimated lines for the fits
  const dynamics::FrfSet& measured;   // all lines, for the errors
  const calibration::MeasuredFeatures& features;
  const AuditOptions& options;
  double baseline_bic;
  double noise_floor;
  double baseline_error;  // total rms log-magnitude error of the calibrated model
  const dynamics::ParameterSet& user_start;  // the model's own start values
  const BandedFitData& banded;               // fit_data in the band, for the whole-curve costs
};

// The identifiability screen of one candidate at a parameter point.
struct Screen {
  std::vector<std::string> not_identifiable;  // added parameters held at their start values
  std::vector<std::string> held_calibration;  // calibration parameters held (exact trade-off with the effect)
  std::string note;
};

bool Contains(const std::vector<std::string>& v, const std::string& n);
/// Fittable parameters that `effect` adds, prefixed.
std::vector<std::string> FittableOf(const std::string& effect);
/// Whole-curve calibration options of the audit with `free` parameters.
calibration::CalibrationOptions FitOptions(const AuditOptions& o, std::vector<std::string> free);
BandedFitData BandFitData(const calibration::PostureMap& postures, const dynamics::FrfSet& data, double fmin_hz,
                          double fmax_hz);
/// Whole-curve residuals of a model against the banded data (FrfSet order);
/// empty if the model cannot be built or evaluated there.
Eigen::VectorXd WholeCurveResidualVector(const dynamics::RobotDescription& desc,
                                         const dynamics::ParameterSet& params, const BandedFitData& data);
/// Sum of squared whole-curve residuals; +inf where the model fails.
double WholeCurveCost(const dynamics::RobotDescription& desc, const dynamics::ParameterSet& params,
                      const BandedFitData& data);
/// Trial values of one parameter for the start-value scan.
std::vector<double> ScanGrid(const dynamics::ParameterSpec& s, double current);
/// Best-first start-value scan of the `added` parameters.
dynamics::ParameterSet ScanStart(const dynamics::RobotDescription& desc, dynamics::ParameterSet params,
                                 const std::vector<std::string>& added, const BandedFitData& data);
std::vector<std::string> FreeAfter(const std::vector<std::string>& previous, const std::string& effect,
                                   const CandidateResult& c);
double Chi2OfMove(const dynamics::RobotDescription& desc, const dynamics::ParameterSet& at,
                  const Eigen::VectorXd& r_at, const std::string& name, double value, const FitContext& x);
Screen ScreenParameters(const dynamics::RobotDescription& desc, const dynamics::ParameterSet& at,
                        const std::vector<std::string>& calibration, const std::vector<std::string>& added,
                        const FitContext& x);
/// A candidate fit with an effect parameter on a bound, or not converged.
bool Doubtful(const CandidateResult& cand);
/// Whether `challenger` (another start of the same candidate) replaces `incumbent`.
bool Replaces(const CandidateResult& challenger, const CandidateResult& incumbent);
bool NeedsMoreStarts(const CandidateResult& c, const FitContext& x);
/// Marks `c`'s fit failed with `e`'s message (its status, message and note
/// "fit failed: ...", infinite BIC and BIC change, a NaN error): numerical
/// trouble in one candidate (an eigensolver failing at an extreme parameter
/// value) is that candidate's status, reported in its row, not the audit's
/// end. FitCandidate and FitParameterHypothesis catch NumericalError with it.
void MarkFitFailed(const NumericalError& e, CandidateResult* c);
/// Fits `effect` on top of the model (see candidate_fit.cc).
CandidateResult FitCandidate(const dynamics::RobotDescription& base_desc, const dynamics::ParameterSet& start,
                             const std::vector<std::string>& base_effects_added, const std::string& effect,
                             const std::vector<std::string>& base_free, const FitContext& x,
                             bool more_starts = true, const dynamics::ParameterSet* resume = nullptr);
/// The fit of `free` from `from`; a fit stopped by the iteration limit is
/// run again with four times the limit and the better kept.
calibration::CalibrationResult CalibrateWithRetry(const dynamics::RobotDescription& desc,
                                                  const dynamics::ParameterSet& from,
                                                  const std::vector<std::string>& free, const FitContext& x);
/// Every stride-th line of each FRF.
dynamics::FrfSet Decimate(const dynamics::FrfSet& in, int stride);
int AutoLineStride(const dynamics::FrfSet& measured, const calibration::MeasuredFeatures& features);
double ScanCost(const dynamics::ParameterSet& params, const std::vector<std::string>& scanned);
/// Runs fit(i) for i in [0, n) on up to `threads` threads, the costliest first.
std::vector<CandidateResult> RunAll(int n, int threads, const std::function<CandidateResult(int)>& fit,
                                    const std::function<double(int)>& cost);

}  // namespace robomach::audit::internal
