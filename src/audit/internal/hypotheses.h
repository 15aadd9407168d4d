#pragma once

// The audit's hypotheses beyond the effect library (issue #33). Private to
// src/audit.
#include <optional>
#include <string>
#include <vector>

#include "audit/internal/candidate_fit.h"
#include "robomach/audit/model_audit.h"

namespace robomach::audit::internal {

/// kq1_Nm_per_rad … kqn_Nm_per_rad of the model.
std::vector<std::string> DefaultParameterCandidates(const dynamics::ParameterSet& p);

/// The calibrated model with `freed` model parameters free besides
/// `calibration` (a parameter hypothesis): a best-first scan of the freed
/// ones from `start`, the fit, its errors and BIC. Implausible when the fit
/// did not converge or a freed parameter ends on a bound.
CandidateResult FitParameterHypothesis(const dynamics::RobotDescription& desc, const dynamics::ParameterSet& start,
                                       const std::vector<std::string>& freed,
                                       const std::vector<std::string>& calibration, const FitContext& x);

/// Every virtual joint (virtual_joint_<place>_<axis>) the robot can take,
/// without those that turn about a joint's own axis and those in the model.
std::vector<std::string> VirtualJointNames(const dynamics::RobotDescription& desc);

/// The virtual-joint screen: each virtual joint added to the calibrated
/// model at stiffnesses a factor of 4 apart over its range; at each, the
/// whole-curve cost after the linearised (Gauss–Newton) re-adjustment of
/// the calibration parameters, |r − Q Qᵀ r|² with Q an orthonormal basis of
/// their sensitivity columns at the calibrated model. Best (lowest
/// predicted error) first. `*baseline`: the same measure for the calibrated
/// model without a virtual joint (rms whole-curve residual in noise units).
std::vector<ScreenedVirtualJoint> ScreenVirtualJoints(const dynamics::RobotDescription& desc,
                                                      const dynamics::ParameterSet& calibrated,
                                                      const std::vector<std::string>& calibration,
                                                      const FitContext& x, double* baseline);

/// What the parameter uncertainty allows (AuditResult::uncertainty, issue
/// #37 §4): the uncertain parameters of `u` (those the model has and the
/// audit does not calibrate) moved within their `confidence` region around
/// u's estimates, the calibrated model's whole-curve cost minimised there
/// by up to four Gauss–Newton steps constrained to the region (a trust-region
/// subproblem in the covariance's whitened coordinates, the calibration
/// parameters re-adjusted linearly as in the virtual-joint screen), then
/// the calibration refitted at the point and its errors computed.
/// `error_before` and `significance_factor` grade it. std::nullopt when no
/// parameter of `u` can move.
std::optional<UncertaintyAllowance> AllowanceOfUncertainty(const dynamics::RobotDescription& desc,
                                                           const dynamics::ParameterSet& calibrated,
                                                           const dynamics::ParameterUncertainty& u,
                                                           double confidence, const FitContext& x,
                                                           double error_before);

}  // namespace robomach::audit::internal
