#include "robomach/drilling/controller_kinds.h"

#include "robomach/drilling/drilling_sim.h"

namespace robomach::drilling {
namespace {

// The gain laws of ControllerParameters (drilling_sim.h): per joint,
//   pid:    kp = m w², kd = 2 zeta m w, ki = kp w / r
//   pd:     kp = m w², kd = 2 zeta m w
//   pd-tdc: kp = w², kd = 2 zeta w, Mbar = alpha m
// Defaults: drill-sim --tune (30 simulations each) on config/drilling/
// (planar3r, drill_5mm, q235), rounded to 3 digits; pd takes pid's w and zeta.
class PidKind final : public ControllerKind {
 public:
  explicit PidKind(bool integral) : integral_(integral) {}
  std::string name() const override { return integral_ ? "pid" : "pd"; }
  ControllerParameters defaults() const override {
    return integral_ ? ControllerParameters{"pid", 70.6, 1.06, 3.91, 0.005}
                     : ControllerParameters{"pd", 70.6, 1.06, 0.0, 0.005};
  }
  std::string third_parameter() const override { return integral_ ? "integral_ratio" : ""; }
  std::pair<double, double> third_bounds() const override { return {1.0, 100.0}; }
  std::unique_ptr<JointController> Make(const ControllerParameters& p, const Eigen::VectorXd& m, double L,
                                        const Eigen::VectorXd& limit) const override {
    PidGains g;
    g.kp = m * p.omega * p.omega;
    g.kd = m * 2.0 * p.zeta * p.omega;
    g.ki = integral_ ? Eigen::VectorXd(g.kp * p.omega / p.third) : Eigen::VectorXd::Zero(m.size());
    g.derivative_filter_time_constant = p.filter_time_constant;
    return std::make_unique<PidController>(g, limit, L);
  }

 private:
  bool integral_;
};

class PdTdcKind final : public ControllerKind {
 public:
  std::string name() const override { return "pd-tdc"; }
  ControllerParameters defaults() const override { return {"pd-tdc", 37.0, 0.506, 0.438, 0.005}; }
  std::string third_parameter() const override { return "mbar_ratio"; }
  // alpha < 2: the TDE condition for a diagonal Mbar.
  std::pair<double, double> third_bounds() const override { return {0.01, 1.95}; }
  std::unique_ptr<JointController> Make(const ControllerParameters& p, const Eigen::VectorXd& m, double L,
                                        const Eigen::VectorXd& limit) const override {
    const Eigen::Index n = m.size();
    PdTdcGains g;
    g.kp = Eigen::VectorXd::Constant(n, p.omega * p.omega);
    g.kd = Eigen::VectorXd::Constant(n, 2.0 * p.zeta * p.omega);
    g.mbar = m * p.third;
    g.accel_filter_time_constant = p.filter_time_constant;
    return std::make_unique<PdTdcController>(g, limit, L);
  }
  bool uses_time_delay_estimation() const override { return true; }
};

}  // namespace

const NamedRegistry<const ControllerKind*>& ControllerKindRegistry() {
  static const PidKind pid(true), pd(false);
  static const PdTdcKind pd_tdc;
  static const NamedRegistry<const ControllerKind*> registry = [] {
    NamedRegistry<const ControllerKind*> r("unknown controller kind");
    r.Add(pid.name(), &pid).Add(pd.name(), &pd).Add(pd_tdc.name(), &pd_tdc);
    return r;
  }();
  return registry;
}

const std::vector<const ControllerKind*>& ControllerKinds() {
  static const std::vector<const ControllerKind*> kinds = ControllerKindRegistry().Values();
  return kinds;
}

std::string ControllerKindList() { return ControllerKindRegistry().NameList(); }

const ControllerKind& FindControllerKind(const std::string& name) { return *ControllerKindRegistry().Find(name); }

}  // namespace robomach::drilling
