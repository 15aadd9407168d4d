#pragma once

// The noise of a measured FRF, line by line (issue #10): a model
//
//     σ(f)² = (rel |H(f)|)² + floor(f)²        [m/N]²,  σ² = E|H_measured − H_true|²
//
// from the coherence when the file has it and the number of averages is
// known, otherwise estimated from the scatter of the data themselves; the
// signal-to-noise ratio |H| / floor and the usable band that follows from it.
// Every fit (modal fit, whole-curve calibration, the audit's errors) weights
// its residuals with this σ once it is attached to the data (Frf::WithNoise).

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/solver_status.h"
#include "robomach/dynamics/measured_frf.h"

namespace robomach::calibration {

struct NoiseOptions {
  /// A line is usable where the signal-to-noise ratio |H| / floor(f) reaches
  /// this value (|H| the running median over 5 lines). 3 (about 10 dB):
  /// above it the log-magnitude and phase residuals of a complex Gaussian
  /// error ε = noise/H, E|ε|² ≤ 1/9, are unbiased to E₁(9)/2 ≈ 6e-6 and
  /// their variance is within 10 % of the linearised 1/(2 SNR²) that the
  /// weights assume; at SNR 1 the log-magnitude is biased by E₁(1)/2 ≈ 0.11
  /// and the phase is nearly uniform, so such lines carry no usable
  /// information about the model and only bias a fit.
  double min_snr{3.0};
  /// Number of averages n behind the coherence (H1 estimate); 0: unknown
  /// (then the coherence is not used and the noise is estimated from the
  /// scatter; so too for n = 1, whose coherence is 1 by construction). The
  /// file's `# averages: N` sets it unless an option does.
  int averages{0};
  /// Use the coherence when the FRF has one and `averages` is known.
  bool use_coherence{true};
  /// Knots of the floor's shape (piecewise linear in log f, log floor) per
  /// octave of the band (scatter estimate).
  double knots_per_octave{1.0};
  /// Gaps of at most this many unusable lines inside usable stretches are
  /// kept (an antiresonance dip), and usable stretches shorter than
  /// min_run_lines are dropped, so the usable band is a few clean runs.
  int max_gap_lines{3};
  int min_run_lines{8};
  /// Scatter estimate: a second pass about the modal fit of the usable
  /// lines (see EstimateFrfNoise).
  bool refine_with_modal_fit{true};
  /// That second pass with the global fitter (FitModesGlobal: LSCF to order
  /// 100, clustered poles, a dense FRF band by band) instead of the
  /// single-FRF FitModes: frf-modes' choice (dataset58, 30 modes: 0.6 s
  /// against 20 s). Not yet the default: with it the noise models of the
  /// audit's realistic KR210 case differ enough that its two-effect verdict
  /// changes (issue #34 note); the tools move over together (issue #36).
  bool global_modal_fit{false};
  /// Scatter estimate with the modal-fit pass: also take the additive floor
  /// from second differences over 8 and 16 lines of the residual about the
  /// modal fit (the larger floor wins). A tap test's integrated-accelerometer
  /// drift below ~100 Hz is smooth over a few lines, so the one-line second
  /// differences take it for signal and a modal fit puts modes in it; the
  /// wide ones see it as noise (issue #18). Off by default: where the model,
  /// not the measurement, is smooth-wrong over a few lines (the residual of
  /// a missing effect), the wide floor would count that misfit as noise and
  /// hide the failure an audit looks for (issue #10's hidden tip mass is no
  /// longer flagged with it on). stability-lobes --frf turns it on;
  /// frf-calibrate and model-audit with --drift-floor.
  bool wide_floor{false};
  /// Isolated outlier lines (issue #33 item 4): a line whose complex value
  /// departs from the smooth curve through its neighbours by far more than
  /// the noise (mains hum and its harmonics, a single-line spike) is named
  /// in FrfNoise::excluded_lines and is not usable, so that no fit takes it
  /// for structure. See FindOutlierLines for the method.
  bool exclude_outlier_lines{true};
  /// A line is an outlier when |H_i − Ĥ_i| exceeds this many standard
  /// deviations of that difference, √(σ_i² + var Ĥ_i), Ĥ_i the local
  /// rational fit through its neighbours. For noise alone |H_i − Ĥ_i|²/(σ_i²
  /// + var Ĥ_i) is Exp(1), so the probability of a false alarm per line is
  /// exp(−z²): 2e-16 at z = 6, and still 1e-7 per line (4e-4 in 4096 lines)
  /// if σ were underestimated by a factor of 1.5 (the noise model's floor
  /// is within 25 %).
  double outlier_threshold{6.0};
  /// The threshold for a line that is not at a mains multiple (50 or 60 Hz
  /// and harmonics, within half a line): a single-line spike must be far
  /// beyond the noise to be told from structure the local fit does not
  /// follow, a weak mode narrower than two lines on the flank of a strong
  /// one (seen at 7.9 × the noise at 32.5 Hz of a robot on a compliant
  /// base, 0.625 Hz lines, in clean data).
  double outlier_threshold_off_mains{15.0};
  /// Neighbours on each side of a line that its local fit uses (the lines
  /// next to it and flagged lines are left out of its fit).
  int outlier_window_lines{8};
  /// A run of more than this many neighbouring flagged lines is not an
  /// isolated line but structure the local fit does not follow (two close
  /// modes, a mode narrower than a line): it is kept and not flagged. A run
  /// of two or more is flagged only at a mains multiple (hum leaking
  /// between grid lines); elsewhere only single lines are spikes. A line
  /// whose neighbours the local model does not describe (reduced χ² above
  /// 4) is not judged at all.
  int max_outlier_run_lines{3};

