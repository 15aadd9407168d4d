#include "robomach/stability/measured_tip_model.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "robomach/calibration/global_modal_fit.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"

namespace robomach::stability {

void DirectFrfFitOptions::Validate() const {
  ValidateNested("noise", noise);
  ValidateNested("fit", fit);
  CheckOptionRange("max_active_fraction", max_active_fraction, 0.0, 1.0);
  CheckOptionFinite("max_noise_rms", max_noise_rms);
  CheckOptionAtLeast("max_noise_rms", max_noise_rms, 1.0);
}

DirectFrfFit FitDirectFrf(const dynamics::Frf& measured, const DirectFrfFitOptions& o) {
  o.Validate();
  DirectFrfFit out{measured, calibration::EstimateFrfNoise(measured, o.noise), {}, NAN, true, "", 0.0, false, {}};
  std::vector<int> lines;
  for (int i = 0; i < measured.size(); ++i) {
    if (out.noise.usable[i]) lines.push_back(i);
  }
  if (lines.empty()) {
    out.fit.message = "no usable line";
    out.problem = "no line reaches a signal-to-noise ratio of " + std::to_string(o.noise.min_snr);
    return out;
  }
  const dynamics::Frf usable = measured.WithNoise(out.noise.sigma_m_per_N).Select(lines);
  int active = 0, positive_f = 0;
  for (int k = 0; k < usable.size(); ++k) {
    if (!(usable.freq_hz()(k) > 0.0)) continue;
    ++positive_f;
    // σ is the complex noise's rms; each part has σ/√2.
    active += usable.receptance()(k).imag() > 2.0 * (*usable.noise_sigma())(k) / std::sqrt(2.0);
  }
  out.active_fraction = positive_f > 0 ? static_cast<double>(active) / positive_f : 0.0;
  out.not_driving_point = out.active_fraction > o.max_active_fraction;
  out.fit = calibration::FitOneFrf(usable, o.fit);
  if (out.fit.status != SolverStatus::kConverged || out.fit.modes.empty()) {
    out.problem = "modal fit: " + out.fit.message;
    return out;
  }
  const double f_lo = usable.freq_hz()(0), f_hi = usable.freq_hz()(usable.size() - 1);
  for (const calibration::FittedMode& m : out.fit.modes) {
    if (m.freq_hz * (1.0 - m.damping_ratio) < f_lo || m.freq_hz * (1.0 + m.damping_ratio) > f_hi) {
      out.edge_modes_hz.push_back(m.freq_hz);
    }
  }
  double s = 0.0;
  for (int k = 0; k < usable.size(); ++k) {
    s += std::norm((out.fit.Evaluate(usable.freq_hz()(k)) - usable.receptance()(k)) / (*usable.noise_sigma())(k));
  }
  out.noise_rms = std::sqrt(s / usable.size());
  out.poor = !(out.noise_rms <= o.max_noise_rms);
  if (out.poor) {
    std::ostringstream m;
    m.precision(3);
    m << "the fitted modes miss the data by " << out.noise_rms << " times the noise (rms over the "
      << usable.size() << " usable lines; limit " << o.max_noise_rms << ")";
    out.problem = m.str();
  }
  return out;
}

TipModalModel ModesAlong(const calibration::ModalFitResult& fit, const Eigen::Vector3d& e,
                         std::vector<double>* dropped_hz) {
  const Eigen::Vector3d u = e.normalized();
  std::vector<double> w, z;
  std::vector<Eigen::Vector3d> p;
  for (const calibration::FittedMode& m : fit.modes) {
    const double A = m.modal_constant.real();  // φ_a² [1/kg]
    if (!(A > 0.0) || !(m.damping_ratio >= 0.0 && m.damping_ratio < 1.0)) {
      if (dropped_hz) dropped_hz->push_back(m.freq_hz);
      continue;
    }
    w.push_back(HzToRadPerSec(m.freq_hz));
    z.push_back(m.damping_ratio);
    p.push_back(std::sqrt(A) * u);
  }
  TipModalModel out;
  out.omega_rad_s = Eigen::Map<Eigen::VectorXd>(w.data(), static_cast<Eigen::Index>(w.size()));
  out.zeta = Eigen::Map<Eigen::VectorXd>(z.data(), static_cast<Eigen::Index>(z.size()));
  out.p.resize(3, static_cast<Eigen::Index>(p.size()));
  for (size_t k = 0; k < p.size(); ++k) out.p.col(static_cast<Eigen::Index>(k)) = p[k];
  return out;
}

TipModalModel ModesOfTwoDirections(const calibration::ModalFitResult& fit_a, const Eigen::Vector3d& e_a,
                                   const calibration::ModalFitResult& fit_b, const Eigen::Vector3d& e_b,
                                   const dynamics::Frf& cross, std::vector<double>* dropped_hz) {
  const TipModalModel ma = ModesAlong(fit_a, e_a, dropped_hz), mb = ModesAlong(fit_b, e_b, dropped_hz);
  // Pair the modes of the two directions (each used once, nearest first).
  std::vector<int> partner(ma.num_modes(), -1);
  std::vector<char> taken(mb.num_modes(), 0);
  for (int i = 0; i < ma.num_modes(); ++i) {
    double best = INFINITY;
    for (int j = 0; j < mb.num_modes(); ++j) {
      const double d = std::abs(ma.omega_rad_s(i) - mb.omega_rad_s(j));
      const double zbar = 0.5 * (ma.zeta(i) + mb.zeta(j));
      if (!taken[j] && d < 0.2 * 2.0 * zbar * ma.omega_rad_s(i) && d < best) {
        best = d;
        partner[i] = j;
      }
    }
    if (partner[i] >= 0) taken[partner[i]] = 1;
  }
  std::vector<std::complex<double>> poles;
  for (int i = 0; i < ma.num_modes(); ++i) {
    if (partner[i] < 0) continue;
    const double w = 0.5 * (ma.omega_rad_s(i) + mb.omega_rad_s(partner[i]));
    const double z = 0.5 * (ma.zeta(i) + mb.zeta(partner[i]));
    poles.push_back({-z * w, w * std::sqrt(1.0 - z * z)});
  }
  calibration::ModalFitResult cr;
  if (!poles.empty()) calibration::FitResidues(cross, poles, false, &cr);
  std::vector<TipModalModel> parts;
  int shared = 0;
  for (int i = 0; i < ma.num_modes(); ++i) {
    TipModalModel m;
    m.omega_rad_s = Eigen::VectorXd::Constant(1, ma.omega_rad_s(i));
    m.zeta = Eigen::VectorXd::Constant(1, ma.zeta(i));
    m.p = ma.p.col(i);
    if (partner[i] >= 0) {
      const int j = partner[i];
      const double sign = cr.modes.at(shared).modal_constant.real() < 0.0 ? -1.0 : 1.0;
      m.omega_rad_s(0) = std::abs(poles[shared]);
      m.zeta(0) = -poles[shared].real() / std::abs(poles[shared]);
      m.p.col(0) += sign * mb.p.col(j);
      ++shared;
    }
    parts.push_back(m);
  }
  for (int j = 0; j < mb.num_modes(); ++j) {
    if (taken[j]) continue;
    TipModalModel m;
    m.omega_rad_s = Eigen::VectorXd::Constant(1, mb.omega_rad_s(j));
    m.zeta = Eigen::VectorXd::Constant(1, mb.zeta(j));
    m.p = mb.p.col(j);
    parts.push_back(m);
  }
  return Concatenate(parts);
}

TipModalModel Concatenate(const std::vector<TipModalModel>& models) {
  Eigen::Index n = 0;
  for (const TipModalModel& m : models) n += m.num_modes();
  TipModalModel out;
  out.omega_rad_s.resize(n);
  out.zeta.resize(n);
  out.p.resize(3, n);
  Eigen::Index k = 0;
  for (const TipModalModel& m : models) {
    const Eigen::Index c = m.num_modes();
    out.omega_rad_s.segment(k, c) = m.omega_rad_s;
    out.zeta.segment(k, c) = m.zeta;
    out.p.middleCols(k, c) = m.p;
    k += c;
  }
  return out;
}

}  // namespace robomach::stability
