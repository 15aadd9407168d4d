#include "robomach/stability/lobe_uncertainty.h"

#include <cmath>
#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/stability/posture_stability.h"
#include "robomach/stability/tip_dynamics.h"
#include "robomach/stability/tool_tip_model.h"
#include "robomach/stability/zoa_lobes.h"

namespace robomach::stability {

namespace {

// The ZOA lobes' points at options.zoa_speeds_rad_s (ZoaCriticalDepths),
// with the posture's dynamics and cutting frame they came from.
struct ZoaPoints {
  dynamics::PostureDynamics d;
  Eigen::Matrix3d R_BC;
  std::vector<LobePoint> points;
};

ZoaPoints ZoaPointsAt(const dynamics::RobotDescription& description, const dynamics::ParameterSet& parameters,
                      const std::string& id, const Eigen::VectorXd& q, const Eigen::Vector3d& feed_B,
                      const LobesOptions& options) {
  ZoaOptions zo;
  zo.max_lobe_index = options.max_lobe_index;
  zo.min_spindle_speed_rad_s = options.min_speed_rad_s;
  dynamics::PostureOptions po;
  po.cartesian = false;
  po.jacobian_condition = false;
  const auto model = dynamics::RobotModel::Build(description, parameters);
  ZoaPoints out;
  out.d = dynamics::EvaluatePosture(model, q, po);
  const TipDynamics tip = TipFromPosture(id, out.d, feed_B, options.process.teeth, options.max_speed_rad_s);
  out.R_BC = tip.R_BC;
  out.points = ComputeZoaLobes(tip.freq_hz, tip.Phi_C, options.process, zo).At(options.zoa_speeds_rad_s);
  return out;
}

}  // namespace

Eigen::VectorXd ZoaCriticalDepths(const dynamics::RobotDescription& description, const dynamics::ParameterSet& parameters,
                                  const std::string& id, const Eigen::VectorXd& q, const Eigen::Vector3d& feed_B,
                                  const LobesOptions& options) {
  const std::vector<LobePoint> points = ZoaPointsAt(description, parameters, id, q, feed_B, options).points;
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
  const ZoaPoints zoa0 =
      ZoaPointsAt(description, dynamics::WithValues(base, u, at_estimates), id, q, feed_B, options);
  Eigen::VectorXd d0(static_cast<Eigen::Index>(zoa0.points.size()));
  std::vector<Eigen::Index> kept;  // the speeds with a boundary at the estimates
  for (size_t i = 0; i < zoa0.points.size(); ++i) {
    const bool ok = zoa0.points[i].status == LobeStatus::kOk;
    d0(static_cast<Eigen::Index>(i)) = ok ? zoa0.points[i].critical_depth : NAN;
    if (ok) kept.push_back(static_cast<Eigen::Index>(i));
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
  // The first-order derivatives from each speed's lobe continued exactly
  // (ZoaLobeContinuation): the grid's lines move with the modes, and the
  // differences of `outputs` at 1e-3 sigma see that motion (on the demo
  // posture the first-order band's width jumped by up to 30 % from one
  // speed to the next). The smallest depth's derivative is that at the
  // speed of the smallest depth at the estimates. A speed whose lobe is not
  // found again is NaN here, and Propagate takes that output's own
  // differences (its reason says how many).
  std::vector<ZoaLobeContinuation> lobes;
  Eigen::Index smallest = 0;
  for (size_t k = 0; k < kept.size(); ++k) {
    lobes.emplace_back(zoa0.d, zoa0.R_BC, options.process, zoa0.points[static_cast<size_t>(kept[k])]);
    if (d0(kept[k]) < d0(kept[static_cast<size_t>(smallest)])) smallest = static_cast<Eigen::Index>(k);
  }
  dynamics::PostureOptions po;
  po.cartesian = false;
  po.jacobian_condition = false;
  auto local = [&](const Eigen::VectorXd& values) {
    const dynamics::PostureDynamics d = dynamics::EvaluatePosture(
        dynamics::RobotModel::Build(description, dynamics::WithValues(base, u, values)), q, po);
    const TipModalModel modes = ModalModelFromPosture(d);
    Eigen::VectorXd out(static_cast<Eigen::Index>(kept.size()) + 1);
    for (size_t k = 0; k < kept.size(); ++k) {
      out(static_cast<Eigen::Index>(k) + 1) = lobes[k].ok() ? lobes[k](d, modes) : NAN;
    }
    out(0) = out(smallest + 1);
    return out;
  };
  ZoaBand band;
  band.id = id;
  band.speed_rad_s = options.zoa_speeds_rad_s;
  band.propagation = dynamics::Propagate(u, outputs, propagation, names, local);
  if (band.propagation.method_used == dynamics::PropagationMethod::kFirstOrder) {
    band.propagation.reason += band.propagation.linearised
                                   ? "; derivatives from each speed's lobe continued exactly"
                                   : "; derivatives from each speed's lobe continued exactly where it was found again";
  }
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
  propagation.Validate();
  MapDepthIntervals out;
  dynamics::OutputInterval none;
  none.value = none.std_dev = none.lower = none.upper = NAN;
  out.depth.assign(points.size(), none);
  std::vector<dynamics::PropagationResult> how(points.size());
  std::vector<char> done(points.size(), 0), local_used(points.size(), 0);
  const bool first_order = propagation.method == dynamics::PropagationMethod::kFirstOrder;
  Eigen::VectorXd estimates(static_cast<Eigen::Index>(u.parameters.size()));
  bool base_is_estimate = true;
  for (size_t k = 0; k < u.parameters.size(); ++k) {
    estimates(static_cast<Eigen::Index>(k)) = u.parameters[k].value;
    base_is_estimate = base_is_estimate && base.Get(u.parameters[k].name) == u.parameters[k].value;
  }
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
        auto dynamics_at = [&](const Eigen::VectorXd& values) {
          return dynamics::EvaluatePosture(
              dynamics::RobotModel::Build(description, dynamics::WithValues(base, u, values)), p.q, po);
        };
        auto depth = [&](const Eigen::VectorXd& values) {
          const PostureStability s = AnalysePosture(dynamics_at(values), R, process, analysis);
          return Eigen::VectorXd::Constant(1, s.critical_depth);
        };
        try {
          // The derivatives from the local model of the critical depth
          // (LocalCriticalDepth), not from differences of repeated analyses
          // (noise from the search's tolerance and the lines that move with
          // the modes). Its analysis is the map's where the map's model is
          // the estimates' (the local model checks that it reproduces it),
          // else one at the estimates. Forced first order: the local model
          // is the output (forward differences, no analysis at all); auto:
          // it gives the derivatives, the analyses the sigma points.
          std::optional<LocalCriticalDepth> local;
          if (propagation.method != dynamics::PropagationMethod::kMonteCarlo) {
            const dynamics::PostureDynamics d0 = dynamics_at(estimates);
            if (base_is_estimate) local.emplace(d0, R, process, analysis, p.stability);
            if (!local || !local->usable()) {
              local.emplace(d0, R, process, analysis, AnalysePosture(d0, R, process, analysis));
            }
          }
          const bool usable = local && local->usable();
          auto local_depth = [&](const Eigen::VectorXd& values) {
            return Eigen::VectorXd::Constant(1, (*local)(dynamics_at(values)));
          };
          dynamics::PropagationOptions forward = propagation;
          forward.central_differences = false;  // the local model is smooth at the step (1e-3 sigma)
          bool used_local = false;
          bool lost_step = false;
          if (usable && first_order) {
            try {
              how[i] = dynamics::Propagate(u, local_depth, forward, {"the critical depth"});
              used_local = std::isfinite(how[i].outputs[0].std_dev);
            } catch (const std::invalid_argument&) {
              used_local = false;  // the local model's value was not finite
            }
            lost_step = !used_local;
          }
          if (!used_local) {
            // Auto (the local model gives the derivatives), Monte Carlo, or
            // a local model that did not reach every step of forced first
            // order (repeated analyses then).
            const bool linearise = usable && !first_order;
            how[i] = dynamics::Propagate(u, depth, linearise ? forward : propagation, {"the critical depth"},
                                         linearise ? dynamics::OutputFunction(local_depth) : dynamics::OutputFunction());
            used_local = how[i].linearised;
          }
          if (used_local) {
            how[i].reason += "; derivatives from the rightmost eigenvalue's sensitivity and the lobe at the best speed";
          } else if (local && !local->usable() && how[i].method_used == dynamics::PropagationMethod::kFirstOrder) {
            how[i].reason += "; derivatives from repeated analyses: " + local->why_not();
          } else if (lost_step) {
            how[i].reason += "; derivatives from repeated analyses: the local model lost the lobe at the best speed "
                             "at a step";
          }
          local_used[i] = used_local;
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
    out.local_model += local_used[i];
    if (how[i].method_used == dynamics::PropagationMethod::kMonteCarlo) {
      if (out.monte_carlo++ == 0) out.example_reason = how[i].reason;
    } else {
      if (out.first_order++ == 0 && out.example_reason.empty()) out.example_reason = how[i].reason;
    }
  }
  return out;
}

}  // namespace robomach::stability