  /// min_snr finite and > 0; averages >= 0; knots_per_octave in (0, 8];
  /// max_gap_lines >= 0; min_run_lines >= 1; outlier_threshold finite and
  /// >= 3; outlier_threshold_off_mains finite and >= outlier_threshold;
  /// outlier_window_lines in [4, 64]; max_outlier_run_lines >= 1.
  /// @throws OptionError naming the field first, with the bound and the
  ///   value ("NoiseOptions: min_snr must be finite and > 0, got -1").
  void Validate() const;
};

enum class NoiseSource { kCoherence, kScatter };
std::string ToString(NoiseSource s);  // "coherence", "scatter"
/// The inverse of ToString. @throws std::invalid_argument naming the two.
NoiseSource ParseNoiseSource(const std::string& name);

/// One line left out of every fit as an isolated outlier (see
/// NoiseOptions::exclude_outlier_lines).
struct ExcludedLine {
  int line{0};             // index in the FRF
  double freq_hz{0.0};
  /// |H − Ĥ| / σ at the line: the size of the departure from the smooth
  /// curve through the neighbours in units of the noise ("38 x the noise").
  double ratio{0.0};
  double excess_m_per_N{0.0};  // |H − Ĥ| [m/N]
  /// The nearest multiple of 50 or 60 Hz is within half a line spacing of
  /// it (0: none): mains hum or a harmonic of it.
  double mains_hz{0.0};
};

/// "50 Hz (38 x the noise, mains hum 50 Hz x1)".
std::string DescribeExcludedLine(const ExcludedLine& line);

/// The noise model of one FRF, per line of the FRF it was estimated from.
struct FrfNoise {
  NoiseSource source{NoiseSource::kScatter};
  int averages{0};                 // used with the coherence
  double relative{0.0};            // rel [-]
  Eigen::VectorXd floor_m_per_N;   // the additive floor [m/N]
  Eigen::VectorXd sigma_m_per_N;   // σ per line [m/N]
  Eigen::VectorXd snr;             // |H| (5-line running median) / floor
  std::vector<char> usable;        // per line
  /// The usable stretches [f_lo, f_hi] in Hz, ascending.
  std::vector<std::pair<double, double>> usable_bands;
  int usable_lines{0};
  /// Iterations of the scatter fit, and how it ended (kConverged, or
  /// kNotConverged at its iteration limit: the estimate is the last step's).
  int iterations{0};
  SolverStatus status{SolverStatus::kConverged};
  bool modal_refined{false};  // the scatter about the modal fit was used
  /// Isolated outlier lines in the usable band, ascending in frequency;
  /// their `usable` is 0 (they are not counted in usable_lines, and the
  /// usable bands are drawn as if they were usable).
  std::vector<ExcludedLine> excluded_lines;
  /// For people: "coherence (5 averages)" or "scatter: rel 2.0 %, floor 3e-9..2e-7 m/N".
  std::string description;
};

/// The noise model of one FRF (see the file comment). Scatter estimate: the
/// second difference d_i = c₀ H_{i−1} + c₁ H_i + c₂ H_{i+1} (weights exact
/// for a straight line, (1, −2, 1) on an even grid) removes the smooth
/// signal; for independent circular complex noise |d_i|² is exponentially
/// distributed with mean v_i = Σ c_j² σ_j². rel and the knots of ln floor
/// are the maximum-likelihood estimate of that model (Fisher scoring on
/// Σ ln v_i + |d_i|²/v_i, with a weak smoothness penalty on the knots so
/// that octaves with one or two lines stay determined), lines whose
/// |d|²/v exceeds 12 (probability e⁻¹² for noise) being dropped and the fit
/// repeated: they are sharp resonance peaks where the signal itself is not
/// smooth on the grid. The signal's curvature still inflates the second
/// differences on the flanks of lightly damped modes (rel came out 30-50 %
/// high with ζ = 0.04 at 12 Hz on a 0.625 Hz grid), so a second pass fits
/// the modes of the usable lines (FitModes with the first σ) and uses the
/// residuals about that fit there, |r_i|² with mean σ_i² (1 − p/2N) for p
/// fitted real parameters on N lines, and the second differences elsewhere.
/// Lines are assumed independent; a window that
/// correlates neighbouring lines (Hann on the response) makes the estimate
/// low, by about 1 − ρ for a neighbour correlation ρ.
///
/// Coherence estimate, for the H1 estimator averaged over n impacts: the
/// normalised random error of |H| is ε² = (1 − γ²) / (2 n γ²), and the same
/// for the phase in radians [Bendat & Piersol 2010, eq. 9.73], so the
/// complex variance is σ² = |H|² (1 − γ²) / (n γ²) for the true coherence.
/// The coherence in a file is itself estimated from the n impacts, and for
/// impacts of equal force amplitude |H|² (1 − γ̂²)/γ̂² = Σ|Y_k − Ȳ|² / n
/// exactly (Y_k = X_k/F_k the single-impact estimates, Ȳ their mean), whose
/// unbiased variance of the mean is that divided by n − 1:
///     σ² = |H|² (1 − γ̂²) / ((n − 1) γ̂²).
/// With n in place of n − 1 the estimate is low by (n − 1)/n (20 % at n = 5;
/// the test checks it against simulated impacts). rel and the floor are then
/// fitted to those σ² (for the SNR and the report).
///
/// - [Bendat & Piersol 2010] J. S. Bendat, A. G. Piersol, Random Data:
///   Analysis and Measurement Procedures, 4th ed., Wiley, 2010, §9.2.
/// @throws std::invalid_argument for bad options or fewer than 8 lines.
FrfNoise EstimateFrfNoise(const dynamics::Frf& frf, const NoiseOptions& options = {});

/// "usable 2.5-412 Hz in 3 stretches (633 of 4096 lines)".
std::string DescribeUsable(const FrfNoise& noise);

/// Isolated outlier lines among the lines with `candidate` set, for the
/// noise σ per line (EstimateFrfNoise calls it; exposed for tests and
/// tools). For each candidate line i a local rational model
///     Ĥ(x) = (n₀ + n₁ x + n₂ x²) / (1 + d₁ x),   x = (f − f_i)/Δf,
/// one complex pole and a linear background, is fitted to the
/// `outlier_window_lines` neighbours on each side, without the lines i−1,
/// i, i+1 and lines already flagged (Sanathanan–Koerner iterations of the
/// linearised Levy problem, weights 1/(σ_k |1 + d₁ x_k|) [Sanathanan &
/// Koerner 1963]), and Ĥ_i = n₀ is compared with H_i: z_i = |H_i − Ĥ_i| /
/// √(σ_i² + var Ĥ_i), var Ĥ_i from the weighted least-squares covariance
/// plus (1e-4 × the window's median |H|)², a tolerance for the local model's
/// own error (measured ≤ 7e-6 on noise-free data; without it noise-free
/// synthetic data, whose σ is the smallest relative noise 1e-6, had a line
/// flagged).
/// A single mode with any damping, on any grid, is exactly of that form
/// near its peak (its other pole and the other modes are smooth over the
/// window), so the peak of a lightly damped mode with only a few lines in
/// its half-power band is predicted from its flanks and not flagged; a
/// one-line spike is not. The line with the largest z above
/// `outlier_threshold` is flagged and left out of its neighbours' fits,
/// which are redone, until no z is above it (a 2-3 line spike is found
/// line by line); runs longer than `max_outlier_run_lines` are unflagged.
///
/// - [Sanathanan & Koerner 1963] C. K. Sanathanan, J. Koerner, Transfer
///   function synthesis as a ratio of two complex polynomials, IEEE Trans.
///   Automatic Control 8(1), 56-58, 1963.
std::vector<ExcludedLine> FindOutlierLines(const dynamics::Frf& frf, const Eigen::VectorXd& sigma_m_per_N,
                                           const std::vector<char>& candidate, const NoiseOptions& options = {});

/// The noise models of every FRF of a campaign.
using NoiseModels = std::map<dynamics::FrfKey, FrfNoise>;
NoiseModels EstimateNoise(const dynamics::FrfSet& measured, const NoiseOptions& options = {});

/// The usable lines of every FRF with their σ attached (Frf::WithNoise):
/// what every fit and error of the calibration and the audit works on.
/// An FRF without a usable line is left out.
/// @throws std::invalid_argument if an FRF has no noise model.
dynamics::FrfSet UsableData(const dynamics::FrfSet& measured, const NoiseModels& noise);

/// Per-line weights of the log-magnitude and phase residuals of
/// WholeCurveResiduals: 1 / s with s = σ / (√2 |H|), the standard deviation
/// of each of ln|H| and arg H under circular complex noise σ (linearised).
/// Without a noise model, all ones.
Eigen::VectorXd LogResidualWeights(const dynamics::Frf& frf);

/// The largest receptance of an FRF on the band its noise model finds
/// usable (issue #34 item 5), for the unit plausibility
/// (dynamics::ReceptancePeakFinding). The largest |H| over all lines is no
/// measure of the unit: a tap test's integrated-accelerometer drift makes
/// its lowest lines 1e-3 m/N and more where the tool tip is 1e-6 m/N (a
/// real tap test: 1.02e-3 m/N at 1-3 Hz, 6.8e-7 m/N on its usable
/// 89-4615 Hz), and a single hit's 1/ω² of any accelerometer offset does the
/// same. The noise model here is EstimateFrfNoise with the wide floor on
/// (the drift, smooth over a few lines, counts as noise: NoiseOptions::
/// wide_floor) and the coherence when `averages` >= 2; the peak is the
/// largest median of three neighbouring usable lines above 0 Hz with
/// coherence >= 0.5 (as dynamics::PeakReceptance). A wrong unit scales
/// every line alike (mm or um under _m: x1e3 or x1e6; kN: x1e3) or by ω
/// (a mobility, an accelerance), and the noise model is invariant to a
/// scale, so its usable band and the resonances in it keep the mistake.
///
/// The usable lines being a subset of all lines, the noise model (seconds on
/// a few thousand lines) is estimated only when the peak of all lines
/// (dynamics::PeakReceptance) is above kMaxPlausibleReceptance: below, the
/// usable band cannot change the verdict on the upper limit, and the lower
/// limit (1e-12 m/N, a force in mN on the stiffest structure) is judged on
/// all lines as before.
struct UsableBandPeak {
  double peak_m_per_N{0.0};
  /// The usable band the peak was taken on [Hz] (first and last usable line).
  double fmin_hz{0.0};
  double fmax_hz{0.0};
  /// True when the peak is the one of the usable band; false when the peak
  /// of all lines is plausible already (no noise model estimated), the
  /// noise model found no usable line or the FRF has fewer than 8 lines:
  /// then the peak is dynamics::PeakReceptance of all lines.
  bool on_usable_band{false};
};
UsableBandPeak PeakReceptanceInUsableBand(const dynamics::Frf& frf, int averages = 0);

/// dynamics::ReceptancePeakFinding of PeakReceptanceInUsableBand, naming
/// the band: "" when plausible. `what` starts the sentence; `format` says
/// where the message tells the user to look for the units.
std::string UsableBandUnitFinding(const std::string& what, const UsableBandPeak& peak,
                                  dynamics::FrfFileFormat format = dynamics::FrfFileFormat::kUnknown);

/// UsableBandUnitFinding of PeakReceptanceInUsableBand of every FRF of the
/// set (`averages` behind each, 0 unknown): one finding per FRF out of
/// range, each starting with `source` and the FRF's key.
std::vector<std::string> ReceptanceUnitFindings(const dynamics::FrfSet& frfs, const std::string& source,
                                                int averages = 0,
                                                dynamics::FrfFileFormat format = dynamics::FrfFileFormat::kUnknown);

}  // namespace robomach::calibration
