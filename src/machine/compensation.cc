#include "robomach/machine/compensation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "robomach/common/errors.h"

namespace robomach::machine {
namespace {

void CheckTable(const CompensationTable& t, const std::string& what) {
  if (t.values.empty()) throw std::invalid_argument(what + ": the table has no points");
  if (!(t.step > 0.0) || !std::isfinite(t.step) || !std::isfinite(t.min)) {
    throw std::invalid_argument(what + ": expected a finite min and a step > 0");
  }
  for (double v : t.values) {
    if (!std::isfinite(v)) throw std::invalid_argument(what + ": non-finite table value");
  }
}

void CheckAxis(int axis, int n, const std::string& what) {
  if (axis < 0 || axis >= n) {
    throw std::invalid_argument(what + ": axis index " + std::to_string(axis) + " outside [0, " +
                                std::to_string(n) + ")");
  }
}

}  // namespace

double CompensationTable::Evaluate(double position) const {
  const double u = (position - min) / step;
  const int n = static_cast<int>(values.size());
  if (!(u > 0.0)) return values.front();         // below MIN (and NaN): first value holds
  if (u >= n - 1) return values.back();          // above MAX: last value holds
  const int i = static_cast<int>(u);             // P_{i} <= position < P_{i+1}
  const double f = u - i;
  return values[i] + f * (values[i + 1] - values[i]);
}

Compensation::Compensation(int num_axes, std::vector<EncoderCompensation> encoder,
                           std::vector<CrossAxisCompensation> cross_axis,
                           std::vector<TemperatureCompensation> temperature)
    : num_axes_(num_axes),
      encoder_(std::move(encoder)),
      cross_(std::move(cross_axis)),
      temperature_(std::move(temperature)) {
  for (const auto& e : encoder_) {
    CheckAxis(e.axis, num_axes_, "encoder compensation");
    CheckTable(e.table, "encoder compensation");
  }
  for (const auto& c : cross_) {
    CheckAxis(c.input_axis, num_axes_, "cross-axis compensation input");
    CheckAxis(c.output_axis, num_axes_, "cross-axis compensation output");
    CheckTable(c.table, "cross-axis compensation");
  }
  for (const auto& t : temperature_) {
    CheckAxis(t.axis, num_axes_, "temperature compensation");
    for (size_t i = 0; i < t.rows.size(); ++i) {
      const auto& r = t.rows[i];
      if (!std::isfinite(r.t_s) || !std::isfinite(r.k0) || !std::isfinite(r.tan_beta) || !std::isfinite(r.p0)) {
        throw std::invalid_argument("temperature compensation: non-finite value");
      }
      if (i > 0 && !(r.t_s > t.rows[i - 1].t_s)) {
        throw std::invalid_argument("temperature compensation: times must increase strictly");
      }
    }
  }
}

void Compensation::Offsets(double t_s, const double* measured, double* offset) const {
  for (int a = 0; a < num_axes_; ++a) offset[a] = 0.0;
  for (const auto& e : encoder_) offset[e.axis] += e.table.Evaluate(measured[e.axis]);
  for (const auto& c : cross_) offset[c.output_axis] += c.table.Evaluate(measured[c.input_axis]);
  for (const auto& t : temperature_) {
    // The row in force: the last with t_s <= t (none before the first row).
    const auto it = std::upper_bound(t.rows.begin(), t.rows.end(), t_s,
                                     [](double t, const TemperatureRow& r) { return t < r.t_s; });
    if (it == t.rows.begin()) continue;
    const TemperatureRow& r = *(it - 1);
    offset[t.axis] += r.k0 + r.tan_beta * (measured[t.axis] - r.p0);
  }
}

void Compensation::MeasuredToReal(double t_s, const double* measured, double* real) const {
  Offsets(t_s, measured, real);
  for (int a = 0; a < num_axes_; ++a) real[a] += measured[a];
}

void Compensation::RealToMeasured(double t_s, const double* real, double* measured) const {
  std::vector<double> off(num_axes_), next(num_axes_);
  for (int a = 0; a < num_axes_; ++a) measured[a] = real[a];
  // measured = real - offset(measured): a contraction when every table slope
  // and tan(beta) is well below 1 (micrometres per hundreds of millimetres).
  for (int iter = 0; iter < 100; ++iter) {
    Offsets(t_s, measured, off.data());
    bool same = true;
    for (int a = 0; a < num_axes_; ++a) {
      next[a] = real[a] - off[a];
      if (next[a] != measured[a]) same = false;
      measured[a] = next[a];
    }
    if (same) return;
    // A two-cycle of the last ulp is as good as exact.
    if (iter > 20) {
      double worst = 0.0;
      Offsets(t_s, measured, off.data());
      for (int a = 0; a < num_axes_; ++a) {
        worst = std::max(worst, std::abs(measured[a] + off[a] - real[a]) / std::max(1.0, std::abs(real[a])));
      }
      if (worst < 1e-15) return;
    }
  }
  throw NumericalError("compensation: real-to-measured inversion did not converge (table slopes near 1?)");
}

}  // namespace robomach::machine
