#include "robomach/identification/joint_stiffness.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include <ceres/ceres.h>
#include <Eigen/Dense>

#include "identification/internal/information.h"
#include "identification/internal/tracker_residual.h"
#include "robomach/common/enum_names.h"
#include "robomach/common/errors.h"
#include "robomach/identification/compliance_model.h"

namespace robomach::identification {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// 1.959964 is the two-sided 95 % quantile of the standard normal.
constexpr double kZ95 = 1.959963984540054;

std::string JointList(const std::vector<int>& joints) {
  std::ostringstream s;
  for (size_t i = 0; i < joints.size(); ++i) {
    if (i > 0) s << (i + 1 == joints.size() ? " and " : ", ");
    s << joints[i] + 1;
  }
  return s.str();
}

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

// What a load case must add so that joint j (0-based, of n) is loaded.
std::string MomentAdvice(int j, int n) {
  if (j == n - 1) {
    return "add load cases with a moment about the tool axis (a load point off the tool axis, "
           "lx_mm/ly_mm, with the rope not parallel to the axis)";
  }
  if (j == 0) {
    return "add load cases with a moment about the vertical base axis (pull the rope sideways, "
           "with the flange far from the base axis)";
  }
  return "add load cases with a moment about joint " + std::to_string(j + 1) +
         "'s axis (other postures or rope directions, so that the force passes farther from "
         "that axis)";
}


}  // namespace

Determination DeterminationFromRelativeStd(double relative_std, double weak_relative_std) {
  if (!std::isfinite(relative_std)) return Determination::kNotDetermined;
  return relative_std > weak_relative_std ? Determination::kWeak : Determination::kDetermined;
}

const char* ToString(Determination d) {
  switch (d) {
    case Determination::kDetermined: return "determined";
    case Determination::kWeak: return "weakly determined";
    case Determination::kNotDetermined: return "not determined";
  }
  return "?";
}

const char* ToString(RobustLoss l) {
  switch (l) {
    case RobustLoss::kNone: return "none";
    case RobustLoss::kHuber: return "huber";
    case RobustLoss::kCauchy: return "cauchy";
  }
  return "?";
}

RobustLoss ParseRobustLoss(const std::string& name) {
  constexpr RobustLoss kAll[] = {RobustLoss::kNone, RobustLoss::kHuber, RobustLoss::kCauchy};
  return ParseByName("robust loss", name, kAll);
}

Determination ParseDetermination(const std::string& name) {
  constexpr Determination kAll[] = {Determination::kDetermined, Determination::kWeak,
                                    Determination::kNotDetermined};
  return ParseByName("determination", name, kAll);
}

void IdentificationOptions::Validate() const {
  const IdentificationOptions& o = *this;
  auto fail = [](const std::string& field, double v, const std::string& bound) {
    std::ostringstream s;
    s << "IdentificationOptions::" << field << ": expected " << bound << ", got " << v;
    throw OptionError(field, s.str());
  };
  if (!(o.tracker_noise > 0.0) || !std::isfinite(o.tracker_noise)) {
    fail("tracker_noise", o.tracker_noise, "a finite value > 0 m");
  }
  if (!(o.loss_scale > 0.0)) fail("loss_scale", o.loss_scale, "a value > 0");
  if (!(o.outlier_false_alarm > 0.0 && o.outlier_false_alarm < 1.0)) {
    fail("outlier_false_alarm", o.outlier_false_alarm, "a probability in (0, 1)");
  }
  if (!(o.weak_relative_std > 0.0)) fail("weak_relative_std", o.weak_relative_std, "a value > 0");
  if (o.max_iterations < 1) fail("max_iterations", o.max_iterations, "at least 1");
}

dynamics::ParameterUncertainty StiffnessUncertainty(const JointStiffnessResult& result, const std::string& source) {
  std::vector<int> joints;
  for (int j = 0; j < result.num_joints; ++j) {
    if (j < result.log_stiffness_covariance.rows() && std::isfinite(result.log_stiffness_covariance(j, j))) {
      joints.push_back(j);
    }
  }
  if (joints.empty()) throw std::invalid_argument("no joint stiffness was determined: no uncertainty to write");
  dynamics::ParameterUncertainty u;
  u.source = source;
  const auto m = static_cast<Eigen::Index>(joints.size());
  u.covariance.resize(m, m);
  for (Eigen::Index a = 0; a < m; ++a) {
    const int ja = joints[a];
    u.parameters.push_back({"kq" + std::to_string(ja + 1) + "_Nm_per_rad", result.joint_stiffness(ja),
                            dynamics::UncertainScale::kInverse});
    for (Eigen::Index b = 0; b < m; ++b) {
      const int jb = joints[b];
      // c = 1/k = e^{-log k}: cov(c_a, c_b) = c_a c_b cov(log k_a, log k_b),
      // exact here because the fit's covariance is that of the linear
      // problem in the compliances (see the 95 % intervals above).
      u.covariance(a, b) = result.log_stiffness_covariance(ja, jb) / (result.joint_stiffness(ja) * result.joint_stiffness(jb));
    }
  }
  u.covariance = (0.5 * (u.covariance + u.covariance.transpose())).eval();  // symmetric to the last bit
  return u;
}

