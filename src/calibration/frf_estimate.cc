#include "robomach/calibration/frf_estimate.h"

#include <algorithm>
#include <complex>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

// Eigen's FFT module (kissfft's algorithm, templated on double; MPL-2.0, in
// libeigen3-dev): see third_party_notes.md for why this one.
#include <unsupported/Eigen/FFT>

#include "robomach/calibration/frf_noise.h"
#include "robomach/common/enum_names.h"
#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"

namespace robomach::calibration {
namespace {

void Require(bool ok, const std::string& field, double value, const std::string& rule) {
  if (!ok) {
    throw OptionError(field.substr(0, field.find('[')),
                      "FrfEstimateOptions::" + field + " = " + FormatNumber(value, 6) + ": expected " + rule);
  }
}

// The hit's pulse: the contiguous run of samples around the force peak with
// |f| >= trigger_fraction · peak.
struct Pulse {
  int peak{0};
  int start{0};
  int end{0};  // last sample of the pulse
  double peak_N{0.0};
};

Pulse FindPulse(const Eigen::VectorXd& f, int n, double trigger_fraction) {
  Pulse p;
  f.head(n).cwiseAbs().maxCoeff(&p.peak);
  p.peak_N = std::abs(f(p.peak));
  const double level = trigger_fraction * p.peak_N;
  p.start = p.peak;
  while (p.start > 0 && std::abs(f(p.start - 1)) >= level) --p.start;
  p.end = p.peak;
  while (p.end + 1 < n && std::abs(f(p.end + 1)) >= level) ++p.end;
  return p;
}

// Raised-cosine edge: 0 at x <= 0, 1 at x >= 1.
double CosineRamp(double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  return 0.5 * (1.0 - std::cos(kPi * x));
}

double ForceWindow(double t_rel_s, double pre_s, double width_s, double taper_s) {
  if (width_s < 0.0) return 1.0;  // off
  const double lo = -pre_s, hi = width_s;
  if (t_rel_s >= lo && t_rel_s <= hi) return 1.0;
  if (t_rel_s < lo) return CosineRamp(1.0 - (lo - t_rel_s) / taper_s);
  return CosineRamp(1.0 - (t_rel_s - hi) / taper_s);
}

// The largest n' <= n whose only prime factors are 2, 3 and 5: kissfft's
// fast radices. A prime length would cost O(N²) (1 s for 18 transforms of
// 4099 samples, against 1 ms at 4096).
int FastFftLength(int n) {
  for (int m = n; m > 1; --m) {
    int r = m;
    for (const int p : {2, 3, 5}) {
      while (r % p == 0) r /= p;
    }
    if (r == 1) return m;
  }
  return n;
}

}  // namespace

void FrfEstimateOptions::Validate() const {
  const FrfEstimateOptions& o = *this;
  Require(std::isfinite(o.force_window_s), "force_window_s", o.force_window_s, "a finite width [s] (0 = automatic, < 0 = off)");
  Require(o.force_window_pre_s >= 0.0 && std::isfinite(o.force_window_pre_s), "force_window_pre_s",
          o.force_window_pre_s, ">= 0 [s] (0 = automatic)");
  Require(o.force_window_taper_s >= 0.0 && std::isfinite(o.force_window_taper_s), "force_window_taper_s",
          o.force_window_taper_s, ">= 0 [s] (0 = automatic)");
  Require(o.exponential_tau_s >= 0.0 && std::isfinite(o.exponential_tau_s), "exponential_tau_s",
          o.exponential_tau_s, ">= 0 [s] (0 = no exponential window)");
  Require(o.fmax_hz >= 0.0 && std::isfinite(o.fmax_hz), "fmax_hz", o.fmax_hz, ">= 0 [Hz] (0 = fs/2.56)");
  Require(o.trigger_fraction > 0.0 && o.trigger_fraction < 1.0, "trigger_fraction", o.trigger_fraction,
          "in (0, 1)");
  Require(o.double_hit_fraction >= o.trigger_fraction && o.double_hit_fraction < 1.0, "double_hit_fraction",
          o.double_hit_fraction, "in [trigger_fraction " + FormatNumber(o.trigger_fraction, 6) + ", 1)");
  Require(o.flat_top_samples >= 2, "flat_top_samples", o.flat_top_samples, ">= 2");
  Require(o.force_range_N >= 0.0 && std::isfinite(o.force_range_N), "force_range_N", o.force_range_N,
          ">= 0 [N] (0 = unknown)");
  for (size_t c = 0; c < o.response_range.size(); ++c) {
    Require(o.response_range[c] >= 0.0 && std::isfinite(o.response_range[c]),
            "response_range[" + std::to_string(c) + "]", o.response_range[c], ">= 0 (0 = unknown)");
  }
  Require(o.leakage_fraction > 0.0 && o.leakage_fraction < 1.0, "leakage_fraction", o.leakage_fraction,
          "in (0, 1)");
}

std::string ToString(HitStatus s) {
  switch (s) {
    case HitStatus::kAccepted: return "accepted";
    case HitStatus::kDoubleHit: return "double hit";
    case HitStatus::kOverload: return "overload";
  }
  return "?";
}

HitStatus ParseHitStatus(const std::string& name) {
  constexpr HitStatus kAll[] = {HitStatus::kAccepted, HitStatus::kDoubleHit, HitStatus::kOverload};
  return ParseByName("hit status", name, kAll);
}

int DetectFlatTop(const Eigen::VectorXd& x, int min_run) {
  const int n = static_cast<int>(x.size());
  if (n < min_run || min_run < 2) return -1;
  // The quantum: the smallest nonzero step between neighbouring samples.
  double quantum = std::numeric_limits<double>::infinity();
  for (int i = 1; i < n; ++i) {
    const double d = std::abs(x(i) - x(i - 1));
    if (d > 0.0) quantum = std::min(quantum, d);
  }
  if (!std::isfinite(quantum)) return -1;  // a constant signal: no pulse at all, not a clip
  std::vector<double> sorted(x.data(), x.data() + n);
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double median = sorted[n / 2];
  for (const double extreme : {x.maxCoeff(), x.minCoeff()}) {
    int count = 0, first = -1;
    for (int i = 0; i < n;) {
      if (x(i) != extreme) {
        ++i;
        continue;
      }
      int j = i;
      while (j + 1 < n && x(j + 1) == extreme) ++j;
      const int run = j - i + 1;
      count += run;
      if (first < 0) first = i;
      // A smooth peak stays within one quantum of its extreme over the run
      // and falls by at most ~8 quanta over the next `run` samples (a
      // parabola: x''(run/2)²/2 = q gives x''((3/2)run)²/2 = 9q); a clip
      // cuts off a steeper signal.
      const double drop_before = std::abs(extreme - x(std::max(0, i - run)));
      const double drop_after = std::abs(extreme - x(std::min(n - 1, j + run)));
      if (run >= min_run && std::max(drop_before, drop_after) > 16.0 * quantum) return i;
      i = j + 1;
    }
    // A fast signal clipped at a few of its peaks: the same extreme value,
    // to the last digit, in `min_run` or more samples that need not be
    // neighbours. A decaying response reaches its extreme once; only a
    // signal a few hundred quanta tall could repeat it by rounding, hence
    // the 1000 quanta.
    if (count >= min_run && std::abs(extreme - median) > 1000.0 * quantum) return first;
  }
  return -1;
}

namespace {

// The stages of EstimateFrf below, in their order: the records' layout, hit
// screening (pass 1), the force window, windowed spectra summed over the
// accepted hits (pass 2) with the leakage check, the H1/H2/coherence
// estimators, and the findings on units and excitation.

// What every hit is cut to: response channels, sample rate, samples of the
// FFT block, line spacing and the number of lines up to fmax.
struct Layout {
  int nc{0};
  double fs{0.0};
  int n{0};
  double df{0.0};
  int lines{0};
};

// Pass 1's outcome besides the hit reports: each hit's pulse, and the
// longest pulse of an accepted hit (the automatic force window's base).
struct Screening {
  std::vector<Pulse> pulses;
  double longest_pulse_s{0.0};
};

// The force window [s]: width after the pulse start (< 0 = off), the part
// before it, and the cosine taper at both ends.
struct ForceWindowSpec {
  double width{0.0};
  double pre{0.0};
  double taper{0.0};
};

// Sums (1) over the accepted hits, and what the leakage check saw per channel.
struct SpectralSums {
  Eigen::VectorXd g_ff;
  Eigen::MatrixXd g_xx;
  Eigen::MatrixXcd g_fx;
  std::vector<int> leaky_hits;
  std::vector<double> worst_tail;
  double shortest_decay_s{std::numeric_limits<double>::infinity()};
};

// Checks the records agree (sample rate, channels, length, finite samples)
// and fixes the block length and the lines, with warnings where the records
// are cut or fmax is above Nyquist.
Layout CheckRecords(const std::vector<ImpactRecord>& hits, int nc, const FrfEstimateOptions& o,
                    FrfEstimateResult* result) {
  const double fs = hits.front().sample_rate_hz;
  int n = std::numeric_limits<int>::max();
  int n_max = 0;
  for (const ImpactRecord& h : hits) {
    if (!(h.sample_rate_hz > 0.0) || std::abs(h.sample_rate_hz - fs) > 1e-4 * fs) {
      throw std::invalid_argument("hit " + h.id + " (" + h.source + "): sample rate " + FormatNumber(h.sample_rate_hz, 9) +
                                  " Hz differs from hit " + hits.front().id + "'s " + FormatNumber(fs, 9) + " Hz");
    }
    if (h.response.cols() != nc || h.response.rows() != h.force_N.size()) {
      throw std::invalid_argument("hit " + h.id + " (" + h.source + "): expected " + std::to_string(nc) +
                                  " response channels with " + std::to_string(h.force_N.size()) +
                                  " samples, got " + std::to_string(h.response.cols()) + " with " +
                                  std::to_string(h.response.rows()));
    }
    if (h.force_N.size() < 16) {
      throw std::invalid_argument("hit " + h.id + " (" + h.source + "): " + std::to_string(h.force_N.size()) +
                                  " samples; at least 16 are needed");
    }
    if (!h.force_N.allFinite() || !h.response.allFinite()) {
      throw std::invalid_argument("hit " + h.id + " (" + h.source + "): non-finite sample");
    }
    n = std::min(n, static_cast<int>(h.force_N.size()));
    n_max = std::max(n_max, static_cast<int>(h.force_N.size()));
  }
  if (n != n_max) {
    result->warnings.push_back("records have " + std::to_string(n) + " to " + std::to_string(n_max) +
                               " samples; all are cut to the shortest (" + std::to_string(n) + ")");
  }
  if (const int fast = FastFftLength(n); fast != n) {
    // The end of a record holds the least (a decayed response), and the
    // leakage check below still looks at the new end.
    result->warnings.push_back("the last " + std::to_string(n - fast) + " of " + std::to_string(n) +
                               " samples are dropped for the FFT (" + std::to_string(fast) +
                               " has only the factors 2, 3, 5)");
    n = fast;
  }
  result->sample_rate_hz = fs;
  result->block_samples = n;
  const double df = fs / n;
  const double fmax = o.fmax_hz > 0.0 ? o.fmax_hz : fs / 2.56;
  // The line count in double before it becomes an int: fmax / df of 1e12 Hz
  // would overflow one (seen: "fmax_hz 1e+12 is below the line spacing").
  const double lines_wanted = std::floor(fmax / df + 1e-9);
  const int lines = lines_wanted >= n / 2 ? n / 2 : static_cast<int>(lines_wanted);
  if (fmax > 0.5 * fs * (1.0 + 1e-12)) {
    result->warnings.push_back("fmax_hz " + FormatNumber(fmax, 6) + " is above the Nyquist frequency " +
                               FormatNumber(0.5 * fs, 6) + " Hz of the records (sample rate " + FormatNumber(fs, 6) +
                               " Hz): the lines stop there");
  }
  if (lines < 1) throw std::invalid_argument("EstimateFrf: fmax_hz " + FormatNumber(fmax) + " is below the line spacing " + FormatNumber(df) + " Hz");
  return Layout{nc, fs, n, df, lines};
}

// Pass 1 for one hit: its pulse (into *pulse), double hits and overloads.
HitReport ScreenHit(const ImpactRecord& rec, const std::vector<ResponseChannel>& channels,
                    const FrfEstimateOptions& o, const Layout& lay, Pulse* pulse) {
  const int n = lay.n;
  const double fs = lay.fs;
  HitReport rep;
  rep.id = rec.id;
  rep.source = rec.source;
  const Eigen::VectorXd f = rec.force_N.head(n);
  if (f.cwiseAbs().maxCoeff() == 0.0) {
    throw std::invalid_argument("hit " + rec.id + " (" + rec.source + "): the force is zero throughout");
  }
  const Pulse p = FindPulse(f, n, o.trigger_fraction);
  *pulse = p;
  rep.peak_force_N = f(p.peak);
  rep.hit_time_s = rec.start_time_s + p.start / fs;
  rep.pulse_duration_s = (p.end - p.start + 1) / fs;
  const auto time_of = [&](int i) { return FormatNumber(rec.start_time_s + i / fs, 5); };
  // Double hit: a second pulse before or after the main one.
  const double dbl = o.double_hit_fraction * p.peak_N;
  int second = -1;
  for (int i = 0; i < n; ++i) {
    if (i >= p.start && i <= p.end) continue;
    if (std::abs(f(i)) > dbl) {
      second = i;
      break;
    }
  }
  if (second >= 0) {
    // Report the second pulse's own peak.
    int j = second, best = second;
    while (j < n && (j < p.start || j > p.end) && std::abs(f(j)) > o.trigger_fraction * p.peak_N) {
      if (std::abs(f(j)) > std::abs(f(best))) best = j;
      ++j;
    }
    rep.status = HitStatus::kDoubleHit;
    rep.notes.push_back(std::string("double hit: ") + (best > p.end ? "a second" : "an earlier") +
                        " force pulse at t = " + time_of(best) + " s, " +
                        FormatNumber(100.0 * std::abs(f(best)) / p.peak_N, 3) + " % of the main pulse's peak (at t = " +
                        time_of(p.peak) + " s)");
  }
  // Overload: flat tops or samples at a given range.
  const auto check_channel = [&](const Eigen::VectorXd& x, const std::string& name, double range,
                                 const std::string& unit) {
    const int flat = DetectFlatTop(x, o.flat_top_samples);
    if (flat >= 0) {
      rep.status = rep.status == HitStatus::kAccepted ? HitStatus::kOverload : rep.status;
      rep.notes.push_back("overload: " + name + " is clipped (flat top at " + FormatNumber(x(flat), 5) + " " + unit +
                          " from t = " + time_of(flat) + " s)");
      return;
    }
    if (range > 0.0) {
      Eigen::Index i;
      const double m = x.cwiseAbs().maxCoeff(&i);
      if (m >= range) {
        rep.status = rep.status == HitStatus::kAccepted ? HitStatus::kOverload : rep.status;
        rep.notes.push_back("overload: " + name + " reaches " + FormatNumber(x(i), 5) + " " + unit + " at t = " +
                            time_of(static_cast<int>(i)) + " s, at or beyond the range " + FormatNumber(range, 5) +
                            " " + unit);
      }
    }
  };
  check_channel(f, "force", o.force_range_N, "N");
  for (int c = 0; c < lay.nc; ++c) {
    static const char* kUnits[] = {"m", "m/s", "m/s^2"};
    check_channel(rec.response.col(c).head(n), "response " + channels[c].name,
                  o.response_range.empty() ? 0.0 : o.response_range[c],
                  kUnits[static_cast<int>(channels[c].quantity)]);
  }
  return rep;
}

// Pass 1: pulses, double hits and overloads, a report per hit.
Screening ScreenHits(const std::vector<ImpactRecord>& hits, const std::vector<ResponseChannel>& channels,
                     const FrfEstimateOptions& o, const Layout& lay, FrfEstimateResult* result) {
  Screening s;
  s.pulses.resize(hits.size());
  for (size_t h = 0; h < hits.size(); ++h) {
    const HitReport rep = ScreenHit(hits[h], channels, o, lay, &s.pulses[h]);
    if (rep.status == HitStatus::kAccepted) s.longest_pulse_s = std::max(s.longest_pulse_s, rep.pulse_duration_s);
    result->hits.push_back(rep);
  }
  return s;
}

// The force window, the automatic parts from the longest accepted pulse and
// the sample interval.
ForceWindowSpec ChooseForceWindow(const FrfEstimateOptions& o, double longest_pulse_s, double fs,
                                  FrfEstimateResult* result) {
  ForceWindowSpec w;
  w.width = o.force_window_s != 0.0 ? o.force_window_s : 3.0 * longest_pulse_s + 32.0 / fs;
  w.pre = o.force_window_pre_s > 0.0 ? o.force_window_pre_s : 16.0 / fs;
  w.taper = o.force_window_taper_s > 0.0 ? o.force_window_taper_s : 8.0 / fs;
  result->force_window_s = w.width;
  result->force_window_pre_s = w.width < 0.0 ? 0.0 : w.pre;
  return w;
}

// Pass 2: windows, spectra, sums (1) over the accepted hits (counted in
// result->averages), and the leakage check of each windowed response.
SpectralSums AccumulateSpectra(const std::vector<ImpactRecord>& hits, const std::vector<Pulse>& pulses,
                               const FrfEstimateOptions& o, const Layout& lay, const ForceWindowSpec& win,
                               FrfEstimateResult* result) {
  const int n = lay.n, nc = lay.nc, lines = lay.lines;
  const double fs = lay.fs;
  const double pre = win.pre, width = win.width, taper = win.taper;
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  SpectralSums s;
  s.g_ff = Eigen::VectorXd::Zero(lines);
  s.g_xx = Eigen::MatrixXd::Zero(lines, nc);
  s.g_fx = Eigen::MatrixXcd::Zero(lines, nc);
  std::vector<double> buf(n);
  std::vector<std::complex<double>> spec_f, spec_x;
  const int tail = std::max(1, n / 20);
  s.leaky_hits.assign(nc, 0);
  s.worst_tail.assign(nc, 0.0);
  for (size_t h = 0; h < hits.size(); ++h) {
    if (result->hits[h].status != HitStatus::kAccepted) continue;
    const ImpactRecord& rec = hits[h];
    const Pulse& p = pulses[h];
    s.shortest_decay_s = std::min(s.shortest_decay_s, (n - p.start) / fs);
    // Offsets: the mean of the samples before the force window (pre-trigger),
    // if there are at least 8 of them.
    const int pre_end = std::max(0, p.start - static_cast<int>(std::ceil((pre + taper) * fs)));
    const auto offset = [&](const Eigen::VectorXd& x) { return pre_end >= 8 ? x.head(pre_end).mean() : 0.0; };
    Eigen::VectorXd w_exp = Eigen::VectorXd::Ones(n);
    if (o.exponential_tau_s > 0.0) {
      for (int i = p.start; i < n; ++i) w_exp(i) = std::exp(-(i - p.start) / fs / o.exponential_tau_s);
    }
    const Eigen::VectorXd f = rec.force_N.head(n);
    const double f0 = offset(f);
    for (int i = 0; i < n; ++i) buf[i] = (f(i) - f0) * ForceWindow((i - p.start) / fs, pre, width, taper) * w_exp(i);
    fft.fwd(spec_f, buf);
    for (int k = 0; k < lines; ++k) s.g_ff(k) += std::norm(spec_f[k + 1]);
    for (int c = 0; c < nc; ++c) {
      const Eigen::VectorXd x = rec.response.col(c).head(n);
      const double x0 = offset(x);
      for (int i = 0; i < n; ++i) buf[i] = (x(i) - x0) * w_exp(i);
      // Leakage: has the windowed response died out by the end of the record?
      double peak = 0.0, tail_ms = 0.0, pre_ms = 0.0;
      for (int i = 0; i < n; ++i) peak = std::max(peak, std::abs(buf[i]));
      for (int i = n - tail; i < n; ++i) tail_ms += buf[i] * buf[i];
      tail_ms /= tail;
      for (int i = 0; i < pre_end; ++i) pre_ms += buf[i] * buf[i];
      if (pre_end > 0) pre_ms /= pre_end;
      const double tail_rms = std::sqrt(tail_ms);
      const bool above_noise = pre_end >= 8 ? tail_rms > 2.0 * std::sqrt(pre_ms) : true;
      if (tail_rms > o.leakage_fraction * peak && above_noise) {
        ++s.leaky_hits[c];
        s.worst_tail[c] = std::max(s.worst_tail[c], tail_rms / peak);
      }
      fft.fwd(spec_x, buf);
      for (int k = 0; k < lines; ++k) {
        const std::complex<double> F = spec_f[k + 1], X = spec_x[k + 1];
        s.g_xx(k, c) += std::norm(X);
        s.g_fx(k, c) += std::conj(F) * X;
      }
    }
    ++result->averages;
  }
  return s;
}

// One warning per channel whose response had not decayed by the end of the
// record in some accepted hit, with the exponential window that would help.
void WarnLeakage(const SpectralSums& s, const std::vector<ResponseChannel>& channels, const FrfEstimateOptions& o,
                 FrfEstimateResult* result) {
  for (size_t c = 0; c < channels.size(); ++c) {
    if (s.leaky_hits[c] == 0) continue;
    result->leakage = true;
    result->warnings.push_back("response " + channels[c].name + ": has not decayed by the end of the record in " +
                               std::to_string(s.leaky_hits[c]) + " of " + std::to_string(result->averages) +
                               " accepted hits (rms of the last 5 % up to " + FormatNumber(100.0 * s.worst_tail[c], 3) +
                               " % of the peak): leakage widens the peaks and overstates the damping; use longer "
                               "records or an exponential window (tau = " + FormatNumber(s.shortest_decay_s / 6.0, 3) +
                               " s, a sixth of the shortest time from a hit to its record's end, leaves e^-6 = "
                               "0.25 %" + (o.exponential_tau_s > 0.0 ? "; the window now has tau = " +
                                           FormatNumber(o.exponential_tau_s, 3) + " s" : std::string()) + ")");
  }
}

// The estimators from the averaged sums: H1, H2 and the coherence per
// channel, and the warning when too few hits make the coherence mean little.
void EstimateChannels(const SpectralSums& s, const Layout& lay, FrfEstimateResult* result) {
  const int lines = lay.lines;
  result->force_autospectrum = s.g_ff / result->averages;
  for (int c = 0; c < lay.nc; ++c) {
    ChannelFrf ch;
    ch.h1.resize(lines);
    ch.h2.resize(lines);
    ch.coherence.resize(lines);
    for (int k = 0; k < lines; ++k) {
      const std::complex<double> gfx = s.g_fx(k, c);
      ch.h1(k) = s.g_ff(k) > 0.0 ? gfx / s.g_ff(k) : std::complex<double>(0.0);
      ch.h2(k) = std::abs(gfx) > 0.0 ? s.g_xx(k, c) / std::conj(gfx) : std::complex<double>(0.0);
      const double den = s.g_ff(k) * s.g_xx(k, c);
      // Cauchy-Schwarz makes |G_fx|² <= G_ff G_xx; clamp the rounding.
      ch.coherence(k) = den > 0.0 ? std::min(1.0, std::norm(gfx) / den) : 0.0;
    }
    result->channels.push_back(std::move(ch));
  }
  if (result->averages == 1) {
    result->warnings.push_back("one accepted hit: the coherence is 1 on every line by construction and says nothing");
  } else if (result->averages == 2) {
    result->warnings.push_back(
        "only 2 hits averaged: the coherence needs at least 3 to mean much, 5 or more are usual");
  }
}

// Unit plausibility: the largest receptance on the coherent lines of the
// band the noise model finds usable (issue #34 item 5: on a single hit the
// 1/ω² of an accelerometer's slow drift made the lowest lines 1e-3 m/N).
void CheckReceptanceUnits(const std::vector<ResponseChannel>& channels, int lines, FrfEstimateResult* result) {
  for (size_t c = 0; c < channels.size(); ++c) {
    const int p = static_cast<int>(channels[c].quantity);  // 0 displacement, 1 velocity, 2 acceleration
    Eigen::VectorXcd receptance(lines);
    for (int k = 0; k < lines; ++k) {
      const double w = 2.0 * M_PI * result->freq_hz(k);
      receptance(k) = result->channels[c].h1(k) / std::pow(w, p);
    }
    const UsableBandPeak peak = PeakReceptanceInUsableBand(
        dynamics::Frf::FromSamples(result->freq_hz, receptance, result->channels[c].coherence), result->averages);
    const std::string finding = UsableBandUnitFinding("response " + channels[c].name, peak);
    if (!finding.empty()) {
      result->implausible = true;
      result->warnings.push_back(finding);
    }
  }
}

// Roll-off of the force spectrum: 20 dB below its level at the lowest lines.
void CheckForceRollOff(int lines, FrfEstimateResult* result) {
  const int ref_lines = std::max(1, std::min(lines, 5));
  const double ref = result->force_autospectrum.head(ref_lines).mean();
  for (int k = 0; k < lines; ++k) {
    if (result->force_autospectrum(k) < 0.01 * ref) {
      result->warnings.push_back("the force spectrum is 20 dB below its low-frequency level from " +
                                 FormatNumber(result->freq_hz(k), 5) +
                                 " Hz up: the FRF there rests on little excitation (a harder hammer tip "
                                 "excites higher)");
      break;
    }
  }
}

}  // namespace

FrfEstimateResult EstimateFrf(const std::vector<ImpactRecord>& hits, const std::vector<ResponseChannel>& channels,
                              const FrfEstimateOptions& o) {
  o.Validate();
  FrfEstimateResult result;
  result.exponential_tau_s = o.exponential_tau_s;
  const int nc = static_cast<int>(channels.size());
  if (nc == 0) throw std::invalid_argument("EstimateFrf: no response channel");
  if (!o.response_range.empty() && static_cast<int>(o.response_range.size()) != nc) {
    throw std::invalid_argument("FrfEstimateOptions::response_range has " + std::to_string(o.response_range.size()) +
                                " entries; expected none or one per channel (" + std::to_string(nc) + ")");
  }
  if (hits.empty()) return result;
  const Layout lay = CheckRecords(hits, nc, o, &result);
  const Screening screening = ScreenHits(hits, channels, o, lay, &result);
  const ForceWindowSpec win = ChooseForceWindow(o, screening.longest_pulse_s, lay.fs, &result);
  const SpectralSums sums = AccumulateSpectra(hits, screening.pulses, o, lay, win, &result);
  WarnLeakage(sums, channels, o, &result);
  result.freq_hz = Eigen::VectorXd::LinSpaced(lay.lines, lay.df, lay.lines * lay.df);
  if (result.averages == 0) {
    result.status = FrfEstimateStatus::kNoHits;
    return result;
  }
  result.status = FrfEstimateStatus::kOk;
  EstimateChannels(sums, lay, &result);
  CheckReceptanceUnits(channels, lay.lines, &result);
  CheckForceRollOff(lay.lines, &result);
  return result;
}

std::pair<double, double> CorrectExponentialWindowDamping(double freq_hz, double damping_ratio, double tau_s) {
  if (!(tau_s > 0.0) || !(freq_hz > 0.0) || !(damping_ratio >= 0.0 && damping_ratio < 1.0)) {
    throw std::invalid_argument("CorrectExponentialWindowDamping: expected tau_s > 0, freq_hz > 0 and 0 <= "
                                "damping_ratio < 1, got " + FormatNumber(tau_s) + ", " + FormatNumber(freq_hz) + ", " +
                                FormatNumber(damping_ratio));
  }
  const double wm = HzToRadPerSec(freq_hz);
  const double sigma = damping_ratio * wm - 1.0 / tau_s;
  const double wd = wm * std::sqrt(1.0 - damping_ratio * damping_ratio);
  const double wn = std::hypot(sigma, wd);
  return {RadPerSecToHz(wn), sigma / wn};
}

void CorrectExponentialWindowDamping(double tau_s, std::vector<FittedMode>* modes) {
  if (!(tau_s > 0.0)) throw std::invalid_argument("CorrectExponentialWindowDamping: tau_s must be > 0");
  for (FittedMode& m : *modes) {
    // The window multiplies h(t) = Σ R e^{λt} by e^{−t/τ}: poles move by
    // −1/τ, residues stay. Undo the move.
    m.pole += 1.0 / tau_s;
    const double wn = std::abs(m.pole);
    m.freq_hz = RadPerSecToHz(wn);
    m.damping_ratio = -m.pole.real() / wn;
    m.peak_contribution = m.damping_ratio > 0.0 ? std::abs(m.modal_constant) / (2.0 * m.damping_ratio * wn * wn)
                                                : std::numeric_limits<double>::infinity();
  }
}

RunFindings JudgeFrfEstimate(const FrfEstimateResult& r, int min_hits, const std::string& min_hits_name) {
  RunFindings v;
  if (r.averages < min_hits && r.averages > 0) {
    v.Flag(std::to_string(r.averages) + " accepted hit(s), fewer than " + min_hits_name + " " + std::to_string(min_hits));
  }
  if (r.leakage) v.Flag("leakage (a response has not decayed by the end of its record)");
  if (r.implausible) v.Flag("a receptance outside the plausible range: a unit mistake (see the warning)");
  return v;
}

}  // namespace robomach::calibration
