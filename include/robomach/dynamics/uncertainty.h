#pragma once

#include <cmath>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/dynamics/parameters.h"
#include "robomach/dynamics/robot_model.h"

namespace robomach::dynamics {

/// The coordinate in which a fitted parameter's uncertainty is (close to)
/// Gaussian: its logarithm for a positive scale parameter whose relative
/// error is what a fit determines (a mass), its inverse where the model the
/// fit solved is linear in the inverse (a joint stiffness from tracker
/// displacements, which are linear in the compliances 1/k), the value itself
/// otherwise.
enum class UncertainScale { kLinear, kLog, kInverse };
const char* ToString(UncertainScale s);
/// "linear", "log" or "inverse". @throws std::invalid_argument naming them.
UncertainScale ParseUncertainScale(const std::string& name);

struct UncertainParameter {
  std::string name;   // the model's parameter name, unit in it (kq3_Nm_per_rad)
  double value{0.0};  // the estimate, in that unit
  UncertainScale scale{UncertainScale::kLog};
};

/// Estimates of fitted parameters and the covariance of their coordinates
/// θ_i = log(value_i) (kLog), 1/value_i (kInverse) or value_i (kLinear): what kq-identify writes
/// with --uncertainty-out and the predicting tools read with --uncertainty
/// (docs/formats.md §12, docs/uncertainty.md).
struct ParameterUncertainty {
  std::vector<UncertainParameter> parameters;
  Eigen::MatrixXd covariance;  // n × n, symmetric positive semi-definite
  std::string source;          // the tool and data that fitted them
};

/// @throws std::invalid_argument naming the field: no parameter, a repeated
///   or empty name, a non-finite value, a log- or inverse-scale value <= 0, a covariance
///   of the wrong size, not finite, not symmetric (relative 1e-8) or with an
///   eigenvalue below −1e-9 of the largest (not a covariance), or a
///   relative standard deviation no fit gives (over 100 % on the inverse
///   scale, over a factor of 10 on the log scale: a covariance of the value
///   itself typed under that scale, the message says).
void CheckValid(const ParameterUncertainty& u);

/// The coordinates θ of `values` (one per parameter of `u`, in their
/// units) on each parameter's scale, and back; a compliance θ <= 0 (the
/// inverse scale) has no value: NaN.
Eigen::VectorXd ToTheta(const ParameterUncertainty& u, const Eigen::VectorXd& values);
Eigen::VectorXd FromTheta(const ParameterUncertainty& u, const Eigen::VectorXd& theta);

/// Parameters fitted in different campaigns, taken as independent: the
/// parameter lists concatenated, the covariance block-diagonal.
/// @throws std::invalid_argument if a name occurs in two parts (naming both
///   sources: the same parameter fitted twice must be merged by the fit).
ParameterUncertainty CombineIndependent(const std::vector<ParameterUncertainty>& parts);

/// The inverse of the standard normal distribution function: z with
/// Φ(z) = p, 0 < p < 1 (bisection on std::erfc to 1e-12).
double NormalQuantile(double p);

/// The χ² distribution function with `dof` (>= 1, whole) degrees of
/// freedom, from its closed forms (Abramowitz & Stegun 26.4.4-5).
/// @throws std::invalid_argument for dof < 1.
double ChiSquaredCdf(double x, int dof);
/// Its inverse: the x with ChiSquaredCdf(x, dof) = p, 0 < p < 1 (bisection),
/// the squared radius of a p confidence ellipsoid of dof Gaussian parameters.
/// @throws std::invalid_argument for p outside (0, 1) or dof < 1.
double ChiSquaredQuantile(double p, int dof);

enum class PropagationMethod { kAuto, kFirstOrder, kMonteCarlo };
/// "auto", "first-order", "monte-carlo".
const char* ToString(PropagationMethod m);
/// @throws std::invalid_argument naming the choices.
PropagationMethod ParsePropagationMethod(const std::string& name);

struct PropagationOptions {
  /// Two-sided confidence level of the intervals, in (0, 1).
  double confidence{0.95};
  PropagationMethod method{PropagationMethod::kAuto};
  /// Monte Carlo samples (each one evaluation of the outputs).
  int samples{2000};
  std::uint64_t seed{1};
  /// kAuto keeps the first-order intervals when, at the sigma points
  /// θ̂ ± z √λ_k v_k (z the confidence quantile, λ_k, v_k the covariance's
  /// eigenpairs), every output departs from its linear prediction by at most
  /// this fraction of its first-order half-width z σ; otherwise it runs
  /// Monte Carlo. 0.1: the linearised and Monte Carlo widths then agree
  /// within about 10 % (issue #37).
  double nonlinearity_tolerance{0.1};
  /// First order: central differences along each principal axis (two
  /// evaluations, error O(h²)), or forward differences from the estimates
  /// (one, error O(h)). The step h is 1e-3 standard deviations, so forward
  /// differences are as good for outputs that are smooth at that scale,
  /// such as a local model of them (stability::LocalCriticalDepth). With a
  /// `linearisation` (Propagate) it applies to that; f's own differences,
  /// where the local model does not reach, are always central.
  bool central_differences{true};

