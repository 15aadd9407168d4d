#pragma once

// The kinds of joint controller drill-sim builds, tunes and reports, behind
// one interface and chosen by name in one place (as OMPL's planners are):
// a new kind is one class in controller_kinds.cc and one line in its list.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/named_registry.h"
#include "robomach/drilling/controllers.h"

namespace robomach::drilling {

struct ControllerParameters;

class ControllerKind {
 public:
  virtual ~ControllerKind() = default;
  /// The name on the command line and in files: "pid", "pd", "pd-tdc".
  virtual std::string name() const = 0;
  /// Gains found by TuneController on the default scenario (config/drilling/).
  virtual ControllerParameters defaults() const = 0;
  /// The name of ControllerParameters::third in summaries
  /// ("integral_ratio", "mbar_ratio"); empty when the kind has none.
  virtual std::string third_parameter() const = 0;
  /// Tuning bounds of `third` (only used when third_parameter() is not empty).
  virtual std::pair<double, double> third_bounds() const { return {1.0, 1.0}; }
  /// Builds the controller: per-joint effective inertia m_i = M_eff(i, i)
  /// [kg m²], control period [s], motor torque limits [N m].
  virtual std::unique_ptr<JointController> Make(const ControllerParameters& p, const Eigen::VectorXd& m,
                                                double control_period_s,
                                                const Eigen::VectorXd& torque_limit_Nm) const = 0;
  /// Whether the time-delay estimation stability condition
  /// ||I - M^-1 Mbar|| < 1 (TdeStabilityMeasure) applies.
  virtual bool uses_time_delay_estimation() const { return false; }
};

/// Every kind by name, in a fixed order (pid, pd, pd-tdc); the functions
/// below are this registry's.
const NamedRegistry<const ControllerKind*>& ControllerKindRegistry();

/// Every kind, in a fixed order (pid, pd, pd-tdc).
const std::vector<const ControllerKind*>& ControllerKinds();

/// "pid, pd or pd-tdc".
std::string ControllerKindList();

/// The kind called `name`. @throws std::invalid_argument "unknown controller
/// kind 'NAME': expected pid, pd or pd-tdc".
const ControllerKind& FindControllerKind(const std::string& name);

}  // namespace robomach::drilling
