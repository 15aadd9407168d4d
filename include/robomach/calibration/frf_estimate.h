#pragma once

// FRFs from raw impact-hammer time records (issue #18, item 4): the H1 and
// H2 estimators with the ordinary coherence, averaged over hits, with a
// force window and an exponential window, and the checks that reject a hit
// (double hit, overload) instead of averaging it.
//
// Estimators [Bendat & Piersol 2010; Ewins 2000]. With F_i(f)
// and X_i(f) the discrete Fourier transforms of the windowed force and
// response of hit i, and the auto and cross spectra summed over the n
// accepted hits
//   G_ff = Σ |F_i|²,   G_xx = Σ |X_i|²,   G_fx = Σ conj(F_i) X_i,          (1)
// the estimates are
//   H1 = G_fx / G_ff,   H2 = G_xx / conj(G_fx),                            (2)
//   γ² = |G_fx|² / (G_ff G_xx) = H1 / H2,   0 ≤ γ² ≤ 1.                    (3)
// Uncorrelated noise on the response biases H2 up and leaves H1 unbiased;
// noise on the force biases H1 down and leaves H2 unbiased; |H1| ≤ |H2|.
//
// Windows. The force window is 1 from `force_window_pre_s` before the hit to
// `force_window_s` after it, with cosine tapers of `force_window_taper_s`
// outside that, and 0 elsewhere: it removes the force channel's noise
// between hits. The exponential window w(t) = exp(−(t − t_hit)/τ) (1 before
// the hit) is applied to force and response alike, so that the estimate is
// exactly the FRF of the impulse response h(t) e^{−t/τ}: every pole λ moves
// to λ − 1/τ. A mode's measured damping ratio is therefore too high by
// about 1/(τ ω_n) [Fladung & Rost 1997]; CorrectExponentialWindowDamping
// removes the shift exactly.
//
// - [Bendat & Piersol 2010] J. S. Bendat, A. G. Piersol, Random Data:
//   Analysis and Measurement Procedures, 4th ed., Wiley, 2010.
// - [Ewins 2000] D. J. Ewins, Modal Testing: Theory, Practice and
//   Application, 2nd ed., Research Studies Press, 2000.
// - [Fladung & Rost 1997] W. Fladung, R. Rost, Application and correction of
//   the exponential window for frequency response functions, Mechanical
//   Systems and Signal Processing 11(1), 1997, 23–36.

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/calibration/impact_record.h"
#include "robomach/calibration/modal_fit.h"
#include "robomach/common/run_status.h"

namespace robomach::calibration {

/// The shortest exponential window frf-estimate accepts, in sample periods:
/// below, the window is gone within a few samples of the hit and the FRF is
/// that of the pulse alone; its damping bias 1/(τ ω) is 0.16 x fs / f, at
/// least 0.32 (= 1/(2 pi x 0.5 x 4)) at the Nyquist frequency.
inline constexpr double kMinExponentialWindowSamples = 4.0;

struct FrfEstimateOptions {
  /// Force window: 1 on [t_hit − pre, t_hit + width], cosine tapers of
  /// `force_window_taper_s` on both sides, 0 elsewhere. t_hit is the first
  /// sample of the hit's pulse above `trigger_fraction` of its peak.
  /// 0 means automatic: width 3 × the longest accepted pulse + 32 samples,
  /// pre 16 samples, taper 8 samples. The samples are there because the
  /// acquisition's anti-aliasing filter spreads the pulse over tens of
  /// samples (a linear-phase filter also before it); cutting that ringing
  /// off biases the FRF at high frequency (seen: 1 % at 0.3 fs with a
  /// 3-pulse-width window). A negative width switches the force window off.
  double force_window_s{0.0};          // [s]
  double force_window_pre_s{0.0};      // [s]
  double force_window_taper_s{0.0};    // [s]
  /// Exponential window time constant τ [s]; 0 = no exponential window.
  /// It adds ≈ 1/(τ ω) to the damping ratio of a mode at ω: frf-estimate
  /// refuses τ under kMinExponentialWindowSamples sample periods (exit 64).
  double exponential_tau_s{0.0};
  /// Highest line written [Hz]; 0 = fs / 2.56 (the usual anti-aliasing ratio).
  /// Above the Nyquist frequency fs / 2 the lines stop at fs / 2 and the
  /// result has a warning (frf-estimate refuses such a --fmax-hz, exit 64).
  double fmax_hz{0.0};
  /// The pulse starts and ends where |force| crosses this fraction of the
  /// peak.
  double trigger_fraction{0.05};
  /// Double hit: any force sample outside the main pulse (the run of
  /// samples around the peak above `trigger_fraction`), before or after it,
  /// above this fraction of the peak.
  double double_hit_fraction{0.10};
  /// Overload: a channel clipped (DetectFlatTop with this many samples), or
  /// any sample at or beyond a given range.
  int flat_top_samples{3};
  double force_range_N{0.0};    // 0 = unknown
  /// Per response channel, in its SI unit (m, m/s, m/s²); 0 = unknown.
  /// Empty: unknown for all; else one entry per channel.
  std::vector<double> response_range;
  /// Leakage check: a (windowed) response whose rms over the last 5 % of
  /// the record is above this fraction of its peak, and above 2 × the rms
  /// of the pre-trigger samples (the noise), has not decayed.
  /// Truncating a decay that is still at a fraction ε of its start changes
  /// the FRF at its resonance by about ε.
  double leakage_fraction{0.005};

