#include "robomach/stability/lobe_uncertainty.h"

#include <cmath>
#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/stability/posture_stability.h"
#include "robomach/stability/tip_dynamics.h"
#include "robomach/stability/tool_tip_model.h"
#include "robomach/stability/zoa_lobes.h"

namespace robomach::stability {

Eigen::VectorXd ZoaCriticalDepths(const dynamics::RobotDescription& description, const dynamics::ParameterSet& parameters,
                                  const std::string& id, const Eigen::VectorXd& q, const Eigen::Vector3d& feed_B,
                                  const LobesOptions& options) {
  ZoaOptions zo;
  zo.max_lobe_index = options.max_lobe_index;
  zo.min_spindle_speed_rad_s = options.min_speed_rad_s;
  dynamics::PostureOptions po;
  po.cartesian = false;
  po.jacobian_condition = false;
  const auto model = dynamics::RobotModel::Build(description, parameters);
  const TipDynamics tip = TipFromPosture(id, dynamics::EvaluatePosture(model, q, po), feed_B, options.process.teeth,
                                         options.max_speed_rad_s);
  const std::vector<LobePoint> points =
      ComputeZoaLobes(tip.freq_hz, tip.Phi_C, options.process, zo).At(options.zoa_speeds_rad_s);
  Eigen::VectorXd d(static_cast<Eigen::Index>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) {
    d(static_cast<Eigen::Index>(i)) = points[i].status == LobeStatus::kOk ? points[i].critical_depth : NAN;
  }
  return d;
}

ZoaBand ZoaLobeBand(const dynamics::RobotDescription& description, const dynamics::ParameterSet& base,
                    const std::string& id, const Eigen::VectorXd& q, const Eigen::Vector3d& feed_B,
                    const LobesOptions& options, const dynamics::ParameterUncertainty& u,
                    const dynamics::PropagationOptions& propagation) {
  // The critical depth at every speed [m], NaN where there is no boundary.
  auto depths = [&](const Eigen::VectorXd& values) {
    return ZoaCriticalDepths(description, dynamics::WithValues(base, u, values), id, q, feed_B, options);
  };
  Eigen::VectorXd at_estimates(static_cast<Eigen::Index>(u.parameters.size()));
  for (size_t i = 0; i < u.parameters.size(); ++i) at_estimates(static_cast<Eigen::Index>(i)) = u.parameters[i].value;
  const Eigen::VectorXd d0 = depths(at_estimates);
  std::vector<Eigen::Index> kept;  // the speeds with a boundary at the estimates
  for (Eigen::Index i = 0; i < d0.size(); ++i) {
    if (std::isfinite(d0(i))) kept.push_back(i);
  }
  if (kept.empty()) throw std::invalid_argument("tool tip " + id + ": the ZOA lobes have no boundary at any speed");
  // Outputs: the smallest depth first, then each kept speed's depth.
  auto outputs = [&](const Eigen::VectorXd& values) {
    const Eigen::VectorXd d = depths(values);
    Eigen::VectorXd out(static_cast<Eigen::Index>(kept.size()) + 1);
    for (size_t k = 0; k < kept.size(); ++k) out(static_cast<Eigen::Index>(k) + 1) = d(kept[k]);  // NaN: failed sample
    out(0) = out.tail(static_cast<Eigen::Index>(kept.size())).minCoeff();
    return out;
  };
  std::vector<std::string> names{"the smallest critical depth"};
  for (Eigen::Index i : kept) {
    names.push_back("the critical depth at " +
                    std::to_string(std::lround(RadPerSecToRpm(options.zoa_speeds_rad_s(i)))) + " rpm");
  }
  ZoaBand band;
  band.id = id;
  band.speed_rad_s = options.zoa_speeds_rad_s;
  band.propagation = dynamics::Propagate(u, outputs, propagation, names);
  band.min_depth = band.propagation.outputs[0];
  dynamics::OutputInterval none;
  none.value = none.std_dev = none.lower = none.upper = NAN;
  band.depth.assign(static_cast<size_t>(d0.size()), none);
  for (size_t k = 0; k < kept.size(); ++k) band.depth[static_cast<size_t>(kept[k])] = band.propagation.outputs[k + 1];
  return band;
}

MapDepthIntervals StabilityMapIntervals(const dynamics::RobotDescription& description,
                                        const dynamics::ParameterSet& base,
                                        const std::vector<ToolPoseTarget>& targets,
                                        const std::vector<MapPoint>& points, const MillingProcess& process,
                                        const PostureStabilityOptions& analysis,
                                        const dynamics::ParameterUncertainty& u,
                                        const dynamics::PropagationOptions& propagation, int threads,
                                        const ProgressCallback& progress) {
  if (targets.size() != points.size()) throw std::invalid_argument("StabilityMapIntervals: one point per target");
  dynamics::CheckValid(u);
  dynamics::CheckValid(propagation);
  MapDepthIntervals out;
  dynamics::OutputInterval none;
  none.value = none.std_dev = none.lower = none.upper = NAN;
  out.depth.assign(points.size(), none);
  std::vector<dynamics::PropagationResult> how(points.size());
  std::vector<char> done(points.size(), 0);
  dynamics::PostureOptions po;
  po.cartesian = false;
  po.jacobian_condition = false;
  std::atomic<size_t> next{0};
  std::atomic<long> finished{0};
  std::mutex error_mutex;
  std::string error;
  auto work = [&] {
    for (size_t i = next++; i < points.size(); i = next++) {
      const MapPoint& p = points[i];
      const bool analysed = (p.status == PointStatus::kOk || p.status == PointStatus::kNearSingular) &&
                            std::isfinite(p.stability.critical_depth);
      if (analysed) {
        const Eigen::Matrix3d R = CuttingFrameAtPosture(targets[i].Pose(p.rotation), targets[i].feed_B);
        auto depth = [&](const Eigen::VectorXd& values) {
          const auto model = dynamics::RobotModel::Build(description, dynamics::WithValues(base, u, values));
          const PostureStability s = AnalysePosture(dynamics::EvaluatePosture(model, p.q, po), R, process, analysis);
          return Eigen::VectorXd::Constant(1, s.critical_depth);
        };
        try {
          how[i] = dynamics::Propagate(u, depth, propagation, {"the critical depth"});
          out.depth[i] = how[i].outputs[0];
          done[i] = 1;
        } catch (const std::exception& e) {
          const std::lock_guard<std::mutex> lock(error_mutex);
          if (error.empty()) error = "point " + std::to_string(i) + ": " + e.what();
        }
      }
      ++finished;
    }
  };
  const int n_threads = std::max(1, threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency()));
  // Workers take points in turn; the calling thread reports progress.
  std::vector<std::thread> pool;
  for (int t = 0; t < n_threads; ++t) pool.emplace_back(work);
  const long total = static_cast<long>(points.size());
  while (finished < total) {
    if (progress) progress(finished, total);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  for (auto& t : pool) t.join();
  if (progress) progress(total, total);
  if (!error.empty()) throw std::invalid_argument(error);
  for (size_t i = 0; i < points.size(); ++i) {
    if (!done[i]) continue;
    out.evaluations += how[i].evaluations;
    if (how[i].method_used == dynamics::PropagationMethod::kMonteCarlo) {
      if (out.monte_carlo++ == 0) out.example_reason = how[i].reason;
    } else {
      if (out.first_order++ == 0 && out.example_reason.empty()) out.example_reason = how[i].reason;
    }
  }
  return out;
}

}  // namespace robomach::stability