  /// confidence in (0, 1); samples in [100, 10 000 000];
  /// nonlinearity_tolerance in (0, 1].
  /// @throws OptionError naming the field, its bound and value
  ///   ("confidence: expected a level in (0, 1), got 95 (a percentage? ...)").
  void Validate() const;
};

/// One output's value at the estimate and its interval.
struct OutputInterval {
  double value{0.0};            // at the estimates
  double std_dev{0.0};          // first order: √(J Σ Jᵀ); Monte Carlo: of the samples
  double lower{0.0}, upper{0.0};
  /// The sigma-point check's largest departure from linear of this output
  /// over its first-order half-width (NaN when not checked).
  double nonlinearity{NAN};
};

struct PropagationResult {
  std::vector<OutputInterval> outputs;
  PropagationMethod method_used{PropagationMethod::kFirstOrder};
  /// Why that method: forced by the options, or the sigma-point check's
  /// result in words ("largest departure from linear 3.2 % of the
  /// half-width, under 10 %").
  std::string reason;
  /// Largest departure from the linear prediction at the sigma points over
  /// the half-width (NaN when not checked).
  double nonlinearity{NAN};
  int evaluations{0};
  /// Monte Carlo samples whose outputs could not be computed (a sampled
  /// parameter outside its bounds, a model that cannot be built); they are
  /// left out of the quantiles and named in `reason`.
  int failed_samples{0};
  /// First order whose derivatives all came from Propagate's
  /// `linearisation` (an output it did not reach at some step takes f's own
  /// central differences, and `reason` says how many).
  bool linearised{false};
};

/// The outputs as a function of the parameters' values, in the order and
/// units of ParameterUncertainty::parameters. May throw for values it cannot
/// evaluate (counted as failed samples in Monte Carlo; fatal at the estimate
/// and in the first-order differences).
using OutputFunction = std::function<Eigen::VectorXd(const Eigen::VectorXd& values)>;

/// Carries the parameter uncertainty to the outputs of `f`.
///
/// First order (the delta method): the derivatives of f along the
/// covariance's principal axes v_k by central differences with steps of
/// 1e-3 √λ_k (2 r + 1 evaluations for a covariance of rank r),
/// Σ_f = Σ_k λ_k (∂f/∂v_k)(∂f/∂v_k)ᵀ = J Σ_θ Jᵀ, interval value ± z σ_f,
/// z = Φ⁻¹((1 + P)/2). Monte Carlo: θ ~ N(θ̂, Σ_θ) drawn with std::mt19937_64
/// from `seed` through the covariance's eigen-decomposition (semi-definite
/// allowed), interval between the (1 − P)/2 and (1 + P)/2 sample quantiles.
/// Auto: first order, checked at 2n sigma points (PropagationOptions);
/// Monte Carlo where the check fails.
/// @throws std::invalid_argument for invalid options or uncertainty, or if
///   f fails at the estimate.
/// `output_names` (optional, one per output) name the output in `reason`.
/// `linearisation` (optional): a local model of f, equal to it to first
/// order at the estimate and smooth at the differences' scale, from which
/// the first-order derivatives are taken instead of from f, whose
/// differences at 1e-3 sigma can be noise (an output interpolated between
/// lines that move with the parameters, a search with a tolerance). The
/// value, the sigma points of the check and Monte Carlo use f.
PropagationResult Propagate(const ParameterUncertainty& u, const OutputFunction& f,
                            const PropagationOptions& options = {}, const std::vector<std::string>& output_names = {},
                            const OutputFunction& linearisation = nullptr);

/// The values of `u`'s parameters placed into a copy of `base` (names must
/// exist in it). @throws std::invalid_argument naming an unknown parameter
///   and the known ones, or a value outside the parameter's bounds.
ParameterSet WithValues(const ParameterSet& base, const ParameterUncertainty& u, const Eigen::VectorXd& values);

/// Puts `u`'s estimates into `parameters` (WithValues at the estimates)
/// and returns the note every tool gives when some changed, "the
/// uncertainty's estimates replace the config's values: kq1_Nm_per_rad
/// 1.2e+06 -> 1.31e+06, ..." ("" when none did).
/// @throws std::invalid_argument as WithValues.
std::string UseEstimates(const ParameterUncertainty& u, ParameterSet* parameters);

/// Intervals of one mode's undamped natural frequency [Hz], damping ratio
/// [-] and peak receptance along its tool-tip shape, 1 / (m ω² 2ζ) with m the
/// effective tip mass [m/N] (0 for a mode that does not move the tip).
struct ModeIntervals {
  OutputInterval freq_hz, damping_ratio, peak_receptance_m_per_N;
};

struct PostureModeIntervals {
  std::vector<ModeIntervals> modes;  // ascending frequency at the estimates
  PropagationResult propagation;     // method, reason, evaluations (outputs: 3 per mode)
};

/// The modes at posture q of the model `description` with `base` parameters
/// and the values of `u` in them, with intervals from `u`'s covariance.
/// Modes are matched by their rank in frequency (a crossing of two modes
/// within the interval swaps them; the propagation's sigma-point check then
/// sees the kink and Monte Carlo gives the band of each rank).
/// @throws std::invalid_argument for an unknown parameter, a q of the wrong
///   size, or a model that cannot be built at the estimates.
PostureModeIntervals ModalIntervals(const RobotDescription& description, const ParameterSet& base,
                                    const Eigen::VectorXd& q, const ParameterUncertainty& u,
                                    const PropagationOptions& options = {});

/// Band of the direct tool-tip receptances |H_xx|, |H_yy|, |H_zz| at a
/// posture (frf-predict's plot, issue #37 §3).
struct ReceptanceBand {
  Eigen::VectorXd freq_hz;                           // the band's lines
  std::array<Eigen::VectorXd, 3> magnitude, lower, upper;  // [m/N], at the estimates and the interval's ends
  PropagationResult propagation;  // outputs: ln|H| per direction, then line
};

/// The interval of ln|H_aa(f)| carried from `u`, returned as magnitudes
/// (exp of the interval's ends), on at most `max_lines` lines of `freq_hz`:
/// every k-th line and the line nearest each mode's frequency at the
/// estimates (so no peak is missed). Near a resonance |H| is far from linear
/// in the parameters (the peak moves): auto then finds it and runs Monte Carlo.
/// @throws std::invalid_argument for max_lines < 2, an unknown parameter or
///   a model that cannot be built at the estimates.
ReceptanceBand DirectReceptanceBand(const RobotDescription& description, const ParameterSet& base,
                                    const Eigen::VectorXd& q, const ParameterUncertainty& u,
                                    const Eigen::VectorXd& freq_hz, const PropagationOptions& options = {},
                                    int max_lines = 400);

/// One line for a terminal: "P1: 95 % intervals (first order): mode 1
/// 11.2 Hz [10.9, 11.5], mode 2 ..." (the three lowest modes).
std::string IntervalLine(const std::string& pose_id, const PostureModeIntervals& intervals, double confidence);

}  // namespace robomach::dynamics