  /// force_window_s finite; force_window_pre_s, force_window_taper_s,
  /// exponential_tau_s, fmax_hz, force_range_N and each response_range
  /// finite and >= 0; trigger_fraction in (0, 1); double_hit_fraction in
  /// [trigger_fraction, 1); flat_top_samples >= 2; leakage_fraction in (0, 1).
  /// @throws OptionError naming the field, its value and the bound
  ///   ("FrfEstimateOptions::exponential_tau_s = -1: expected >= 0 [s] ...";
  ///   field() "response_range" for an entry of it).
  void Validate() const;
};

enum class HitStatus { kAccepted, kDoubleHit, kOverload };
/// "accepted", "double hit", "overload".
std::string ToString(HitStatus s);
/// The inverse of ToString. @throws std::invalid_argument naming the three.
HitStatus ParseHitStatus(const std::string& name);

struct HitReport {
  std::string id;
  std::string source;
  HitStatus status{HitStatus::kAccepted};
  double hit_time_s{NAN};      // t_hit [s] (record time)
  double peak_force_N{NAN};
  double pulse_duration_s{NAN};
  /// Why the hit was rejected, e.g. "double hit: a second force pulse at
  /// t = 0.0213 s, 42 % of the main pulse's peak (...)"; empty for
  /// accepted hits.
  std::vector<std::string> notes;
};

enum class FrfEstimateStatus {
  kOk,       // at least one accepted hit
  kNoHits,   // every hit rejected (or none given): no estimate
};

/// The estimate per response channel, in the channel's quantity (receptance,
/// mobility or accelerance per N), on the lines Δf..fmax.
struct ChannelFrf {
  Eigen::VectorXcd h1;
  Eigen::VectorXcd h2;
  Eigen::VectorXd coherence;  // γ², 1 on every line for a single hit
};

struct FrfEstimateResult {
  FrfEstimateStatus status{FrfEstimateStatus::kNoHits};
  Eigen::VectorXd freq_hz;            // lines k Δf, k = 1.. [Hz]
  std::vector<ChannelFrf> channels;   // in the order of the input channels
  Eigen::VectorXd force_autospectrum; // G_ff / n per line [N² (arbitrary DFT scale)]
  int averages{0};                    // accepted hits
  std::vector<HitReport> hits;        // one per input record, in input order
  double sample_rate_hz{0.0};
  int block_samples{0};               // N: the shortest record, cut to a 2·3·5-smooth length
  double force_window_s{0.0};         // the width used (after "automatic") [s]; < 0: off
  double force_window_pre_s{0.0};     // the lead used [s]
  double exponential_tau_s{0.0};      // [s]; 0: none
  /// Leakage, force roll-off, records of unequal length, one average:
  /// each a sentence naming the hit or the frequency.
  std::vector<std::string> warnings;
  bool leakage{false};  // a response had not decayed by the end of its window
  /// A channel's receptance (converted from its quantity) is outside
  /// [kMinPlausibleReceptance, kMaxPlausibleReceptance] on the coherent
  /// lines of its usable band (PeakReceptanceInUsableBand, frf_noise.h):
  /// almost surely a unit mistake (mm or um under an _m column, kN
  /// under force_N); a warning names the channel and the likely mistake.
  bool implausible{false};
};

/// Plausible peak receptance: dynamics::kMinPlausibleReceptance and
/// kMaxPlausibleReceptance (measured_frf.h), the one check of every tool.
using dynamics::kMaxPlausibleReceptance;
using dynamics::kMinPlausibleReceptance;

/// Estimates H1, H2 and the coherence of each response channel from the
/// hits, after rejecting double hits and overloads (eq. (1)–(3)).
/// Every record must have the same sample rate (within 1e-4: times rounded
/// to 1 µs in a CSV give rates a few 1e-6 apart) and
/// channels.size() response columns; records are cut to the shortest one,
/// and then to the largest length ≤ it with only the factors 2, 3 and 5
/// (the FFT's fast radices; a warning names the samples dropped).
/// @throws std::invalid_argument for inconsistent records (naming the hit)
///   or invalid options.
FrfEstimateResult EstimateFrf(const std::vector<ImpactRecord>& hits,
                              const std::vector<ResponseChannel>& channels,
                              const FrfEstimateOptions& options = {});

/// frf-estimate's verdict on an estimate (its exit 3; Python's
/// judge_frf_estimate): flagged, one finding each, for fewer accepted hits
/// than `min_hits` (when there is at least one), leakage, and a receptance
/// outside the plausible range (a unit mistake). `min_hits_name` is how the
/// caller calls the minimum ("--min-hits" in the tool).
RunFindings JudgeFrfEstimate(const FrfEstimateResult& result, int min_hits = 1,
                             const std::string& min_hits_name = "min_hits");

/// Clipping of a converter or amplifier, as the first sample of either
///  (a) a run of at least `min_run` consecutive samples exactly equal to the
///      signal's maximum (or minimum) where the signal, `run` samples before
///      or after the run, is more than 16 quanta away from that value (the
///      quantum: the smallest nonzero sample-to-sample step). A smooth peak
///      of a quantised signal also repeats its extreme value, but stays
///      within about 8 quanta of it over that distance (a parabola within
///      one quantum over the run is within 9 at 1.5 runs from its apex); or
///  (b) the extreme value, to the last digit, in `min_run` or more samples
///      in all (a fast signal clipped at several of its peaks for one or two
///      samples each), when it is more than 1000 quanta from the median: a
///      decaying response reaches its extreme once, and only a signal a few
///      hundred quanta tall could repeat it by rounding.
/// Returns the index of that sample, or −1.
int DetectFlatTop(const Eigen::VectorXd& x, int min_run);

/// The true damping of a mode measured through an exponential window of
/// time constant τ: the window moves the pole λ = −σ + iω_d to
/// −(σ + 1/τ) + iω_d, so with the measured natural frequency f_m and
/// damping ratio ζ_m, σ = ζ_m ω_m − 1/τ, ω_d = ω_m √(1 − ζ_m²), and the
/// corrected ω_n = √(σ² + ω_d²), ζ = σ / ω_n. To first order
/// ζ ≈ ζ_m − 1/(τ ω_n) [Fladung & Rost 1997].
/// @returns {natural frequency [Hz], damping ratio}; the ratio can come out
///   ≤ 0 when the measured damping was mostly the window's (noise).
/// @throws std::invalid_argument unless τ > 0, f_m > 0, 0 ≤ ζ_m < 1.
std::pair<double, double> CorrectExponentialWindowDamping(double freq_hz, double damping_ratio,
                                                          double tau_s);
/// Corrects the frequency, damping ratio and pole of every mode in place.
void CorrectExponentialWindowDamping(double tau_s, std::vector<FittedMode>* modes);

}  // namespace robomach::calibration
