#include "robomach/dynamics/frf_prediction.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "robomach/common/enum_names.h"
#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/robot_model.h"
#include "robomach/dynamics/tool_tip_frf.h"

namespace robomach::dynamics {

const char* ToString(ReceptanceMethod m) { return m == ReceptanceMethod::kDirect ? "direct" : "modal"; }

ReceptanceMethod ParseReceptanceMethod(const std::string& name) {
  constexpr ReceptanceMethod kAll[] = {ReceptanceMethod::kModal, ReceptanceMethod::kDirect};
  return ParseByName("method", name, kAll);
}

std::vector<Eigen::Matrix3cd> ReceptanceBy(ReceptanceMethod method, const PostureDynamics& dynamics,
                                           const Eigen::VectorXd& freq_hz) {
  return method == ReceptanceMethod::kDirect ? ReceptanceDirect(dynamics.system, freq_hz)
                                             : Receptance(dynamics, freq_hz);
}

void PredictOptions::Validate() const {
  if (method != ReceptanceMethod::kModal && method != ReceptanceMethod::kDirect) {
    throw OptionError("method", "method: expected modal (0) or direct (1), got " +
                                    std::to_string(static_cast<int>(method)));
  }
}

FrfPredictionResult PredictFrfs(const std::shared_ptr<const RobotModel>& model,
                                const std::vector<NamedPosture>& postures, const Eigen::VectorXd& freq_hz,
                                const PredictOptions& options) {
  options.Validate();
  for (Eigen::Index i = 0; i < freq_hz.size(); ++i) {
    if (!std::isfinite(freq_hz(i)) || freq_hz(i) < 0.0) {
      throw std::invalid_argument("freq_hz[" + std::to_string(i) + "] is not a finite frequency >= 0");
    }
  }
  FrfPredictionResult result;
  PostureEvaluator evaluator(model);
  const long total = static_cast<long>(postures.size());
  for (size_t p = 0; p < postures.size(); ++p) {
    const NamedPosture& pose = postures[p];
    PosturePredictionResult out;
    out.id = pose.id;
    out.dynamics = evaluator.Evaluate(pose.q);
    out.joints_outside_limits = model->chain().JointsOutsideLimits(pose.q);
    for (int j : out.joints_outside_limits) {
      const auto& lim = model->chain().limits()[j];
      std::ostringstream msg;
      msg << "posture " << pose.id << ": joint " << j + 1 << " at " << RadToDeg(pose.q(j))
          << " deg is outside its limits [" << RadToDeg(lim.lower) << ", " << RadToDeg(lim.upper) << "] deg";
      result.verdict.Flag(msg.str(), static_cast<int>(p));
    }
    if (out.dynamics.near_singular) {
      std::ostringstream msg;
      msg << "posture " << pose.id << " is near a singularity (condition number of J "
          << out.dynamics.jacobian_condition
          << "); the FRF is computed in joint space and stays valid, but the Cartesian M, K, C are not reported";
      result.verdict.Flag(msg.str(), static_cast<int>(p));
    }
    {
      int rigid = 0;
      for (const Mode& m : out.dynamics.modes) {
        if (!(m.freq_hz >= kMinPredictedModeHz)) ++rigid;
      }
      if (rigid > 0) {
        std::ostringstream msg;
        msg << "posture " << pose.id << ": " << rigid << " mode(s) at " << out.dynamics.modes.front().freq_hz
            << " Hz (below " << kMinPredictedModeHz
            << " Hz): the stiffness matrix is singular, a part of the model is held by no spring (an effect's "
               "stiffness made negligible, e.g. by a unit mistake in its config section); the FRF is that of a "
               "free body";
        result.verdict.Flag(msg.str(), static_cast<int>(p));
      }
    }
    out.H = ReceptanceBy(options.method, out.dynamics, freq_hz);
    for (const auto& h : out.H) {
      if (!h.allFinite()) throw std::runtime_error("non-finite receptance at posture " + pose.id);
    }
    result.postures.push_back(std::move(out));
    if (options.progress) options.progress(static_cast<long>(p + 1), total);
  }
  return result;
}

}  // namespace robomach::dynamics
