#pragma once

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/progress.h"
#include "robomach/common/solver_status.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/dynamics/uncertainty.h"
#include "robomach/identification/load_case.h"

namespace robomach::identification {

enum class RobustLoss { kNone, kHuber, kCauchy };

/// "none", "huber", "cauchy" (kq-identify's --robust).
const char* ToString(RobustLoss l);
/// The inverse of ToString. @throws std::invalid_argument "robust loss
/// 'NAME': expected none, huber or cauchy".
RobustLoss ParseRobustLoss(const std::string& name);

/// Options of IdentifyJointStiffness. Defaults in the header (style §2.2).
struct IdentificationOptions {
  /// Tracker noise, 1 sigma per measured coordinate [m]. A displacement is
  /// the difference of two measurements, so its noise is √2 times this.
  double tracker_noise{1e-5};
  /// Robust loss on the normalised residual of each case (3 components).
  /// With a loss, cases flagged as outliers are dropped and the fit is
  /// repeated with the plain least-squares cost, so that the covariance is
  /// that of the inliers.
  RobustLoss loss{RobustLoss::kNone};
  /// Scale of the robust loss in units of the displacement noise sigma.
  double loss_scale{3.0};
  /// Family-wise false-alarm probability for outlier flags: a case is an
  /// outlier if its squared normalised residual exceeds the χ²(3) quantile
  /// at 1 − outlier_false_alarm / num_cases (Bonferroni), scaled up by the
  /// robust noise estimate when the residuals are larger than the noise.
  double outlier_false_alarm{0.01};
  /// Relative standard deviation (σ_k / k) above which a joint is "weakly
  /// determined". There is no such bound for "not determined": that is a
  /// numerical rank-deficiency of the problem in the joint (see
  /// IdentifyJointStiffness), never a large but finite uncertainty.
  double weak_relative_std{0.1};
  int max_iterations{100};