double ChiSquare3UpperQuantile(double p) {
  if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("ChiSquare3UpperQuantile: p outside (0, 1)");
  // Survival function of χ²₃: erfc(√(x/2)) + √(2x/π) e^(−x/2)
  // (the odd-ν closed form of [Abramowitz & Stegun 1964, ch. 26] with ν = 3,
  // M. Abramowitz, I. A. Stegun, Handbook of Mathematical Functions, NBS).
  // It decreases strictly, so
  // bisection on [0, 2000] (sf(2000) < 1e-400) converges to machine precision.
  auto sf = [](double x) {
    return std::erfc(std::sqrt(0.5 * x)) + std::sqrt(2.0 * x / 3.14159265358979323846) * std::exp(-0.5 * x);
  };
  double lo = 0.0, hi = 2000.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (sf(mid) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

namespace {

// The stages of IdentifyJointStiffness below, in their order: assembly of
// the cases, the joints the data can determine, the linear start, the
// staged Ceres solve, residuals, per-joint uncertainty, rigid joints,
// condition number and advice. They pass their state in CaseData, Fit and
// JointFindings.

// What the stages need of the load cases (their ids and measured
// displacements aside): per case y = D/σ and B = A diag(1/k0)/σ of (3) in
// tracker_residual.h.
struct CaseData {
  int n{0};            // joints
  int m{0};            // load cases
  Eigen::VectorXd k0;  // the robot config's stiffness (the prior)
  double sigma{0.0};   // noise of a displacement component [m]
  std::vector<Matrix3Xd> B;
  std::vector<Eigen::Vector3d> y;
};

// The state of the fit, from the joint classification to the covariance.
struct Fit {
  internal::Identifiability prior;  // of the information of all cases, before any fit
  std::vector<int> unseen;          // not determined: no sensitivity at all
  std::vector<int> traded;          // not determined: an exact trade-off
  std::vector<int> free;            // the fitted joints
  std::vector<int> diverged;        // held at the prior after running away
  Eigen::VectorXd theta;            // θ = log(k/k0); 0 = prior
  std::vector<bool> excluded;       // cases left out (robust second pass)
  ceres::Solver::Summary summary;   // of the last solve
  // Covariance of θ from ceres::Covariance (zero rows for held joints).
  Eigen::MatrixXd cov_theta;
  double inflate{1.0};  // factor on the standard deviations from χ²/dof
};

// What the uncertainty stages find about single joints, for the advice.
struct JointFindings {
  std::vector<int> cov_failed;            // fitted, but the covariance is rank-deficient in them
  std::vector<int> rigid;                 // consistent with a rigid joint: only a lower bound
  std::vector<double> rigid_x, rigid_sx;  // their relative compliance and its σ
};

// Assembly: y and B per case, and per joint the largest moment about its
// axis and the largest lever of the target, which the advice quotes.
CaseData AssembleCases(const dynamics::RobotModel& model, const std::vector<LoadCase>& cases,
                       const ProgressCallback& progress, JointStiffnessResult* out) {
  JointStiffnessResult& res = *out;
  CaseData d;
  d.n = res.num_joints;
  d.m = res.num_cases;
  d.k0 = model.joint_stiffness();
  d.sigma = res.noise_sigma_displacement;
  const int n = d.n, m = d.m;
  d.B.resize(m);
  d.y.resize(m);
  res.max_joint_torque = Eigen::VectorXd::Zero(n);
  res.max_target_lever = Eigen::VectorXd::Zero(n);
  const Eigen::Vector3d tcp = TcpInTip(model);
  for (int c = 0; c < m; ++c) {
    LoadCase lc = cases[c];
    if (!lc.p_load_tip) lc.p_load_tip = tcp;
    if (!lc.p_target_tip) lc.p_target_tip = tcp;
    if (!lc.force.allFinite() || !lc.displacement.allFinite()) {
      throw std::invalid_argument("load case " + lc.case_id + ": non-finite force or displacement");
    }
    const CaseKinematics k = EvaluateCaseKinematics(model, lc);
    const Matrix3Xd A = DisplacementPerCompliance(k, lc.force);
    d.B[c] = A * d.k0.cwiseInverse().asDiagonal() / d.sigma;
    d.y[c] = lc.displacement / d.sigma;
    const Eigen::VectorXd tau = k.Jv_L.transpose() * lc.force;
    for (int j = 0; j < n; ++j) {
      res.max_joint_torque(j) = std::max(res.max_joint_torque(j), std::abs(tau(j)));
      res.max_target_lever(j) = std::max(res.max_target_lever(j), k.Jv_T.col(j).norm());
    }
    if (progress && (c + 1 == m || (c + 1) % 100 == 0)) progress(c + 1, m);
  }
  return d;
}

// (ii) Which joints the data can determine at all. The model is linear in
// the relative compliances x_j = c_j/c0_j, so its information B^T B (the
// Fisher information of x) does not depend on where it is evaluated. A
// joint is not determined only where that information is numerically
// rank-deficient in it (internal::AnalyseIdentifiability): no sensitivity
// at all (`unseen`), or an exact trade-off with other joints (`traded`).
// A joint with little but finite information is fitted and reported with
// its (large) uncertainty.
Fit ClassifyJoints(const CaseData& d, JointStiffnessResult* out) {
  const int n = d.n;
  Eigen::MatrixXd info = Eigen::MatrixXd::Zero(n, n);
  for (int c = 0; c < d.m; ++c) info.noalias() += d.B[c].transpose() * d.B[c];
  out->determination.assign(n, Determination::kDetermined);
  Fit fit;
  fit.prior = internal::AnalyseIdentifiability(info);
  for (int j = 0; j < n; ++j) {
    if (!fit.prior.null[j]) fit.free.push_back(j);
    else (fit.prior.no_sensitivity[j] ? fit.unseen : fit.traded).push_back(j);
  }
  fit.theta = Eigen::VectorXd::Zero(n);
  fit.excluded.assign(d.m, false);
  fit.cov_theta = Eigen::MatrixXd::Constant(n, n, kNaN);
  return fit;
}

// (i) Exact linear least squares in x for the free joints, the others at
// the prior (x = 1): the start of the Ceres fit.
void LinearStart(const CaseData& d, Fit* fit, JointStiffnessResult* out) {
  const int n = d.n, m = d.m;
  const std::vector<int>& free = fit->free;
  const int p = static_cast<int>(free.size());
  out->linear_start = Eigen::VectorXd::Constant(n, kNaN);
  if (p == 0) return;
  Eigen::MatrixXd Bf(3 * m, p);
  Eigen::VectorXd rhs(3 * m);
  for (int c = 0; c < m; ++c) {
    Eigen::Vector3d yc = d.y[c];
    for (int j = 0; j < n; ++j) {
      if (std::find(free.begin(), free.end(), j) == free.end()) yc -= d.B[c].col(j);
    }
    rhs.segment<3>(3 * c) = yc;
    for (int a = 0; a < p; ++a) Bf.block<3, 1>(3 * c, a) = d.B[c].col(free[a]);
  }
  const Eigen::VectorXd x = Bf.colPivHouseholderQr().solve(rhs);
  for (int a = 0; a < p; ++a) {
    const int j = free[a];
    if (x(a) > 0.0 && std::isfinite(x(a))) {
      out->linear_start(j) = d.k0(j) / x(a);
      fit->theta(j) = -std::log(x(a));
    }
    // A compliance <= 0 from the linear fit means the data barely see the
    // joint; Ceres starts it at the prior and the covariance says so.
  }
}

// (iii) One Ceres solve in θ over the cases not excluded, the joints not
// free held; with `robust`, under the robust loss. With `covariance`, also
// (v) the covariance of θ on that final problem into fit->cov_theta; false
// when it cannot be computed.
bool SolveTheta(const CaseData& d, const IdentificationOptions& options, bool robust, bool covariance, Fit* fit,
                JointStiffnessResult* out) {
  const int n = d.n, m = d.m;
  const std::vector<int>& free = fit->free;
  const std::vector<bool>& excluded = fit->excluded;
  const int p = static_cast<int>(free.size());
  Eigen::VectorXd& theta = fit->theta;
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  auto problem = std::make_unique<ceres::Problem>(po);
  for (int c = 0; c < m; ++c) {
    if (excluded[c]) continue;
    ceres::LossFunction* loss = nullptr;
    if (robust && options.loss == RobustLoss::kHuber) loss = new ceres::HuberLoss(options.loss_scale);
    if (robust && options.loss == RobustLoss::kCauchy) loss = new ceres::CauchyLoss(options.loss_scale);
    problem->AddResidualBlock(new internal::TrackerResidual(d.y[c], d.B[c]), loss, theta.data());
  }
  if (p < n) {
    std::vector<int> fixed;
    for (int j = 0; j < n; ++j) {
      if (std::find(free.begin(), free.end(), j) == free.end()) fixed.push_back(j);
    }
    problem->SetManifold(theta.data(), new ceres::SubsetManifold(n, fixed));
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  // Relative tolerances well below the noise-limited precision of θ
  // (~1e-3 and worse), so the answer is converged for statistics.
  so.function_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.gradient_tolerance = 1e-14;
  ceres::Solve(so, problem.get(), &fit->summary);
  out->iterations += static_cast<int>(fit->summary.iterations.size());
  if (!covariance) return true;
  // (v) covariance of θ on the final problem.
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  {
    int rows = 0;
    for (int c = 0; c < m; ++c) rows += excluded[c] ? 0 : 3;
    Eigen::MatrixXd J(rows, p);
    int r0 = 0;
    for (int c = 0; c < m; ++c) {
      if (excluded[c]) continue;
      for (int a = 0; a < p; ++a) J.block<3, 1>(r0, a) = d.B[c].col(free[a]) * std::exp(-theta(free[a]));
      r0 += 3;
    }
    const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(J).singularValues();
    // Ceres' own bound (min_reciprocal_condition_number) with margin.
    if (!(sv.size() > 0 && sv(sv.size() - 1) > 1e-12 * sv(0))) return false;
  }
  ceres::Covariance cov(co);
  std::vector<std::pair<const double*, const double*>> blocks{{theta.data(), theta.data()}};
  if (!cov.Compute(blocks, problem.get())) return false;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Cr(n, n);
  cov.GetCovarianceBlock(theta.data(), theta.data(), Cr.data());
  fit->cov_theta = Cr;
  return true;
}

// The staged solve: with a robust loss, a robust pass whose outliers are
// then excluded; plain solves until no joint runs away from the prior; the
// final solve with the covariance; the fit status and the outlier flags.
void RunFit(const CaseData& d, const IdentificationOptions& options, Fit* fit, JointStiffnessResult* out) {
  JointStiffnessResult& res = *out;
  const int n = d.n, m = d.m;
  std::vector<int>& free = fit->free;
  std::vector<bool>& excluded = fit->excluded;
  const Eigen::VectorXd& theta = fit->theta;
  int p = static_cast<int>(free.size());
  if (p == 0) {
    res.status = FitStatus::kFailed;
    res.solver_message = "no joint stiffness can be determined from these load cases";
    return;
  }
  const double chi2_bound = ChiSquare3UpperQuantile(options.outlier_false_alarm / m);
  auto normalized2 = [&](int c) {
    Eigen::Vector3d r = d.y[c];
    for (int j = 0; j < n; ++j) r -= d.B[c].col(j) * std::exp(-theta(j));
    return r.squaredNorm();
  };
  // Outliers are judged against the stated noise, or against the noise the
  // residuals show if that is larger: a robust scale from the median of
  // the squared normalised residuals (the median of χ²₃ is 2.365974), which
  // a few gross outliers do not move. Otherwise an understated noise would
  // make every case an "outlier".
  auto outlier_threshold = [&]() {
    std::vector<double> v(m);
    for (int c = 0; c < m; ++c) v[c] = normalized2(c);
    std::nth_element(v.begin(), v.begin() + m / 2, v.end());
    res.robust_noise_ratio = std::sqrt(v[m / 2] / 2.365974);
    return chi2_bound * std::max(1.0, res.robust_noise_ratio * res.robust_noise_ratio);
  };
  double threshold = chi2_bound;
  if (options.loss != RobustLoss::kNone) {
    SolveTheta(d, options, true, false, fit, out);
    threshold = outlier_threshold();
    for (int c = 0; c < m; ++c) excluded[c] = normalized2(c) > threshold;
    // Never drop so many cases that fewer equations than unknowns remain.
    const int kept = static_cast<int>(std::count(excluded.begin(), excluded.end(), false));
    if (3 * kept <= p) std::fill(excluded.begin(), excluded.end(), false);
  }
  // A joint whose stiffness runs away from the prior by more than 1000×
  // (its compliance heads for 0 because the data ask for a negative one)
  // is not determined by these cases: hold it at the prior and solve again.
  // A prior off by 1000× is not a plausible robot config.
  const double kMaxLogRatio = std::log(1e3);
  for (;;) {
    SolveTheta(d, options, false, false, fit, out);
    std::vector<int> runaway;
    for (int j : free) {
      if (!(std::abs(theta(j)) <= kMaxLogRatio)) runaway.push_back(j);
    }
    if (runaway.empty() || static_cast<int>(runaway.size()) == p) break;
    for (int j : runaway) {
      fit->theta(j) = 0.0;
      free.erase(std::find(free.begin(), free.end(), j));
      fit->diverged.push_back(j);
    }
    p = static_cast<int>(free.size());
  }
  // Ceres logs through glog when the covariance is rank-deficient; a
  // rank check first keeps such noise off the user's terminal.
  const bool cov_ok = SolveTheta(d, options, false, true, fit, out);
  switch (fit->summary.termination_type) {
    case ceres::CONVERGENCE: res.status = FitStatus::kConverged; break;
    case ceres::NO_CONVERGENCE: res.status = FitStatus::kNotConverged; break;
    default: res.status = FitStatus::kFailed; break;
  }
  res.solver_message = fit->summary.message;
  if (!cov_ok) {
    res.solver_message += "; the covariance could not be computed (rank-deficient Jacobian)";
    fit->cov_theta.setConstant(kNaN);
  }
  // Outlier flags at the solution; with a robust loss they are the cases
  // the robust pass excluded.
  if (options.loss == RobustLoss::kNone) threshold = outlier_threshold();
  res.outlier_threshold = std::sqrt(threshold);
  for (int c = 0; c < m; ++c) {
    const bool flag = options.loss != RobustLoss::kNone ? excluded[c] : normalized2(c) > threshold;
    if (flag) res.outliers.push_back(c);
  }
}

// Residuals, χ² and the covariance inflation (into fit->inflate).
void ComputeResiduals(const std::vector<LoadCase>& cases, const CaseData& d, const IdentificationOptions& options,
                      Fit* fit, JointStiffnessResult* out) {
  JointStiffnessResult& res = *out;
  const int n = d.n, m = d.m;
  const int p = static_cast<int>(fit->free.size());
  double sum2_in = 0.0, sum2_all = 0.0, chi2 = 0.0;
  int m_in = 0;
  for (int c = 0; c < m; ++c) {
    CaseResidual r;
    r.case_id = cases[c].case_id;
    r.measured = cases[c].displacement;
    Eigen::Vector3d pred = Eigen::Vector3d::Zero();
    for (int j = 0; j < n; ++j) pred += d.B[c].col(j) * std::exp(-fit->theta(j));
    r.predicted = pred * d.sigma;
    r.residual = r.measured - r.predicted;
    r.norm = r.residual.norm();
    r.normalized = r.norm / d.sigma;
    r.outlier = std::find(res.outliers.begin(), res.outliers.end(), c) != res.outliers.end();
    sum2_all += r.norm * r.norm;
    if (!r.outlier || options.loss == RobustLoss::kNone) {
      sum2_in += r.norm * r.norm;
      chi2 += r.normalized * r.normalized;
      ++m_in;
    }
    res.residuals.push_back(std::move(r));
  }
  res.rms_residual = std::sqrt(sum2_in / std::max(m_in, 1));
  res.rms_residual_all = std::sqrt(sum2_all / m);
  const int dof = 3 * m_in - p;
  res.reduced_chi2 = dof > 0 ? chi2 / dof : kNaN;
  // χ²/dof has mean 1 and standard deviation √(2/dof) when the noise is as
  // stated; three of those above 1 is not chance.
  fit->inflate = 1.0;
  if (dof > 0 && res.reduced_chi2 > 1.0 + 3.0 * std::sqrt(2.0 / dof)) {
    fit->inflate = std::sqrt(res.reduced_chi2);
    res.covariance_inflated = true;
  }
}

// Per-joint uncertainty and determination from the (inflated) covariance of
// θ: standard deviations, 95 % intervals, correlations and the covariance of
// log k. Returns the fitted joints the covariance does not determine.
std::vector<int> JointUncertainty(const CaseData& d, const IdentificationOptions& options, Fit* fit,
                                  JointStiffnessResult* out) {
  JointStiffnessResult& res = *out;
  const int n = d.n;
  const Eigen::VectorXd& k0 = d.k0;
  const Eigen::VectorXd& theta = fit->theta;
  Eigen::MatrixXd& cov_theta = fit->cov_theta;
  const Eigen::VectorXd k_hat = (k0.array() * theta.array().exp()).matrix();
  res.joint_stiffness = k_hat;
  res.std_dev = Eigen::VectorXd::Constant(n, kInf);
  res.relative_std = Eigen::VectorXd::Constant(n, kInf);
  res.lower_95 = Eigen::VectorXd::Zero(n);
  res.upper_95 = Eigen::VectorXd::Constant(n, kInf);
  res.variance_inflation = Eigen::VectorXd::Constant(n, kNaN);
  res.trade_off_with.assign(n, {});
  cov_theta *= fit->inflate * fit->inflate;
  res.correlation = Eigen::MatrixXd::Constant(n, n, kNaN);
  for (int j : fit->unseen) res.determination[j] = Determination::kNotDetermined;
  for (int j : fit->traded) res.determination[j] = Determination::kNotDetermined;
  for (int j : fit->diverged) res.determination[j] = Determination::kNotDetermined;
  std::vector<int> cov_failed;
  for (int j : fit->free) {
    const double s = std::sqrt(std::max(cov_theta(j, j), 0.0));
    res.determination[j] = DeterminationFromRelativeStd(s, options.weak_relative_std);
    if (res.determination[j] == Determination::kNotDetermined) {
      cov_failed.push_back(j);
      continue;
    }
    res.relative_std(j) = s;
    // Delta method for σ_k.
    res.std_dev(j) = k_hat(j) * s;
    // The 95 % interval is built in the relative compliance x = e^{-θ}, in
    // which the model is linear (so x̂ is Gaussian with σ_x = x̂ σ_θ exactly,
    // the Gauss-Newton covariance being that of a linear problem), and mapped
    // to k = k0/x. It stays exact for weakly determined joints, where a
    // symmetric interval in log k would not cover the truth 95 % of the
    // time; its upper end is +inf when the compliance interval reaches 0
    // (the data cannot exclude a rigid joint).
    const double x = std::exp(-theta(j)), sx = x * s;
    res.lower_95(j) = k0(j) / (x + kZ95 * sx);
    res.upper_95(j) = x - kZ95 * sx > 0.0 ? k0(j) / (x - kZ95 * sx) : kInf;
  }
  res.log_stiffness_covariance = Eigen::MatrixXd::Constant(n, n, kNaN);
  for (int a : fit->free) {
    for (int b : fit->free) {
      const double dn = std::sqrt(cov_theta(a, a) * cov_theta(b, b));
      if (dn > 0.0) res.correlation(a, b) = cov_theta(a, b) / dn;
      if (std::isfinite(res.relative_std(a)) && std::isfinite(res.relative_std(b))) {
        res.log_stiffness_covariance(a, b) = cov_theta(a, b);
      }
    }
  }
  return cov_failed;
}

// Why a joint's uncertainty is what it is: the information of the final
// problem (fitted joints, inlier cases). Variance inflation and
// correlations are invariant to the scaling of the parameters, so the
// information in x serves for θ at the solution as well.
void ExplainUncertainty(const CaseData& d, const IdentificationOptions& options, const Fit& fit,
                        const JointFindings& found, JointStiffnessResult* out) {
  JointStiffnessResult& res = *out;
  const std::vector<int>& cov_failed = found.cov_failed;
  std::vector<int> fitted;
  for (int j : fit.free) {
    if (std::find(cov_failed.begin(), cov_failed.end(), j) == cov_failed.end()) fitted.push_back(j);
  }
  const int f = static_cast<int>(fitted.size());
  Eigen::MatrixXd sub = Eigen::MatrixXd::Zero(f, f);
  for (int c = 0; c < d.m; ++c) {
    if (std::find(res.outliers.begin(), res.outliers.end(), c) != res.outliers.end() &&
        options.loss != RobustLoss::kNone) continue;
    for (int a = 0; a < f; ++a)
      for (int b = 0; b < f; ++b) sub(a, b) += d.B[c].col(fitted[a]).dot(d.B[c].col(fitted[b]));
  }
  const internal::Identifiability id = internal::AnalyseIdentifiability(sub);
  for (int a = 0; a < f; ++a) {
    const int j = fitted[a];
    res.variance_inflation(j) = id.variance_inflation(a);
    // Partners of a near trade-off: the joints correlated with j by at
    // least 0.5 in magnitude, strongest first; at least the strongest one.
    std::vector<std::pair<double, int>> corr;
    for (int b = 0; b < f; ++b) {
      if (b != a && std::isfinite(id.correlation(a, b))) corr.push_back({std::abs(id.correlation(a, b)), fitted[b]});
    }
    std::sort(corr.rbegin(), corr.rend());
    for (size_t i = 0; i < corr.size(); ++i) {
      if (i == 0 || corr[i].first >= 0.5) res.trade_off_with[j].push_back(corr[i].second);
    }
  }
}

// A joint the fit drove to infinite stiffness (its unconstrained linear
// estimate of the compliance is negative) is still informed by the data
// if that estimate is within noise of zero or above: the data are then
// consistent with a rigid joint, and only a lower bound of its stiffness
// is known. It is weakly determined with that one-sided 95 % interval
// (exact in the compliance, as above) and keeps the prior as its value.
// Only a compliance below zero beyond the noise (cases inconsistent with
// the model) leaves it not determined. Moves such joints from
// fit->diverged to found->rigid.
void FindRigidJoints(const CaseData& d, Fit* fit, JointFindings* found, JointStiffnessResult* out) {
  JointStiffnessResult& res = *out;
  std::vector<int>& diverged = fit->diverged;
  if (diverged.empty()) return;
  const int n = d.n, m = d.m;
  const std::vector<int>& cov_failed = found->cov_failed;
  std::vector<int> S;
  for (int j : fit->free) {
    if (std::find(cov_failed.begin(), cov_failed.end(), j) == cov_failed.end()) S.push_back(j);
  }
  S.insert(S.end(), diverged.begin(), diverged.end());
  const int q = static_cast<int>(S.size());
  int rows = 0;
  for (int c = 0; c < m; ++c) rows += fit->excluded[c] ? 0 : 3;
  Eigen::MatrixXd Bs(rows, q);
  Eigen::VectorXd rhs(rows);
  int r0 = 0;
  for (int c = 0; c < m; ++c) {
    if (fit->excluded[c]) continue;
    Eigen::Vector3d yc = d.y[c];
    for (int j = 0; j < n; ++j) {
      if (std::find(S.begin(), S.end(), j) == S.end()) yc -= d.B[c].col(j) * std::exp(-fit->theta(j));
    }
    rhs.segment<3>(r0) = yc;
    for (int a = 0; a < q; ++a) Bs.block<3, 1>(r0, a) = d.B[c].col(S[a]);
    r0 += 3;
  }
  const Eigen::MatrixXd F = Bs.transpose() * Bs;
  const Eigen::VectorXd x = Bs.colPivHouseholderQr().solve(rhs);
  const Eigen::MatrixXd C = F.ldlt().solve(Eigen::MatrixXd::Identity(q, q)) * (fit->inflate * fit->inflate);
  for (int a = static_cast<int>(S.size() - diverged.size()); a < q; ++a) {
    const int j = S[a];
    const double sx = std::sqrt(std::max(C(a, a), 0.0));
    if (!(std::isfinite(x(a)) && std::isfinite(sx) && x(a) + kZ95 * sx > 0.0)) continue;
    found->rigid.push_back(j);
    found->rigid_x.push_back(x(a));
    found->rigid_sx.push_back(sx);
    res.determination[j] = Determination::kWeak;
    res.lower_95(j) = d.k0(j) / (x(a) + kZ95 * sx);
    res.upper_95(j) = kInf;
  }
  for (int j : found->rigid) diverged.erase(std::find(diverged.begin(), diverged.end(), j));
}

// Condition number of the column-scaled weighted Jacobian ∂r/∂θ (all joints).
double ConditionNumber(const CaseData& d, const Eigen::VectorXd& theta) {
  Eigen::MatrixXd J(3 * d.m, d.n);
  for (int c = 0; c < d.m; ++c) {
    for (int j = 0; j < d.n; ++j) J.block<3, 1>(3 * c, j) = d.B[c].col(j) * std::exp(-theta(j));
  }
  for (int j = 0; j < d.n; ++j) {
    const double cn = J.col(j).norm();
    if (cn > 0.0) J.col(j) /= cn;
  }
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(J).singularValues();
  return sv(sv.size() - 1) > 0.0 ? sv(0) / sv(sv.size() - 1) : kInf;
}

// Advice in words a test engineer can act on (the Advise* stages below).
constexpr char kMoreVariety[] =
    "add postures with different joint angles (arm reach, elbow and wrist angles) and load cases with "
    "other rope directions";

// The sensitivity of the target to joint j's compliance is the product of
// the moment about its axis and the target's lever about it; say which of
// the two is relatively smaller (both if both are under 1 % of the largest).
std::string Sensitivity(const JointStiffnessResult& res, int j, bool weak = true) {
  const int n = res.num_joints;
  const double tmax = res.max_joint_torque.maxCoeff();
  const double lmax = res.max_target_lever.maxCoeff();
  std::ostringstream s;
  const double tr = tmax > 0.0 ? res.max_joint_torque(j) / tmax : 0.0;
  const double lr = lmax > 0.0 ? res.max_target_lever(j) / lmax : 0.0;
  const bool unloaded = tr <= lr || tr < 0.01;
  const bool unwatched = lr < tr || lr < 0.01;
  if (tmax == 0.0) return std::string("no load case loads the robot (every force is zero)");
  // Loaded and watched as well as the best joints: neither is the cause
  // (a noise of 10 mm read "barely loaded, 502.6 against 502.6 N·m").
  if (weak && tr >= 0.5 && lr >= 0.5) {
    s << "it is loaded and seen as well as the other joints (largest moment " << Fixed(res.max_joint_torque(j), 1)
      << " N·m, lever " << Fixed(1e3 * res.max_target_lever(j), 1)
      << " mm), so its deflections are small against the tracker noise: check the noise given (its unit), or "
         "add load cases and heavier masses";
    return s.str();
  }
  if (unloaded) {
    s << "it is barely loaded (largest moment about its axis " << Fixed(res.max_joint_torque(j), 1)
      << " N·m, against " << Fixed(tmax, 1) << " N·m on the most loaded joint): " << MomentAdvice(j, n);
  }
  if (unwatched) {
    s << (unloaded ? "; and the" : "the") << " tracker target barely moves when it turns "
      << "(largest lever " << Fixed(1e3 * res.max_target_lever(j), 1) << " mm, against "
      << Fixed(1e3 * lmax, 1) << " mm): place the target farther from joint " << j + 1 << "'s axis"
      << (j == n - 1 ? " (off the tool axis, tx_mm/ty_mm)" : "");
  }
  return s.str();
}

// Advice on the joints not determined: unseen, exact trade-offs, a
// rank-deficient covariance, a runaway stiffness.
void AdviseNotDetermined(const Fit& fit, const JointFindings& found, JointStiffnessResult* out) {
  JointStiffnessResult& res = *out;
  const int n = res.num_joints;
  for (int j : fit.unseen) {
    res.advice.push_back("joint " + std::to_string(j + 1) +
                         " is not determined (the data do not depend on its stiffness): " + Sensitivity(res, j, false));
  }
  // Exact trade-offs, one sentence per group of joints sharing null directions.
  std::vector<int> traded = fit.traded;
  std::sort(traded.begin(), traded.end());
  std::vector<std::vector<int>> groups;
  for (int j : traded) {
    std::vector<int> g{j};
    for (int i : fit.prior.null_partners[j]) g.push_back(i);
    std::sort(g.begin(), g.end());
    if (std::find(groups.begin(), groups.end(), g) == groups.end()) groups.push_back(g);
  }
  for (const auto& g : groups) {
    if (g.size() == 1) {
      res.advice.push_back("joint " + std::to_string(g[0] + 1) +
                           " is not determined: this data set fixes its compliance only in a combination "
                           "with joints held at the prior. " + kMoreVariety);
      continue;
    }
    res.advice.push_back("joints " + JointList(g) +
                         " are not determined: this data set fixes only combinations of their compliances "
                         "(an exact trade-off: changes of one are undone by the others). " + kMoreVariety);
  }
  const std::vector<int>& cov_failed = found.cov_failed;
  if (!cov_failed.empty()) {
    res.advice.push_back("joint" + std::string(cov_failed.size() > 1 ? "s " : " ") + JointList(cov_failed) +
                         (cov_failed.size() > 1 ? " are" : " is") +
                         " not determined: the covariance at the solution is rank-deficient. " + kMoreVariety);
  }
  for (int j : fit.diverged) {
    res.advice.push_back(
        "joint " + std::to_string(j + 1) +
        " is not determined: the fit drives its stiffness to infinity (the cases ask for a negative "
        "compliance), so its effect is lost in the noise or in inconsistent cases; check the outliers, "
        "then " + MomentAdvice(j, n));
  }
}

// Advice on the weakly determined joints: the rigid ones (a lower bound
// only), then the others with their causes, a near trade-off or low
// sensitivity.
void AdviseWeak(const IdentificationOptions& options, const JointFindings& found, JointStiffnessResult* out) {
  JointStiffnessResult& res = *out;
  const std::vector<int>& rigid = found.rigid;
  for (size_t i = 0; i < rigid.size(); ++i) {
    const int j = rigid[i];
    res.advice.push_back(
        "joint " + std::to_string(j + 1) + " is weakly determined: the data are consistent with a rigid joint "
        "(its compliance is estimated at " + Fixed(100.0 * found.rigid_x[i], 0) + " ± " +
        Fixed(100.0 * found.rigid_sx[i], 0) +
        " % of the robot config's, 1 sigma), so only a lower bound is known: k > " +
        Fixed(res.lower_95(j), 0) + " N·m/rad (95 %); the robot config's value is kept. Low sensitivity: " +
        Sensitivity(res, j) + "; or repeat the cases to average the tracker noise");
  }
  for (int j : res.weakly_identified) {
    if (std::find(rigid.begin(), rigid.end(), j) != rigid.end()) continue;
    std::ostringstream s;
    const double s_all = res.relative_std(j);
    const double vif = res.variance_inflation(j);
    const double s_alone = std::isfinite(vif) && vif >= 1.0 ? s_all / std::sqrt(vif) : s_all;
    s << "joint " << j + 1 << " is weakly determined (±" << Fixed(100.0 * s_all, s_all < 1.0 ? 1 : 0)
      << " % at 1 sigma): ";
    std::vector<std::string> causes;
    // A near trade-off when more than half its variance comes from the
    // correlation with other joints (variance inflation >= 2).
    if (std::isfinite(vif) && vif >= 2.0 && !res.trade_off_with[j].empty()) {
      std::ostringstream t;
      t << "a near trade-off with joint" << (res.trade_off_with[j].size() > 1 ? "s " : " ")
        << JointList(res.trade_off_with[j]) << " (correlation";
      for (size_t i = 0; i < res.trade_off_with[j].size(); ++i) {
        t << (i ? ", " : " ") << Fixed(res.correlation(j, res.trade_off_with[j][i]), 2);
      }
      t << ") makes it ±" << Fixed(100.0 * s_all, 0) << " % where it would be ±" << Fixed(100.0 * s_alone, 0)
        << " % with those known: " << kMoreVariety;
      causes.push_back(t.str());
    }
    // Low sensitivity when even with every other joint known it would be weak.
    if (s_alone > options.weak_relative_std || causes.empty()) {
      causes.push_back("low sensitivity (±" + Fixed(100.0 * s_alone, 0) +
                       " % even with the other joints known): " + Sensitivity(res, j));
    }
    for (size_t i = 0; i < causes.size(); ++i) s << (i ? "; and " : "") << causes[i];
    s << "; or repeat the cases to average the tracker noise";
    res.advice.push_back(s.str());
  }
}

// Advice on the fit as a whole: outlier cases and an understated noise.
void AdviseFitQuality(const IdentificationOptions& options, JointStiffnessResult* out) {
  JointStiffnessResult& res = *out;
  res.outliers_in_fit = !res.outliers.empty() && options.loss == RobustLoss::kNone;
  if (!res.outliers.empty()) {
    std::string ids;
    for (size_t i = 0; i < res.outliers.size(); ++i) {
      ids += (i ? ", " : "") + res.residuals[res.outliers[i]].case_id;
    }
    res.advice.push_back(
        "case" + std::string(res.outliers.size() > 1 ? "s " : " ") + ids +
        (options.loss == RobustLoss::kNone
             ? " disagree with the model far beyond the tracker noise: check them (target moved, "
               "rope slipped, wrong mass) or rerun with a robust loss"
             : " disagree with the model far beyond the tracker noise and were left out of the fit: "
               "check them (target moved, rope slipped, wrong mass)"));
  }
  if (res.covariance_inflated) {
    res.advice.push_back("the residuals are " + Fixed(std::sqrt(res.reduced_chi2), 1) +
                         " times the stated tracker noise: the standard deviations were scaled up "
                         "by that factor; check the noise value and the set-up");
  }
}

}  // namespace

JointStiffnessResult IdentifyJointStiffness(const dynamics::RobotModel& model,
                                            const std::vector<LoadCase>& cases,
                                            const IdentificationOptions& options,
                                            const ProgressCallback& progress) {
  options.Validate();
  if (cases.empty()) throw std::invalid_argument("IdentifyJointStiffness: no load cases");
  JointStiffnessResult res;
  res.num_cases = static_cast<int>(cases.size());
  res.num_joints = model.num_joints();
  res.noise_sigma_displacement = std::sqrt(2.0) * options.tracker_noise;

  const CaseData d = AssembleCases(model, cases, progress, &res);
  Fit fit = ClassifyJoints(d, &res);
  LinearStart(d, &fit, &res);
  RunFit(d, options, &fit, &res);
  ComputeResiduals(cases, d, options, &fit, &res);

  JointFindings found;
  found.cov_failed = JointUncertainty(d, options, &fit, &res);
  ExplainUncertainty(d, options, fit, found, &res);
  FindRigidJoints(d, &fit, &found, &res);
  for (int j = 0; j < d.n; ++j) {
    if (res.determination[j] == Determination::kWeak) res.weakly_identified.push_back(j);
    if (res.determination[j] == Determination::kNotDetermined) res.not_determined.push_back(j);
  }
  res.condition_number = ConditionNumber(d, fit.theta);

  AdviseNotDetermined(fit, found, &res);
  AdviseWeak(options, found, &res);
  AdviseFitQuality(options, &res);
  return res;
}

}  // namespace robomach::identification
