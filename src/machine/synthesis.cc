#include "robomach/machine/synthesis.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "robomach/common/option_validate.h"

namespace robomach::machine {
namespace {

Eigen::VectorXd InitialGuess(const Machine& machine, const SynthesisOptions& o) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(machine.kinematic_axis.size()));
  if (!o.initial_guess.empty()) {
    if (o.initial_guess.size() != machine.kinematic_axis.size()) {
      throw std::invalid_argument("SynthesisOptions::initial_guess: expected one value per kinematic axis");
    }
    for (Eigen::Index j = 0; j < q.size(); ++j) q(j) = o.initial_guess[j];
  }
  return q;
}

// Real axis positions of one pose, then measured ones.
bool MeasuredAt(const Machine& machine, const Compensation* comp, const ToolPose& pose, double t,
                Eigen::VectorXd* q_prev, std::vector<double>* real, std::vector<double>* measured,
                std::string* why) {
  const InverseResult r = machine.kinematics->Inverse(pose, *q_prev);
  if (r.status != InverseStatus::kOk) {
    *why = r.message;
    return false;
  }
  *q_prev = r.q;
  for (Eigen::Index j = 0; j < r.q.size(); ++j) (*real)[machine.kinematic_axis[j]] = r.q(j);
  if (comp != nullptr) {
    comp->RealToMeasured(t, real->data(), measured->data());
  } else {
    *measured = *real;
  }
  return true;
}

}  // namespace

std::vector<double> StartMeasured(const Machine& machine, const Compensation* compensation,
                                  const ProgrammedPath& path, const SynthesisOptions& options) {
  const size_t n = machine.axes.size();
  std::vector<double> real(n), measured(n);
  for (size_t a = 0; a < n; ++a) real[a] = machine.axes[a].origin;
  Eigen::VectorXd q = InitialGuess(machine, options);
  std::string why;
  if (!MeasuredAt(machine, compensation, path.At(0.0), 0.0, &q, &real, &measured, &why)) {
    throw std::invalid_argument("programmed path, point 1: " + why);
  }
  return measured;
}

void SynthesisOptions::Validate() const {
  CheckOptionFinite("feed", feed);
  CheckOptionAbove("feed", feed, 0.0);
  CheckOptionFinite("sample_rate_hz", sample_rate_hz);
  CheckOptionAbove("sample_rate_hz", sample_rate_hz, 0.0);
  CheckOptionFinite("dwell", dwell);
  CheckOptionAtLeast("dwell", dwell, 0.0);
}

long SynthesisRows(const ProgrammedPath& path, const SynthesisOptions& o) {
  o.Validate();
  const double duration = o.dwell + path.length() / o.feed;
  const double rows = std::ceil(duration * o.sample_rate_hz) + 1.0;
  // Beyond a long's range the cast is undefined: saturate (callers refuse it).
  return rows < 9e18 ? static_cast<long>(rows) : std::numeric_limits<long>::max();
}

SynthesisResult SynthesizeCounts(const Machine& machine, const Compensation* compensation,
                                 const ProgrammedPath& path, const SynthesisOptions& o,
                                 const std::vector<double>& origin) {
  o.Validate();
  const size_t n = machine.axes.size();
  if (origin.size() != n) throw std::invalid_argument("SynthesizeCounts: one origin per axis expected");
  SynthesisResult res;
  res.record.num_axes = static_cast<int>(n);
  const long rows = SynthesisRows(path, o);
  res.record.t_s.reserve(rows);
  res.record.counts.reserve(rows * n);
  std::vector<double> real(n), measured(n);
  for (size_t a = 0; a < n; ++a) real[a] = origin[a];
  Eigen::VectorXd q = InitialGuess(machine, o);
  std::string why;
  for (long k = 0; k < rows; ++k) {
    const double t = static_cast<double>(k) / o.sample_rate_hz;
    const double s = std::max(0.0, t - o.dwell) * o.feed;
    if (!MeasuredAt(machine, compensation, path.At(s), t, &q, &real, &measured, &why)) {
      res.ok = false;
      res.message = "at t = " + std::to_string(t) + " s (path length " + std::to_string(s * 1e3) + " mm): " + why;
      return res;
    }
    if (k == 0) res.start_measured = measured;
    res.record.t_s.push_back(t);
    for (size_t a = 0; a < n; ++a) {
      res.record.counts.push_back(std::llround((measured[a] - origin[a]) / machine.axes[a].resolution));
    }
  }
  return res;
}