  /// tracker_noise finite and > 0; loss_scale > 0; outlier_false_alarm in
  /// (0, 1); weak_relative_std > 0; max_iterations >= 1.
  /// @throws OptionError naming the field, the violated bound and the value
  ///   ("IdentificationOptions::tracker_noise: expected a finite value > 0
  ///   m, got -1").
  void Validate() const;
};

/// Outcome of the solver (style §2.9): the library's one solver status
/// (kNotImproved does not occur here).
using FitStatus = SolverStatus;
/// How well the data determine one joint's stiffness.
enum class Determination { kDetermined, kWeak, kNotDetermined };

const char* ToString(Determination d);
/// The inverse of ToString. @throws std::invalid_argument naming the three.
Determination ParseDetermination(const std::string& name);

/// The rule from a joint's relative standard deviation σ_k/k (of a fit, or
/// expected by a test plan): not determined where it is infinite or NaN
/// (the information is rank-deficient), weakly determined above
/// `weak_relative_std`, else determined.
Determination DeterminationFromRelativeStd(double relative_std, double weak_relative_std);

/// The residual of one load case at the solution.
struct CaseResidual {
  std::string case_id;
  Eigen::Vector3d measured{Eigen::Vector3d::Zero()};   // D measured [m, in B]
  Eigen::Vector3d predicted{Eigen::Vector3d::Zero()};  // D of the model [m, in B]
  Eigen::Vector3d residual{Eigen::Vector3d::Zero()};   // measured − predicted [m]
  double norm{NAN};          // |residual| [m]
  double normalized{NAN};    // |residual| / σ_D [-]
  bool outlier{false};
};

struct JointStiffnessResult {
  FitStatus status{FitStatus::kFailed};
  std::string solver_message;           // ceres::Summary message, verbatim, plus our notes
  int num_cases{0};
  int num_joints{0};
  Eigen::VectorXd joint_stiffness;      // [N·m/rad]; a not-determined joint keeps the prior
  Eigen::VectorXd std_dev;              // 1 sigma [N·m/rad]; +inf for a joint held at the prior
  /// 95 % interval [N·m/rad], exact in the compliance 1/k (in which the
  /// model is linear) and mapped to k; upper end +inf when the compliance
  /// interval reaches zero.
  Eigen::VectorXd lower_95, upper_95;
  Eigen::VectorXd relative_std;         // σ(log k) ≈ σ_k / k [-]
  Eigen::MatrixXd correlation;          // of the stiffnesses (NaN rows for undetermined joints)
  /// Covariance of log k (≈ that of the relative compliances, and scaled as
  /// std_dev is); NaN rows and columns for joints not determined.
  Eigen::MatrixXd log_stiffness_covariance;
  std::vector<Determination> determination;
  /// Per fitted joint: σ² over its σ² with every other joint known (>= 1;
  /// NaN for a joint not fitted). 2 or more means over half its variance
  /// comes from near trade-offs with the joints in trade_off_with.
  Eigen::VectorXd variance_inflation;
  /// Per fitted joint: the joints most correlated with it (|correlation|
  /// >= 0.5, strongest first; at least the strongest one).
  std::vector<std::vector<int>> trade_off_with;
  std::vector<int> weakly_identified;   // 0-based joint indices
  std::vector<int> not_determined;      // 0-based joint indices
  /// Sentences a test engineer can act on, one per problem found.
  std::vector<std::string> advice;
  std::vector<CaseResidual> residuals;  // every case, in input order
  std::vector<int> outliers;            // indices into residuals
  /// Outliers were found and, without a robust loss, stayed in the fit (the
  /// result is then flagged; with a loss they were left out).
  bool outliers_in_fit{false};
  double rms_residual{NAN};             // RMS of |residual| over inliers [m]
  double rms_residual_all{NAN};         // RMS of |residual| over all cases [m]
  double noise_sigma_displacement{NAN}; // σ_D per coordinate [m]
  double reduced_chi2{NAN};             // χ² / (3 m − p) of the inliers
  bool covariance_inflated{false};      // std_dev scaled by √reduced_chi2 (residuals > noise)
  double condition_number{NAN};         // of the column-scaled weighted Jacobian at the solution
  /// Noise level the residuals show, relative to the stated one: √(median
  /// of |r|²/σ_D² / median of χ²₃); robust to a few outliers.
  double robust_noise_ratio{NAN};
  /// A case is an outlier if |r|/σ_D exceeds this (the χ²₃ bound, scaled
  /// up by robust_noise_ratio when that is above 1).
  double outlier_threshold{NAN};
  Eigen::VectorXd linear_start;         // exact linear least-squares stiffness [N·m/rad]
  int iterations{0};
  /// Largest |moment about joint i's axis| over the cases [N·m], and the
  /// largest lever of the target about it [m] (what the advice is built on).
  Eigen::VectorXd max_joint_torque;
  Eigen::VectorXd max_target_lever;
  /// kq-identify's exit 3 and Python's `flagged`: the fit did not converge, a
  /// joint is weakly or not determined, or outliers stayed in the fit.
  bool flagged() const {
    return status != FitStatus::kConverged || !not_determined.empty() || !weakly_identified.empty() ||
           outliers_in_fit;
  }
};

/// Identifies the diagonal joint stiffness K_q from load cases.
///
/// Steps: (i) joints the data cannot determine are found and held at the
/// prior (the model's stiffness). The model is linear in the relative
/// compliances x_i = c_i/c0_i, so the Fisher information BᵀB of x (B the
/// noise-weighted displacement per relative compliance) is the same
/// wherever it is evaluated. A joint is *not determined* only where that
/// information is numerically rank-deficient in it: an eigenvalue below
/// 1e-12 of the largest (singular values of B below 1e-6 of the largest,
/// rounding of an exact zero) whose eigenvector has a component above 1e-3
/// on the joint. That is either no sensitivity at all (I_ii ≈ 0: the joint
/// is not loaded, or the target does not move when it turns) or an exact
/// trade-off with other joints (only a combination is fixed); see
/// internal::AnalyseIdentifiability. Every other joint is fitted, however
/// weak its information; (ii) the exact linear least-squares start in x,
/// weighted by σ_D = √2·tracker_noise; (iii) Ceres solves the weighted
/// problem in θ_i = log(k_i/k0_i) (positivity), first with the optional
/// robust loss; (iv) outliers are flagged against the χ²(3) bound, and with
/// a robust loss the plain fit is repeated without them; a joint driven more
/// than 1000× away from the prior (the data ask for a negative compliance)
/// is held at the prior and the fit repeated: it is weakly determined with a
/// one-sided interval (a lower bound of k) if its unconstrained compliance
/// is within 1.96 σ of zero or above (the data are consistent with a rigid
/// joint), not determined otherwise (cases inconsistent with the model); (v) ceres::Covariance gives the covariance
/// of θ, scaled by χ²/dof when the residuals are clearly larger than the
/// stated noise. A fitted joint is "weakly determined" if σ(θ_i) exceeds
/// `weak_relative_std`, and `advice` names the cause: low sensitivity (its
/// σ with all other joints known is itself above that bound: which of load
/// moment and target lever is small), and/or a near trade-off (variance
/// inflation >= 2) with the joints it is most correlated with.
///
/// Numerical trouble is reported in the result's status, never thrown.
/// @param model  robot model; its joint stiffness is the prior and scale.
/// @param cases  load cases; absent load points and targets are the TCP.
/// @param progress  called with (cases evaluated, total) while the per-case
///   kinematics are evaluated.
/// @throws std::invalid_argument for invalid options, no cases, or a case
///   whose q has the wrong size or a non-finite value.
JointStiffnessResult IdentifyJointStiffness(const dynamics::RobotModel& model,
                                            const std::vector<LoadCase>& cases,
                                            const IdentificationOptions& options = {},
                                            const ProgressCallback& progress = {});

/// The fitted joints' stiffnesses with their covariance, as the parameters
/// kq<j>_Nm_per_rad on the inverse scale: the compliances 1/k, in which the
/// tracker model is linear, so that their estimate is Gaussian (the 95 %
/// intervals of the result are built the same way). Joints not determined
/// are left out (they kept the prior and have no finite variance).
/// @throws std::invalid_argument if no joint was determined.
dynamics::ParameterUncertainty StiffnessUncertainty(const JointStiffnessResult& result, const std::string& source);

/// Upper quantile of the χ² distribution with 3 degrees of freedom:
/// x with P(χ²₃ > x) = p, for 0 < p < 1.
double ChiSquare3UpperQuantile(double p);

}  // namespace robomach::identification
