#include "robomach/dynamics/joint_plausibility.h"

#include <cmath>
#include <exception>

#include "robomach/common/number_format.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/gravity_torque.h"
#include "robomach/dynamics/posture_dynamics.h"

namespace robomach::dynamics {
namespace {

// The largest weight each joint holds: |G(q)|, and each joint swept through
// its range (9 angles, the others at q), so that the arm is near horizontal
// once (RNE, microseconds each). Zero when it cannot be computed: the sag is
// then unjudged, not the frequencies.
Eigen::VectorXd LargestGravityTorque(const RobotModel& model, const kinematics::SerialChain& arm,
                                     const Eigen::VectorXd& q) {
  const int n = arm.num_joints();
  try {
    Eigen::VectorXd gravity_torque = GravityTorque(model, q).cwiseAbs();
    for (int i = 0; i < n; ++i) {
      const auto& lim = arm.limits()[i];
      const double lo = lim.bounded ? lim.lower : -kPi, hi = lim.bounded ? lim.upper : kPi;
      for (int s = 0; s <= 8; ++s) {
        Eigen::VectorXd qs = q;
        qs(i) = lo + (hi - lo) * s / 8.0;
        gravity_torque = gravity_torque.cwiseMax(GravityTorque(model, qs).cwiseAbs());
      }
    }
    return gravity_torque;
  } catch (const std::exception&) {
    return Eigen::VectorXd::Zero(n);
  }
}

// Whole hertz from 10 Hz up (7895 Hz, not 7.9e+03), 3 digits below.
std::string Hz(double f) { return f >= 10.0 ? std::to_string(std::lround(f)) : FormatNumber(f, 3); }

}  // namespace

std::vector<std::string> JointPlausibilityFindings(const RobotDescription& description,
                                                   const ParameterSet& parameters, const JointValueLocations& where) {
  const kinematics::SerialChain& arm = description.arm;
  const int n = arm.num_joints();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  for (int j = 0; j < n; ++j) {
    const auto& lim = arm.limits()[j];
    if (lim.bounded && (lim.lower > 0.0 || lim.upper < 0.0)) q(j) = 0.5 * (lim.lower + lim.upper);
  }
  Eigen::MatrixXd M;
  double alpha = 0.0, beta = 0.0;
  Eigen::VectorXd k(n), gravity_torque;
  try {
    const auto model = RobotModel::Build(description, parameters);
    M = EvaluatePosture(model, q).M_q();
    gravity_torque = LargestGravityTorque(*model, arm, q);
    for (int j = 0; j < n; ++j) k(j) = model->joint_stiffness()(j);
    alpha = model->alpha();
    beta = model->beta();
  } catch (const std::exception&) {
    return {};  // a model that does not build is reported by the tool that builds it
  }
  // Where joint j's stiffness was typed (the description's source when not given).
  const auto kq_at = [&](int j) {
    return static_cast<size_t>(j) < where.joint_stiffness.size() ? where.joint_stiffness[j].ToString()
                                                                 : description.source;
  };
  std::vector<std::string> findings;
  const bool have_damping = alpha > 0.0 || beta > 0.0;
  bool frequency_found = false;
  double zeta_max = 0.0;
  int zeta_joint = -1;
  for (int j = 0; j < n; ++j) {
    if (!(M(j, j) > 0.0)) continue;
    const double w = std::sqrt(k(j) / M(j, j));
    const double f_hz = w / (2.0 * kPi);
    if (f_hz < kMinPlausibleJointFrequencyHz || f_hz > kMaxPlausibleJointFrequencyHz) {
      const bool low = f_hz < kMinPlausibleJointFrequencyHz;
      frequency_found = true;
      findings.push_back(
          "implausible (unit mistake?): " + kq_at(j) + ": joint " + std::to_string(j + 1) +
          " (" + arm.joint_names()[j] + "): its stiffness " + FormatDouble(k(j)) + " N·m/rad on the inertia " +
          FormatNumber(M(j, j), 4) + " kg·m² it moves at q = 0 makes a joint frequency sqrt(kq/M)/2pi of " +
          Hz(f_hz) + " Hz, outside the " + FormatNumber(kMinPlausibleJointFrequencyHz, 4) +
          " to " + FormatNumber(kMaxPlausibleJointFrequencyHz, 4) + " Hz of robots: " +
          (low ? "a stiffness in kN·m/rad, or masses in g (x1000)?" : "a stiffness in N·mm/rad (x1000)?"));
    }
    if (have_damping) {
      const double zeta = 0.5 * (alpha * w + beta / w);
      if (zeta > zeta_max) {
        zeta_max = zeta;
        zeta_joint = j;
      }
    }
  }
  // The robot's own weight against the stiffness: a stiffness per degree
  // (/57.3) keeps the joint frequencies in range but turns the joints by
  // degrees (docs/plausibility.md).
  if (!frequency_found) {
    int worst = -1;
    double worst_sag = 0.0;
    for (int j = 0; j < n; ++j) {
      const double sag = k(j) > 0.0 ? gravity_torque(j) / k(j) : 0.0;
      if (sag > worst_sag) {
        worst_sag = sag;
        worst = j;
      }
    }
    if (worst >= 0 && worst_sag > kMaxPlausibleGravitySagRad) {
      frequency_found = true;
      const double deg = worst_sag * 180.0 / kPi;
      findings.push_back(
          "implausible (unit mistake?): " + kq_at(worst) + ": joint " +
          std::to_string(worst + 1) + " (" + arm.joint_names()[worst] + "): the robot's own weight (" +
          FormatNumber(gravity_torque(worst), 4) + " N·m at most, the joints swept through their limits) "
          "turns it by " +
          FormatNumber(deg, 3) + " deg against its stiffness " + FormatDouble(k(worst)) +
          " N·m/rad; robot gearboxes turn by a few arc-minutes under their rated torque (plausible up to " +
          FormatNumber(kMaxPlausibleGravitySagRad * 180.0 / kPi, 3) +
          " deg): a stiffness per degree typed in the N·m/rad field (N·m/rad = N·m/deg x 57.3: " +
          FormatNumber(k(worst) * 180.0 / kPi, 5) + "), or a stiffness in kN·m/rad (x1000)?");
    }
  }
  // A joint frequency off by 31.6 explains any damping ratio: say it once.
  if (!frequency_found && zeta_joint >= 0 && zeta_max > kMaxPlausibleDampingRatio) {
    const double w = std::sqrt(k(zeta_joint) / M(zeta_joint, zeta_joint));
    const bool alpha_term = alpha * w > beta / w;
    findings.push_back(
        "implausible (unit mistake?): " + where.damping.ToString() + ": damping: alpha_s " +
        FormatDouble(alpha) + " s and beta_per_s " + FormatDouble(beta) + " /s give joint " +
        std::to_string(zeta_joint + 1) + " a damping ratio of " + FormatNumber(zeta_max, 3) +
        " at its frequency " + Hz(w / (2.0 * kPi)) + " Hz, more than the " +
        FormatNumber(kMaxPlausibleDampingRatio, 3) + " robots have (0.01 to 0.1 measured): " +
        (alpha_term ? "alpha_s in ms typed in the s field?" : "beta_per_s 1000 times too large?"));
  }
  return findings;
}

}  // namespace robomach::dynamics
