#include "robomach/calibration/virtual_hammer_test.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <stdexcept>

#include "robomach/common/errors.h"
#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::calibration {
namespace {

double Round13(double v) {
  if (v == 0.0 || !std::isfinite(v)) return v;
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.12E", v);
  return std::strtod(buf, nullptr);
}

}  // namespace

// Each message starts with the field and its value, so that a tool can put
// its option's name in the field's place (apps' ValidateOptions).
void VirtualHammerOptions::Validate() const {
  const VirtualHammerOptions& o = *this;
  // The field is the message's first word.
  auto fail = [](const std::string& m) {
    throw OptionError(m.substr(0, m.find_first_of(" :")), "VirtualHammerOptions: " + m);
  };
  const auto num = [](double v) { return FormatNumber(v, 7); };
  if (!(o.sample_rate_hz > 0.0) || !std::isfinite(o.sample_rate_hz)) {
    fail("sample_rate_hz " + num(o.sample_rate_hz) + ": expected a rate > 0 Hz");
  }
  if (o.block_samples < 2) fail("block_samples " + std::to_string(o.block_samples) + ": expected at least 2 samples");
  if (!(o.fmin_hz > 0.0) || !std::isfinite(o.fmin_hz)) {
    fail("fmin_hz " + num(o.fmin_hz) + ": expected a frequency > 0 Hz (the 0 Hz line is not measured)");
  }
  if (!(o.fmax_hz > o.fmin_hz) || !std::isfinite(o.fmax_hz)) {
    fail("fmax_hz " + num(o.fmax_hz) + ": expected a frequency above fmin_hz " + num(o.fmin_hz) + " Hz");
  }
  if (o.fmax_hz > 0.5 * o.sample_rate_hz) {
    fail("fmax_hz " + num(o.fmax_hz) + ": above the Nyquist frequency " + num(0.5 * o.sample_rate_hz) +
         " Hz of sample_rate_hz " + num(o.sample_rate_hz));
  }
  const double df = o.sample_rate_hz / o.block_samples;
  if (std::floor(o.fmax_hz / df + 1e-9) < std::ceil(o.fmin_hz / df - 1e-9)) {
    fail("block_samples " + std::to_string(o.block_samples) + ": the line spacing sample_rate_hz / block_samples = " +
         num(df) + " Hz leaves no line between fmin_hz " + num(o.fmin_hz) + " and fmax_hz " + num(o.fmax_hz) +
         " Hz");
  }
  for (const auto& [name, v] : {std::pair{"relative_noise", o.relative_noise},
                                std::pair{"absolute_noise_m_per_N", o.absolute_noise_m_per_N},
                                std::pair{"absolute_noise_m_per_s_per_N", o.absolute_noise_m_per_s_per_N},
                                std::pair{"absolute_noise_m_per_s2_per_N", o.absolute_noise_m_per_s2_per_N}}) {
    if (!(v >= 0.0) || !std::isfinite(v)) fail(std::string(name) + " " + num(v) + ": expected a finite noise rms >= 0");
  }
  if (!(o.hammer_cutoff_hz >= 0.0) || !std::isfinite(o.hammer_cutoff_hz)) {
    fail("hammer_cutoff_hz " + num(o.hammer_cutoff_hz) + ": expected a frequency >= 0 Hz (0: a flat force spectrum)");
  }
  if (o.averages < 1) fail("averages " + std::to_string(o.averages) + ": expected at least 1");
  if (o.coherence && o.averages < 2) {
    fail("averages " + std::to_string(o.averages) + ": a coherence needs at least 2 (one impact's coherence is 1)");
  }
  if (o.directions.empty()) fail("directions: no direction pair given, expected at least one");
}

double ConfiguredSampleRateHz(const dynamics::RobotDescription& description, double fallback) {
  const auto it = description.extra_values.find("hammer_test.sample_rate_hz");
  return it != description.extra_values.end() ? it->second : fallback;
}

double SynthNoiseFloor(const VirtualHammerOptions& o, double freq_hz) {
  const double w = HzToRadPerSec(freq_hz);
  double a2 = o.absolute_noise_m_per_N * o.absolute_noise_m_per_N;
  if (o.absolute_noise_m_per_s_per_N > 0.0) a2 += std::pow(o.absolute_noise_m_per_s_per_N / w, 2);
  if (o.absolute_noise_m_per_s2_per_N > 0.0) a2 += std::pow(o.absolute_noise_m_per_s2_per_N / (w * w), 2);
  if (o.hammer_cutoff_hz > 0.0) a2 *= 1.0 + std::pow(freq_hz / o.hammer_cutoff_hz, 4);
  return std::sqrt(a2);
}

Eigen::VectorXd HammerTestGrid(const VirtualHammerOptions& o) {
  o.Validate();
  const double df = o.sample_rate_hz / o.block_samples;
  const long k0 = static_cast<long>(std::ceil(o.fmin_hz / df - 1e-9));
  const long k1 = static_cast<long>(std::floor(o.fmax_hz / df + 1e-9));
  if (k1 < k0) throw std::invalid_argument("VirtualHammerOptions: no line between fmin_hz and fmax_hz");
  const double f0 = k0 * df;
  Eigen::VectorXd f(k1 - k0 + 1);
  for (long p = 0; p < f.size(); ++p) f(p) = f0 + p * df;
  return f;
}

dynamics::FrfSet SynthesizeHammerTest(const std::shared_ptr<const dynamics::RobotModel>& model,
                                      const std::vector<NamedPosture>& postures,
                                      const VirtualHammerOptions& o) {
  const Eigen::VectorXd f = HammerTestGrid(o);
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> g(0.0, std::sqrt(0.5));
  dynamics::PostureEvaluator ev(model);
  dynamics::FrfSet out;
  for (const NamedPosture& p : postures) {
    const dynamics::PostureDynamics d = ev.Evaluate(p.q);
    const std::vector<Eigen::Matrix3cd> H = dynamics::Receptance(d, f);
    for (const auto& [r, e] : o.directions) {
      Eigen::VectorXcd h(f.size());
      Eigen::VectorXd coh(f.size());
      for (Eigen::Index i = 0; i < f.size(); ++i) {
        const std::complex<double> clean = H[i](static_cast<int>(r), static_cast<int>(e));
        const std::complex<double> n1(g(rng), g(rng)), n2(g(rng), g(rng));
        const double floor = SynthNoiseFloor(o, f(i));
        std::complex<double> v = clean * (1.0 + o.relative_noise * n1) + floor * n2;
        if (o.round_to_uff_precision) v = {Round13(v.real()), Round13(v.imag())};
        h(i) = v;
        const double a2 = std::norm(clean);
        const double s2 = o.relative_noise * o.relative_noise * a2 + floor * floor;
        coh(i) = a2 + (o.averages - 1) * s2 > 0.0 ? a2 / (a2 + (o.averages - 1) * s2) : 0.0;
        if (o.round_to_uff_precision) coh(i) = Round13(coh(i));
      }
      out.Insert({p.id, r, e}, dynamics::Frf::FromSamples(f, h, o.coherence ? std::optional(coh) : std::nullopt));
    }
  }
  return out;
}

}  // namespace robomach::calibration
