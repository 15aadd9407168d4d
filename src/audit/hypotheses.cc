// The audit's hypotheses beyond the effect library (issue #33): the model's
// own parameters freed (a joint stiffness that is off), and compliance
// anywhere along the chain (virtual joints), screened cheaply and the best
// fitted as candidates.
#include "audit/internal/hypotheses.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/QR>

#include "robomach/common/errors.h"
#include "robomach/common/parallel.h"
#include "robomach/dynamics/effect.h"

namespace robomach::audit::internal {

std::vector<std::string> DefaultParameterCandidates(const dynamics::ParameterSet& p) {
  std::vector<std::string> out;
  for (const auto& s : p.specs()) {
    if (s.name.rfind("kq", 0) == 0 && s.name.find('.') == std::string::npos) out.push_back(s.name);
  }
  return out;
}

CandidateResult FitParameterHypothesis(const dynamics::RobotDescription& desc, const dynamics::ParameterSet& start,
                                       const std::vector<std::string>& freed,
                                       const std::vector<std::string>& calibration, const FitContext& x) {
  const AuditOptions& o = x.options;
  CandidateResult c;
  c.parameters = freed;
  std::sort(c.parameters.begin(), c.parameters.end());  // kq2 before kq3 in every message
  std::vector<std::string> free = calibration;
  for (const std::string& n : freed) {
    if (!Contains(free, n)) free.push_back(n);
  }
  c.added_parameters = static_cast<int>(freed.size());
  try {
    // Start: the best-first scan of the freed parameters from the
    // calibrated model (it moves only where the whole-curve cost falls, so
    // the fit starts no worse than the calibrated model it contains).
    const dynamics::ParameterSet from = ScanStart(desc, start, freed, x.banded);
    c.start = "scan";
    c.fit = CalibrateWithRetry(desc, from, free, x);
  } catch (const NumericalError& e) {
    c.fit.status = calibration::FitStatus::kFailed;
    c.fit.message = e.what();
    c.note = std::string("fit failed: ") + e.what();
    c.bic = c.bic_change = std::numeric_limits<double>::infinity();
    c.errors.total_rms_log_mag = NAN;
    return c;
  }
  c.errors = ComputeErrors(dynamics::RobotModel::Build(desc, c.fit.parameters), x.postures, x.measured, o.fmin_hz,
                           o.fmax_hz, o.num_bands);
  c.bic = Bic(c.errors.rss, c.errors.lines, static_cast<int>(free.size()));
  c.bic_change = c.bic - x.baseline_bic;
  c.plausible = c.fit.status == calibration::FitStatus::kConverged;
  if (!c.plausible) c.note = "fit " + calibration::FitStatusName(c.fit.status) + ": " + c.fit.message;
  // A freed parameter on its bound (three decades from the configured
  // joint stiffness) has found no stiffness: the hypothesis stands in for
  // something else.
  for (const auto& e : c.fit.estimates) {
    if (!e.at_bound || !Contains(freed, e.name)) continue;
    c.plausible = false;
    c.pinned.push_back(e.name);
    std::ostringstream m;
    m.precision(3);
    m << e.name << " on its bound " << e.value;
    c.note += (c.note.empty() ? "" : "; ") + m.str();
  }
  return c;
}

std::vector<std::string> VirtualJointNames(const dynamics::RobotDescription& desc) {
  std::vector<std::string> out;
  const int n = desc.arm.num_joints();
  static const char* kAxes[] = {"rx", "ry", "rz", "tx", "ty", "tz"};
  for (int place = 0; place <= n; ++place) {
    for (const char* axis : kAxes) {
      const std::string name =
          "virtual_joint_" + (place == 0 ? std::string("base") : "link" + std::to_string(place)) + "_" + axis;
      try {
        dynamics::EffectRegistry::Instance().Create(name)->CheckApplicable(desc);
      } catch (const std::invalid_argument&) {
        continue;  // a rotation about a joint's own axis: the joint-stiffness hypothesis covers it
      }
      bool present = false;
      for (const auto& e : desc.effects) present |= e.name == name;
      if (!present) out.push_back(name);
    }
  }
  return out;
}

std::vector<ScreenedVirtualJoint> ScreenVirtualJoints(const dynamics::RobotDescription& desc,
                                                      const dynamics::ParameterSet& calibrated,
                                                      const std::vector<std::string>& calibration,
                                                      const FitContext& x, double* baseline) {
  std::vector<ScreenedVirtualJoint> out;
  *baseline = NAN;
  const Eigen::VectorXd r0 = WholeCurveResidualVector(desc, calibrated, x.banded);
  if (r0.size() == 0 || !(x.noise_floor > 0.0)) return out;
  // Sensitivity of the residuals to the calibration parameters (central
  // differences in the logarithm; additive for a parameter at zero): the
  // linearised re-adjustment every screened value gets.
  Eigen::MatrixXd J(r0.size(), static_cast<Eigen::Index>(calibration.size()));
  for (size_t j = 0; j < calibration.size(); ++j) {
    const std::string& name = calibration[j];
    const dynamics::ParameterSpec& spec = calibrated.spec(name);
    const double v = calibrated.Get(name);
    dynamics::ParameterSet lo = calibrated, hi = calibrated;
    double span;
    if (v > 0.0) {
      lo.SetClamped(name, v * std::exp(-1e-4));
      hi.SetClamped(name, v * std::exp(1e-4));
      span = std::log(hi.Get(name) / lo.Get(name));
    } else {
      hi.SetClamped(name, v + 1e-4 * std::max(std::abs(spec.default_value), 1e-12));
      span = hi.Get(name) - v;
    }
    const Eigen::VectorXd a = WholeCurveResidualVector(desc, lo, x.banded);
    const Eigen::VectorXd b = WholeCurveResidualVector(desc, hi, x.banded);
    J.col(static_cast<Eigen::Index>(j)) =
        a.size() == r0.size() && b.size() == r0.size() && span > 0.0 ? Eigen::VectorXd((b - a) / span)
                                                                     : Eigen::VectorXd::Zero(r0.size());
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(J);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(J.rows(), J.cols());
  // The cost after the best linearised step of the calibration parameters:
  // |r − Q Qᵀ r|², r the residuals with the virtual joint at one stiffness.
  const auto projected = [&](const Eigen::VectorXd& r) { return (r - Q * (Q.transpose() * r)).squaredNorm(); };
  *baseline = std::sqrt(projected(r0) / static_cast<double>(r0.size())) / x.noise_floor;
  const std::vector<std::string> names = VirtualJointNames(desc);
  out.resize(names.size());
  ParallelForOptions po;
  po.threads = x.options.threads;
  po.chunk_size = 1;
  ParallelFor(
      0, static_cast<long>(names.size()),
      [&](long i, int) {
        ScreenedVirtualJoint& s = out[static_cast<size_t>(i)];
        s.effect = names[static_cast<size_t>(i)];
        const auto [d, p] = dynamics::WithEffect(desc, calibrated, s.effect);
        const std::string param = FittableOf(s.effect).at(0);
        const dynamics::ParameterSpec& spec = p.spec(param);
        // A factor of 4 between trial stiffnesses over the whole range: a
        // virtual joint's mode moves by a factor of 2 in frequency between
        // neighbours, so one of them lands within a factor of √2 of any
        // stiffness that matters.
        double best = std::numeric_limits<double>::infinity(), best_k = NAN;
        for (double k = spec.lower; k <= spec.upper * 1.0001; k *= 4.0) {
          dynamics::ParameterSet trial = p;
          trial.SetClamped(param, k);
          const Eigen::VectorXd r = WholeCurveResidualVector(d, trial, x.banded);
          if (r.size() != r0.size()) continue;
          const double c = projected(r);
          if (c < best) best = c, best_k = k;
        }
        s.stiffness = best_k;
        // rms whole-curve residual (log magnitude and phase chord) in units
        // of the noise floor.
        s.predicted_error = std::sqrt(best / static_cast<double>(r0.size())) / x.noise_floor;
      },
      po);
  std::stable_sort(out.begin(), out.end(), [](const ScreenedVirtualJoint& a, const ScreenedVirtualJoint& b) {
    return a.predicted_error < b.predicted_error;
  });
  return out;
}

}  // namespace robomach::audit::internal
