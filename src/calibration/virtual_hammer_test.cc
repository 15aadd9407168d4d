#include "robomach/calibration/virtual_hammer_test.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <stdexcept>

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

void CheckValid(const VirtualHammerOptions& o) {
  auto fail = [](const std::string& m) { throw std::invalid_argument("VirtualHammerOptions: " + m); };
  if (!(o.sample_rate_hz > 0.0)) fail("sample_rate_hz must be > 0");
  if (o.block_samples < 2) fail("block_samples must be >= 2");
  if (!(o.fmin_hz > 0.0)) fail("fmin_hz must be > 0 (the 0 Hz line is not measured)");
  if (!(o.fmax_hz > o.fmin_hz)) fail("fmax_hz must be > fmin_hz");
  if (o.fmax_hz > 0.5 * o.sample_rate_hz) fail("fmax_hz must not exceed the Nyquist frequency sample_rate_hz/2");
  if (!(o.relative_noise >= 0.0) || !(o.absolute_noise_m_per_N >= 0.0) ||
      !(o.absolute_noise_m_per_s_per_N >= 0.0) || !(o.absolute_noise_m_per_s2_per_N >= 0.0)) {
    fail("noise levels must be >= 0");
  }
  if (!(o.hammer_cutoff_hz >= 0.0) || !std::isfinite(o.hammer_cutoff_hz)) fail("hammer_cutoff_hz must be >= 0");
  if (o.averages < 1) fail("averages must be >= 1");
  if (o.coherence && o.averages < 2) fail("a coherence needs averages >= 2 (one impact's coherence is 1)");
  if (o.directions.empty()) fail("no direction pairs");
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
  CheckValid(o);
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
