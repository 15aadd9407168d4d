#include "robomach/stability/stability_map.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <sstream>
#include <stdexcept>

#include <nlopt.hpp>

#include "robomach/common/option_validate.h"
#include "robomach/common/parallel.h"
#include "robomach/common/enum_names.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/kinematics/inverse_kinematics.h"
#include "robomach/kinematics/serial_chain.h"
#include "robomach/stability/tool_tip_model.h"

namespace robomach::stability {

const char* ToString(PointStatus s) {
  switch (s) {
    case PointStatus::kOk: return "ok";
    case PointStatus::kUnreachable: return "unreachable";
    case PointStatus::kJointLimits: return "joint_limits";
    case PointStatus::kNearSingular: return "near_singular";
    case PointStatus::kOtherConfiguration: return "other_configuration";
  }
  return "?";
}

PointStatus ParsePointStatus(const std::string& name) {
  constexpr PointStatus kAll[] = {PointStatus::kOk, PointStatus::kUnreachable, PointStatus::kJointLimits,
                                  PointStatus::kNearSingular, PointStatus::kOtherConfiguration};
  return ParseByName("point status", name, kAll);
}

Eigen::Isometry3d ToolPoseTarget::Pose(double rotation) const {
  const Eigen::Vector3d z = z_T.normalized();
  const Eigen::Vector3d x0 = (x_ref - x_ref.dot(z) * z).normalized();
  const Eigen::Vector3d x = std::cos(rotation) * x0 + std::sin(rotation) * z.cross(x0);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear().col(0) = x;
  X.linear().col(1) = z.cross(x);
  X.linear().col(2) = z;
  X.translation() = p_BT;
  return X;
}

namespace {

// IK: kinematics::IkSolver with its default tolerances (1e-5 m and 1e-4
// rad), well below what matters for the dynamics (the stiffness changes on
// the scale of centimetres and degrees).
using kinematics::IkSolver;

// KDL::Joint caches its last pose in mutable members (kdl/joint.hpp,
// `mutable Frame joint_pose; mutable double q_previous;`), so two threads
// evaluating the same KDL::Chain race and can get each other's joint
// frames. Every thread therefore works on its own copy of the model,
// rebuilt from the same description and parameters (identical numbers,
// separate KDL chains).
std::shared_ptr<const dynamics::RobotModel> PrivateCopy(const dynamics::RobotModel& model) {
  return dynamics::RobotModel::Build(model.description(), model.parameters());
}

struct Worker {
  explicit Worker(const dynamics::RobotModel& shared)
      : model(PrivateCopy(shared)), ik(model->chain()), evaluator(model) {}
  std::shared_ptr<const dynamics::RobotModel> model;
  IkSolver ik;
  dynamics::PostureEvaluator evaluator;
};

}  // namespace

namespace {

// What the stages of EvaluateStabilityMap share: the grid of targets, the
// process and options, and the points being filled in (references to the
// caller's arguments and locals, which outlive the stages).
struct MapGrid {
  const std::vector<ToolPoseTarget>& targets;
  int rows;
  int cols;
  const MillingProcess& process;
  const MapOptions& options;
  const kinematics::SerialChain& chain;  // the shared model's: its joint limits only
  int n;                                 // joints
  double rot0;                           // the rotation every point starts from
  std::vector<MapPoint>& out;            // row-major, rows x cols
};

// The arguments' checks (a robot of n joints), before any work.
void CheckMapArguments(int n, size_t targets, int rows, int cols, const MapOptions& options) {
  if (rows < 1 || cols < 1 || static_cast<size_t>(rows) * cols != targets) {
    throw std::invalid_argument("stability map: rows x cols must equal the number of targets");
  }
  if (options.seed_q.size() != n) {
    throw std::invalid_argument("stability map: the seed posture has " +
                                std::to_string(options.seed_q.size()) + " joints, the robot " +
                                std::to_string(n));
  }
  options.Validate();
}

// The rotation search's coarse scan (OptimiseRotation): the depth is not
// unimodal in the rotation.
constexpr int kRotationScan = 7;

// IK of point i at rot0 from `seed`, with its status; false if unreachable.
bool IkPoint(const MapGrid& g, IkSolver& ik, long i, const Eigen::VectorXd& seed) {
  MapPoint& p = g.out[i];
  p.rotation = g.rot0;
  Eigen::VectorXd q;
  const bool reached = ik.Solve(g.targets[i].Pose(g.rot0), seed, &q);
  p.q = q;
  if (!reached) {
    p.status = PointStatus::kUnreachable;
  } else if (!g.chain.JointsOutsideLimits(q).empty()) {
    p.status = PointStatus::kJointLimits;
  } else if (g.n >= 5 && q(4) * g.options.seed_q(4) < 0.0) {
    // The sign of the wrist bend q5 tells the wrist configuration.
    p.status = PointStatus::kOtherConfiguration;
  } else {
    p.status = PointStatus::kOk;
  }
  return p.status != PointStatus::kUnreachable;
}

// Every point's IK posture and status into g.out: the first column
// top-down from the seed, then the rows in parallel, each from the posture
// of its first point (each row continues from its last solved point).
void SolveIk(const MapGrid& g, const dynamics::RobotModel& model, int threads) {
  const int rows = g.rows, cols = g.cols;
  {
    IkSolver ik(g.chain);
    Eigen::VectorXd seed = g.options.seed_q;
    for (int r = 0; r < rows; ++r) {
      if (IkPoint(g, ik, static_cast<long>(r) * cols, seed) &&
          g.out[static_cast<long>(r) * cols].status == PointStatus::kOk) {
        seed = g.out[static_cast<long>(r) * cols].q;
      }
    }
  }
  // Rows in parallel, each from its first point (one IK solver per thread,
  // each on its own copy of the chain).
  const int t_ik = std::min(threads, rows);
  std::vector<std::shared_ptr<const dynamics::RobotModel>> copies;
  std::vector<std::unique_ptr<IkSolver>> solvers;
  for (int t = 0; t < t_ik; ++t) {
    copies.push_back(PrivateCopy(model));
    solvers.push_back(std::make_unique<IkSolver>(copies.back()->chain()));
  }
  ParallelForOptions po;
  po.threads = t_ik;
  po.chunk_size = 1;
  ParallelFor(
      0, rows,
      [&](long r, int t) {
        const long first = r * cols;
        Eigen::VectorXd seed = g.out[first].status == PointStatus::kOk ? g.out[first].q : g.options.seed_q;
        for (int c = 1; c < cols; ++c) {
          if (IkPoint(g, *solvers[t], first + c, seed) && g.out[first + c].status == PointStatus::kOk) {
            seed = g.out[first + c].q;
          }
        }
      },
      po);
}

// The stability of point i at posture q and tool rotation `rotation` into
// *s and cond(J) into *cond; returns whether the posture is near singular.
bool EvaluateAt(const MapGrid& g, Worker& w, long i, const Eigen::VectorXd& q, double rotation,
                PostureStability* s, double* cond) {
  const dynamics::PostureDynamics d = w.evaluator.Evaluate(q, dynamics::PostureOptions{false, true});
  *cond = d.jacobian_condition;
  *s = AnalysePosture(d, CuttingFrameAtPosture(g.targets[i].Pose(rotation), g.targets[i].feed_B), g.process,
                      g.options.analysis);
  return d.near_singular;
}

// The tool rotation of point i with the deepest critical depth in
// [rotation_min, rotation_max]: a coarse scan, then NLopt around its best.
// A better rotation replaces the point's posture, stability and condition,
// and *singular with its own.
void OptimiseRotation(const MapGrid& g, Worker& w, long i, bool* singular) {
  const MapOptions& options = g.options;
  MapPoint& p = g.out[i];
  const Eigen::VectorXd q_start = p.q;
  auto depth_at = [&](double rot, Eigen::VectorXd* q_out, PostureStability* s, double* cond,
                      bool* sing) -> double {
    Eigen::VectorXd q;
    if (!w.ik.Solve(g.targets[i].Pose(rot), q_start, &q)) return 0.0;
    if (!g.chain.JointsOutsideLimits(q).empty()) return 0.0;
    *sing = EvaluateAt(g, w, i, q, rot, s, cond);
    *q_out = q;
    return std::isfinite(s->critical_depth) ? s->critical_depth : 0.0;
  };
  double best = std::isfinite(p.stability.critical_depth) ? p.stability.critical_depth : 0.0;
  double best_rot = p.rotation;
  auto consider = [&](double rot) {
    Eigen::VectorXd q;
    PostureStability s;
    double cond = NAN;
    bool sing = false;
    const double v = depth_at(rot, &q, &s, &cond, &sing);
    if (v > best) {
      best = v;
      best_rot = rot;
      p.q = q;
      p.stability = s;
      p.jacobian_condition = cond;
      *singular = sing;
    }
    return v;
  };
  constexpr int kScan = kRotationScan;
  for (int j = 0; j < kScan; ++j) {
    consider(options.rotation_min + (options.rotation_max - options.rotation_min) * j / (kScan - 1));
  }
  // Local refinement with NLopt around the best scan point.
  nlopt::opt opt(nlopt::LN_COBYLA, 1);
  const double h = (options.rotation_max - options.rotation_min) / (kScan - 1);
  opt.set_lower_bounds(std::max(options.rotation_min, best_rot - h));
  opt.set_upper_bounds(std::min(options.rotation_max, best_rot + h));
  opt.set_maxeval(std::max(1, options.rotation_evaluations - kScan));
  opt.set_xtol_abs(1e-3);
  opt.set_initial_step(0.25 * h);
  // An exception in the objective is kept and rethrown after the run, as
  // in the scan above: NLopt's wrapper would report it as a generic
  // "nlopt failure" status.
  struct Objective {
    decltype(consider)* f;
    std::exception_ptr error;
  } objective{&consider, nullptr};
  opt.set_max_objective(
      [](unsigned, const double* x, double*, void* data) {
        auto* o = static_cast<Objective*>(data);
        try {
          return (*o->f)(x[0]);
        } catch (...) {
          o->error = std::current_exception();
          throw nlopt::forced_stop();
        }
      },
      &objective);
  std::vector<double> x{best_rot};
  double fx = 0.0;
  try {
    const nlopt::result r = opt.optimize(x, fx);
    p.optimiser_status = r == nlopt::MAXEVAL_REACHED ? "max_evaluations" : "converged";
  } catch (const nlopt::roundoff_limited&) {
    p.optimiser_status = "roundoff_limited";
  } catch (const nlopt::forced_stop&) {
    if (objective.error) std::rethrow_exception(objective.error);
    p.optimiser_status = "forced_stop";
  } catch (const std::runtime_error& e) {
    p.optimiser_status = std::string("failed: ") + e.what();  // NLopt's own failure
  }
  p.rotation = best_rot;
}

// 2. Stability of point i (if its IK found a posture), with the worker of
// the calling thread.
void AnalysePoint(const MapGrid& g, Worker& w, long i) {
  MapPoint& p = g.out[i];
  if (p.status != PointStatus::kOk && p.status != PointStatus::kOtherConfiguration) return;
  bool singular = EvaluateAt(g, w, i, p.q, p.rotation, &p.stability, &p.jacobian_condition);
  if (g.options.optimise_rotation) OptimiseRotation(g, w, i, &singular);
  if (singular) p.status = PointStatus::kNearSingular;
}

}  // namespace

void MapOptions::Validate() const {
  CheckOptionFinite("rotation", rotation);
  if (optimise_rotation) {
    CheckOptionFinite("rotation_min", rotation_min);
    CheckOptionFinite("rotation_max", rotation_max);
    if (!(rotation_max > rotation_min)) {
      std::ostringstream s;
      s << "rotation_max: expected a value > rotation_min " << rotation_min << " [rad], got " << rotation_max;
      throw OptionError("rotation_max", s.str());
    }
    CheckOptionAtLeast("rotation_evaluations", rotation_evaluations, kRotationScan + 1);
  }
  CheckOptionAtLeast("threads", threads, 0);
  ValidateNested("analysis", analysis);
}

std::vector<MapPoint> EvaluateStabilityMap(std::shared_ptr<const dynamics::RobotModel> model,
                                           const std::vector<ToolPoseTarget>& targets, int rows,
                                           int cols, const MillingProcess& process,
                                           const MapOptions& options) {
  process.Validate();
  const int n = model->num_joints();
  CheckMapArguments(n, targets.size(), rows, cols, options);
  const int threads = ResolveThreadCount(options.threads);
  const long total = static_cast<long>(targets.size());
  std::vector<MapPoint> out(total);
  const double rot0 = options.optimise_rotation
                          ? std::clamp(options.rotation, options.rotation_min, options.rotation_max)
                          : options.rotation;
  const MapGrid g{targets, rows, cols, process, options, model->chain(), n, rot0, out};

  // 1. IK: the first column top-down, then every row from its first point.
  SolveIk(g, *model, threads);

  // 2. Stability per point, one evaluator per thread.
  std::vector<std::unique_ptr<Worker>> workers;
  for (int t = 0; t < threads; ++t) workers.push_back(std::make_unique<Worker>(*model));

  ParallelForOptions po;
  po.threads = threads;
  po.chunk_size = 1;  // a point costs 0.1-5 ms (more with optimise_rotation): no need to batch
  po.progress = options.progress;
  ParallelFor(0, total, [&](long i, int t) { AnalysePoint(g, *workers[t], i); }, po);
  return out;
}

int FirstFeedAlongToolAxis(const std::vector<ToolPoseTarget>& targets) {
  for (size_t i = 0; i < targets.size(); ++i) {
    const Eigen::Vector3d z = targets[i].z_T.normalized();
    const Eigen::Vector3d f = targets[i].feed_B - targets[i].feed_B.dot(z) * z;
    if (f.norm() < 1e-6) return static_cast<int>(i);
  }
  return -1;
}

StabilityMapResult ComputeStabilityMap(std::shared_ptr<const dynamics::RobotModel> model,
                                       const std::vector<ToolPoseTarget>& targets, int rows, int cols,
                                       const MillingProcess& process, const MapOptions& options) {
  StabilityMapResult r;
  r.points = EvaluateStabilityMap(std::move(model), targets, rows, cols, process, options);
  for (const MapPoint& p : r.points) {
    r.reached += p.status != PointStatus::kUnreachable && p.status != PointStatus::kJointLimits;
    r.flagged_points += p.status != PointStatus::kOk;
  }
  if (r.flagged_points > 0) {
    r.verdict.Flag(std::to_string(r.flagged_points) + " of " + std::to_string(r.points.size()) +
           " points are flagged (status column: unreachable, joint_limits, near_singular, other_configuration)");
  }
  return r;
}

ClosedFormAgreement CompareClosedForm(const std::vector<MapPoint>& points) {
  std::vector<double> ratio;
  for (const MapPoint& p : points) {
    const PostureStability& s = p.stability;
    if (s.mode_coupling.status == ModeCouplingStatus::kFound && std::isfinite(s.closed_form.critical_depth) &&
        s.closed_form.critical_depth > 0.0) {
      ratio.push_back(s.closed_form.critical_depth / s.mode_coupling.critical_depth);
    }
  }
  ClosedFormAgreement a;
  a.points = static_cast<long>(ratio.size());
  if (ratio.empty()) return a;
  std::sort(ratio.begin(), ratio.end());
  a.median = ratio[ratio.size() / 2];
  a.min = ratio.front();
  a.max = ratio.back();
  return a;
}

CriticalDepthExtremes FindCriticalDepthExtremes(const std::vector<MapPoint>& points) {
  CriticalDepthExtremes e;
  for (size_t i = 0; i < points.size(); ++i) {
    const double d = points[i].stability.critical_depth;
    if (!std::isfinite(d)) continue;
    const long k = static_cast<long>(i);
    if (e.with_depth == 0 || d < points[e.min_index].stability.critical_depth) e.min_index = k;
    if (e.with_depth == 0 || d > points[e.max_index].stability.critical_depth) e.max_index = k;
    ++e.with_depth;
  }
  return e;
}

}  // namespace robomach::stability