CaptureSynthesizer::CaptureSynthesizer(int num_axes, int every, int settle, double glitch_probability,
                                       unsigned seed, std::vector<std::string> axis_names)
    : num_axes_(num_axes), every_(every), settle_(settle), glitch_probability_(glitch_probability), rng_(seed) {
  names_ = std::move(axis_names);
  for (int k = static_cast<int>(names_.size()); k < num_axes; ++k) names_.push_back(std::to_string(k + 1));
  if (num_axes < 1 || num_axes > 8) throw std::invalid_argument("capture: 1..8 axes");
  if (every < 1 || settle < 0 || settle >= every) {
    throw std::invalid_argument("capture: expected every >= 1 and 0 <= settle < every");
  }
  if (!(glitch_probability >= 0.0 && glitch_probability <= 1.0)) {
    throw std::invalid_argument("capture: glitch probability must be in [0, 1]");
  }
  // A random start phase per axis: the count is relative to the first sample,
  // the quadrature phase there is whatever the scale happened to show.
  for (int k = 0; k < num_axes; ++k) phase0_.push_back(static_cast<int>(rng_() % 4));
  current_.assign(num_axes, 0);
}

std::uint16_t CaptureSynthesizer::Word(const std::int64_t* c) const {
  static constexpr int kA[4] = {0, 1, 1, 0}, kB[4] = {0, 0, 1, 1};  // formats.md §8.2
  std::uint16_t w = 0;
  for (int k = 0; k < num_axes_; ++k) {
    const int p = static_cast<int>(((c[k] + phase0_[k]) % 4 + 4) % 4);
    w |= static_cast<std::uint16_t>((kA[p] << (2 * k)) | (kB[p] << (2 * k + 1)));
  }
  return w;
}

void CaptureSynthesizer::Start(const std::int64_t* counts, std::vector<std::uint16_t>* out) {
  current_.assign(counts, counts + num_axes_);
  out->push_back(Word(current_.data()));
  rows_ = 1;
}

void CaptureSynthesizer::Next(const std::int64_t* counts, std::vector<std::uint16_t>* out) {
  const int span = every_ - settle_;
  for (int k = 0; k < num_axes_; ++k) {
    const std::int64_t d = counts[k] - current_[k];
    if (std::abs(d) > span) {
      throw std::invalid_argument("capture: axis " + names_[k] + " moves " + std::to_string(d) +
                                  " counts between rows " + std::to_string(rows_) + " and " +
                                  std::to_string(rows_ + 1) + ", more than the " + std::to_string(span) +
                                  " capture samples between them (every - settle) allow");
    }
  }
  const size_t first = out->size();
  std::vector<std::int64_t> c(num_axes_);
  for (int j = 1; j <= every_; ++j) {
    const int jj = std::min(j, span);
    for (int k = 0; k < num_axes_; ++k) {
      const std::int64_t d = counts[k] - current_[k];
      c[k] = current_[k] + std::llround(static_cast<double>(d) * jj / span);  // steps of at most 1
    }
    out->push_back(Word(c.data()));
  }
  if (glitch_probability_ > 0.0) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    // Samples 1 .. every - 1 of the interval (never the row's own sample).
    for (int j = 1; j + 1 <= every_ - 1; ++j) {
      if (u(rng_) >= glitch_probability_) continue;
      const int bit = static_cast<int>(rng_() % (2 * num_axes_));
      const std::uint32_t axis_bits = 3u << (2 * (bit / 2));
      const std::uint16_t prev = j == 1 ? Word(current_.data()) : (*out)[first + j - 2];
      const std::uint16_t here = (*out)[first + j - 1], next = (*out)[first + j];
      if (((prev ^ here) | (here ^ next)) & axis_bits) continue;  // axis not idle there
      (*out)[first + j - 1] = static_cast<std::uint16_t>(here ^ (1u << bit));
      ++glitches_;
    }
  }
  current_.assign(counts, counts + num_axes_);
  ++rows_;
}

}  // namespace robomach::machine
