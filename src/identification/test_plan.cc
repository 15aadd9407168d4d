#include "identification/internal/information.h"
#include "robomach/identification/test_plan.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/uncertainty.h"
#include "robomach/identification/compliance_model.h"

namespace robomach::identification {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double LogDet(const Eigen::MatrixXd& I) {
  Eigen::LLT<Eigen::MatrixXd> llt(I);
  if (llt.info() != Eigen::Success) return -kInf;
  return 2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
}


struct Candidate {
  Eigen::VectorXd q;
  Eigen::Vector3d p_load;
  std::vector<Eigen::Vector3d> directions;
  std::vector<Eigen::MatrixXd> info;  // per direction, all masses included
};

// The target gradients with the rows of joints no target depends on
// (TargetsDependOnJoint) set to zero: finite-difference noise on such a
// joint must not make a target "undetermined" when the joint is unseen.
Eigen::MatrixXd EffectiveTargetGradients(const PlanOptions& o) {
  Eigen::MatrixXd G = o.target_gradients;
  for (Eigen::Index j = 0; j < G.rows(); ++j) {
    if (!TargetsDependOnJoint(o, static_cast<int>(j))) G.row(j).setZero();
  }
  return G;
}

// The design's criterion, higher better: log det I (D-optimal), or
// −Σ_t g_tᵀ I⁻¹ g_t with target gradients G (L-optimal); −inf where I is
// not positive definite.
using Criterion = std::function<double(const Eigen::MatrixXd&)>;
Criterion DesignCriterion(const Eigen::MatrixXd& G) {
  if (G.size() == 0) return LogDet;
  return [G](const Eigen::MatrixXd& I) {
    const Eigen::LLT<Eigen::MatrixXd> llt(I);
    if (llt.info() != Eigen::Success) return -kInf;
    return -(G.transpose() * llt.solve(G)).trace();
  };
}

// Best `count` directions of a candidate given the current information
// (greedy within the posture); returns the criterion reached.
double ChooseDirections(const Candidate& c, const Eigen::MatrixXd& I, int count, std::vector<int>* chosen,
                        const Criterion& criterion) {
  Eigen::MatrixXd acc = I;
  chosen->clear();
  double best_total = -kInf;
  for (int s = 0; s < count; ++s) {
    int best = -1;
    double best_ld = -kInf;
    for (size_t d = 0; d < c.directions.size(); ++d) {
      if (std::find(chosen->begin(), chosen->end(), static_cast<int>(d)) != chosen->end()) continue;
      const double ld = criterion(acc + c.info[d]);
      if (ld > best_ld) {
        best_ld = ld;
        best = static_cast<int>(d);
      }
    }
    if (best < 0) break;
    chosen->push_back(best);
    acc += c.info[best];
    best_total = best_ld;
  }
  return best_total;
}

// The targets' expected widths with the whole plan and with its first k
// postures, and how many postures reach the width asked for.
void TargetWidths(const PlanOptions& o, const Eigen::MatrixXd& info, const std::vector<int>& sel,
                  const std::vector<std::vector<int>>& sel_dirs,
                  const std::function<Eigen::MatrixXd(int, const std::vector<int>&)>& contribution, TestPlan* plan) {
  const Eigen::MatrixXd G = EffectiveTargetGradients(o);
  const int n = static_cast<int>(info.rows());
  const double z = dynamics::NormalQuantile(0.5 * (1.0 + o.target_confidence));
  auto stds = [&](const Eigen::MatrixXd& I) {
    Eigen::VectorXd s = Eigen::VectorXd::Constant(G.cols(), kInf);
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(I);
    if (!lu.isInvertible() || lu.rcond() < 1e-14) {
      // Some joint unseen: a target that does not depend on it is still determined.
      const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(I);
      const Eigen::MatrixXd P = cod.pseudoInverse();
      for (Eigen::Index t = 0; t < G.cols(); ++t) {
        const Eigen::VectorXd g = G.col(t);
        // g must lie in I's range: its part in the null space is not determined.
        const Eigen::VectorXd r = g - I * (P * g);
        if (r.norm() <= 1e-6 * std::max(g.norm(), 1e-300)) s(t) = std::sqrt(std::max(0.0, g.dot(P * g)));
      }
      return s;
    }
    const Eigen::MatrixXd X = lu.solve(G);
    for (Eigen::Index t = 0; t < G.cols(); ++t) s(t) = std::sqrt(std::max(0.0, G.col(t).dot(X.col(t))));
    return s;
  };
  plan->expected_target_relative_std = stds(info);
  Eigen::MatrixXd I = Eigen::MatrixXd::Zero(n, n);
  for (size_t s = 0; s < sel.size(); ++s) {
    I += contribution(static_cast<int>(s), sel_dirs[s]);
    const double hw = z * stds(I).maxCoeff();
    plan->target_half_width_by_postures.push_back(hw);
    if (o.target_half_width > 0.0 && plan->postures_for_target_width == 0 && hw <= o.target_half_width) {
      plan->postures_for_target_width = static_cast<int>(s) + 1;
    }
  }
  if (o.target_half_width > 0.0 && plan->postures_for_target_width == 0) {
    const double hw = plan->target_half_width_by_postures.back();
    if (std::isfinite(hw)) {
      const double k = std::ceil(static_cast<double>(sel.size()) * (hw / o.target_half_width) * (hw / o.target_half_width));
      plan->postures_for_target_width_estimate = static_cast<int>(std::min(k, 1e6));
    }
    std::ostringstream m;
    m.precision(3);
    m << "the targets' " << 100 * o.target_confidence << " % half-width is ±" << 100 * hw << " % with all "
      << sel.size() << " postures, not the ±" << 100 * o.target_half_width << " % asked for";
    if (plan->postures_for_target_width_estimate >= 1000000) {
      m << ": over a million postures would be needed (a lower tracker noise or heavier loads, --noise-mm and "
           "--masses-kg, narrow every band)";
    } else if (plan->postures_for_target_width_estimate > 0) {
      m << ": about " << plan->postures_for_target_width_estimate << " postures would reach it";
    } else {
      m << ": a target depends on a joint these tests cannot determine";
      std::string joints;
      for (int j = 0; j < n; ++j) {
        if (!std::isfinite(plan->expected_relative_std(j)) && TargetsDependOnJoint(o, j)) {
          joints += (joints.empty() ? " (joint " : ", ") + std::to_string(j + 1);
        }
      }
      if (!joints.empty()) m << joints << ")";
    }
    plan->verdict.Flag(m.str());
  }
}

}  // namespace

Eigen::MatrixXd LogStiffnessInformation(const dynamics::RobotModel& model,
                                        const std::vector<LoadCase>& cases,
                                        const Eigen::VectorXd& kq, double sigma_displacement) {
  const int n = model.num_joints();
  Eigen::MatrixXd I = Eigen::MatrixXd::Zero(n, n);
  for (const LoadCase& c : cases) {
    const Matrix3Xd G = DisplacementPerCompliance(EvaluateCaseKinematics(model, c), c.force) *
                        kq.cwiseInverse().asDiagonal();
    I.noalias() += G.transpose() * G;
  }
  return I / (sigma_displacement * sigma_displacement);
}

bool TargetsDependOnJoint(const PlanOptions& o, int joint) {
  if (o.target_gradients.size() == 0) return true;
  return o.target_gradients.row(joint).cwiseAbs().maxCoeff() > 1e-3 * o.target_gradients.cwiseAbs().maxCoeff();
}

void PlanOptions::Validate() const {
  const PlanOptions& o = *this;
  auto fail = [](const std::string& field, double v, const std::string& bound) {
    std::ostringstream s;
    s << "PlanOptions::" << field << ": expected " << bound << ", got " << v;
    throw OptionError(field, s.str());
  };
  if (o.num_postures < 1) fail("num_postures", o.num_postures, "at least 1");
  if (o.directions_per_posture < 1) fail("directions_per_posture", o.directions_per_posture, "at least 1");
  if (o.masses_kg.empty()) {
    throw OptionError("masses_kg", "PlanOptions::masses_kg: expected at least one mass, got none");
  }
  for (double mkg : o.masses_kg) {
    if (!(mkg > 0.0)) fail("masses_kg", mkg, "masses > 0 kg");
  }
  if (!(o.tracker_noise > 0.0)) fail("tracker_noise", o.tracker_noise, "a value > 0 m");
  if (!(o.max_rope_angle >= 0.0 && o.max_rope_angle < 0.5 * kPi)) {
    fail("max_rope_angle", o.max_rope_angle, "an angle in [0, pi/2) rad");
  }
  if (o.num_candidate_postures != 0 && o.num_candidate_postures < o.num_postures) {
    fail("num_candidate_postures", o.num_candidate_postures, "0 (automatic) or at least num_postures");
  }
  if (o.num_azimuths < 1) fail("num_azimuths", o.num_azimuths, "at least 1");
  if (!(o.joint_limit_margin >= 0.0)) fail("joint_limit_margin", o.joint_limit_margin, "a value >= 0 rad");
  if (!(o.weak_relative_std > 0.0)) fail("weak_relative_std", o.weak_relative_std, "a value > 0");
  if (o.target_gradients.size() > 0 && !o.target_gradients.allFinite()) {
    throw OptionError("target_gradients", "PlanOptions::target_gradients: expected finite numbers, got a NaN or inf");
  }
  if (!(o.target_half_width >= 0.0 && std::isfinite(o.target_half_width))) {
    fail("target_half_width", o.target_half_width, "a relative half-width >= 0 (0: none)");
  }
  if (!(o.target_confidence > 0.0 && o.target_confidence < 1.0)) {
    fail("target_confidence", o.target_confidence, "a level in (0, 1)");
  }
}

namespace {

// The stages of PlanLoadTests below, in their order: candidate rope
// directions, candidate postures with their information, the greedy and
// exchange selection, the expected uncertainty, and the planned loads.

// Candidate rope directions: vertical, and rings at half and full tilt.
std::vector<Eigen::Vector3d> CandidateDirections(const PlanOptions& o) {
  std::vector<Eigen::Vector3d> dirs{Eigen::Vector3d(0, 0, -1)};
  for (double tilt : {0.5 * o.max_rope_angle, o.max_rope_angle}) {
    if (tilt <= 0.0) continue;
    for (int a = 0; a < o.num_azimuths; ++a) {
      const double phi = 2.0 * kPi * a / o.num_azimuths;
      dirs.emplace_back(std::sin(tilt) * std::cos(phi), std::sin(tilt) * std::sin(phi), -std::cos(tilt));
    }
  }
  return dirs;
}

// Random postures within the joint limits (seeded), each with the rope
// directions whose pulley is feasible and their information (all masses
// included); a posture with too few feasible directions or too low a load
// point is dropped.
std::vector<Candidate> SampleCandidates(const dynamics::RobotModel& model, const PlanOptions& o) {
  const int n = model.num_joints();
  const Eigen::VectorXd kq = model.joint_stiffness();
  const double sigma = std::sqrt(2.0) * o.tracker_noise;
  double sum_m2 = 0.0;
  for (double mkg : o.masses_kg) sum_m2 += mkg * mkg;
  // The displacement is linear in the force, so the masses of one direction
  // add (m g)² times the unit-force information.
  const double scale = kStandardGravity * kStandardGravity * sum_m2 / (sigma * sigma);
  const Eigen::Vector3d tcp = TcpInTip(model);
  const std::vector<Eigen::Vector3d> dirs = CandidateDirections(o);

  std::mt19937 rng(o.seed);
  std::vector<Candidate> cands;
  const auto& limits = model.chain().limits();
  const int num_wanted =
      o.num_candidate_postures > 0 ? o.num_candidate_postures : std::max(400, 4 * o.num_postures);
  const int max_tries = 50 * num_wanted;
  for (int tries = 0; tries < max_tries && static_cast<int>(cands.size()) < num_wanted; ++tries) {
    Candidate c;
    c.q.resize(n);
    for (int j = 0; j < n; ++j) {
      double lo = -kPi, hi = kPi;
      if (limits[j].bounded) {
        lo = limits[j].lower + o.joint_limit_margin;
        hi = limits[j].upper - o.joint_limit_margin;
      }
      if (hi < lo) lo = hi = 0.5 * (limits[j].lower + limits[j].upper);
      c.q(j) = std::uniform_real_distribution<double>(lo, hi)(rng);
    }
    LoadCase lc;
    lc.q = c.q;
    lc.p_load_tip = o.p_load_tip.value_or(tcp);
    lc.p_target_tip = o.p_target_tip.value_or(tcp);
    const CaseKinematics k = EvaluateCaseKinematics(model, lc);
    c.p_load = k.p_BL;
    const double height = c.p_load.z() - o.floor_z;
    if (height < o.min_load_height) continue;
    for (const Eigen::Vector3d& d : dirs) {
      const Eigen::Vector3d pulley = c.p_load + d * (height / -d.z());
      // The pulley must stand clear of the robot's foot (0.6 m from the base
      // axis covers the KR210's base plate and a person-sized margin).
      if (pulley.head<2>().norm() < 0.6) continue;
      const Matrix3Xd G = DisplacementPerCompliance(k, d) * kq.cwiseInverse().asDiagonal();
      c.directions.push_back(d);
      c.info.push_back(scale * G.transpose() * G);
    }
    if (static_cast<int>(c.directions.size()) < o.directions_per_posture) continue;
    cands.push_back(std::move(c));
  }
  return cands;
}

// The information of candidate c's directions ds.
Eigen::MatrixXd Contribution(const Candidate& c, const std::vector<int>& ds, int n) {
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  for (int d : ds) M += c.info[d];
  return M;
}

// The chosen postures (indices into the candidates), the directions chosen
// in each, and the information of the plan.
struct Selection {
  std::vector<int> sel;
  std::vector<std::vector<int>> sel_dirs;
  Eigen::MatrixXd info;  // of the chosen loads, without the ridge
};

// Greedy selection of o.num_postures postures by the design criterion, then
// exchange passes.
Selection SelectPostures(const std::vector<Candidate>& cands, const PlanOptions& o, int n) {
  // A ridge of 1e-6 (a prior σ(θ) of 1000, i.e. no knowledge) keeps log det
  // finite while joints are still unseen; one load case adds ~1e3.
  const Eigen::MatrixXd ridge = 1e-6 * Eigen::MatrixXd::Identity(n, n);
  const Criterion criterion = DesignCriterion(o.design_for_targets ? EffectiveTargetGradients(o) : Eigen::MatrixXd());
  Selection r;
  std::vector<int>& sel = r.sel;
  std::vector<std::vector<int>>& sel_dirs = r.sel_dirs;
  Eigen::MatrixXd I = ridge;
  auto contribution = [&](int ci, const std::vector<int>& ds) { return Contribution(cands[ci], ds, n); };
  std::vector<int> chosen;
  for (int s = 0; s < o.num_postures; ++s) {
    int best = -1;
    double best_ld = -kInf;
    std::vector<int> best_dirs;
    for (int ci = 0; ci < static_cast<int>(cands.size()); ++ci) {
      if (std::find(sel.begin(), sel.end(), ci) != sel.end()) continue;
      const double ld = ChooseDirections(cands[ci], I, o.directions_per_posture, &chosen, criterion);
      if (ld > best_ld) {
        best_ld = ld;
        best = ci;
        best_dirs = chosen;
      }
    }
    sel.push_back(best);
    sel_dirs.push_back(best_dirs);
    I += contribution(best, best_dirs);
  }
  // Exchange passes (Fedorov-style): replace a chosen posture by a better one.
  for (int pass = 0; pass < 3; ++pass) {
    bool improved = false;
    for (int s = 0; s < o.num_postures; ++s) {
      const Eigen::MatrixXd I_minus = I - contribution(sel[s], sel_dirs[s]);
      double cur = criterion(I);
      for (int ci = 0; ci < static_cast<int>(cands.size()); ++ci) {
        if (std::find(sel.begin(), sel.end(), ci) != sel.end()) continue;
        const double ld = ChooseDirections(cands[ci], I_minus, o.directions_per_posture, &chosen, criterion);
        if (ld > cur + 1e-9) {
          sel[s] = ci;
          sel_dirs[s] = chosen;
          I = I_minus + contribution(ci, chosen);
          cur = ld;
          improved = true;
        }
      }
    }
    if (!improved) break;
  }
  r.info = I - ridge;
  return r;
}

// The plan's expected uncertainty per joint (and per target), with a
// finding for each joint it cannot determine.
void ExpectedUncertainty(const std::vector<Candidate>& cands, const Selection& s, const PlanOptions& o,
                         const Eigen::VectorXd& kq, TestPlan* plan) {
  const Eigen::MatrixXd& info = s.info;
  const int n = static_cast<int>(info.rows());
  plan->log_det_information = LogDet(info);
  plan->expected_relative_std = internal::MarginalStdFromInformation(info);
  plan->expected_std_dev = kq.cwiseProduct(plan->expected_relative_std);
  for (int j = 0; j < n; ++j) {
    plan->expected_determination.push_back(
        DeterminationFromRelativeStd(plan->expected_relative_std(j), o.weak_relative_std));
    if (plan->expected_determination.back() == Determination::kNotDetermined && TargetsDependOnJoint(o, j)) {
      // The last joint turns the tool about its own axis: only a load or a
      // target off that axis feels it.
      plan->verdict.Flag("joint " + std::to_string(j + 1) + " cannot be determined with this set-up" +
                     (j == n - 1 ? ": put the load point and the target off the tool axis" : ": allow more postures or rope directions"),
                 j);
    }
  }
  if (o.target_gradients.size() > 0) {
    TargetWidths(o, info, s.sel, s.sel_dirs,
                 [&](int k, const std::vector<int>& ds) { return Contribution(cands[s.sel[k]], ds, n); }, plan);
  }
}

// The planned loads (one per chosen posture and direction) and their load
// cases (one per mass).
void ListLoads(const std::vector<Candidate>& cands, const Selection& sl, const PlanOptions& o, TestPlan* plan) {
  for (int s = 0; s < o.num_postures; ++s) {
    const Candidate& c = cands[sl.sel[s]];
    const std::string pose_id = "P" + std::to_string(s + 1);
    for (size_t k = 0; k < sl.sel_dirs[s].size(); ++k) {
      const Eigen::Vector3d d = c.directions[sl.sel_dirs[s][k]];
      PlannedLoad pl;
      pl.pose_id = pose_id;
      pl.q = c.q;
      pl.rope_direction = d;
      pl.p_load = c.p_load;
      pl.p_pulley = c.p_load + d * ((c.p_load.z() - o.floor_z) / -d.z());
      plan->loads.push_back(pl);
      for (double mkg : o.masses_kg) {
        LoadCase lc;
        std::ostringstream id;
        id << pose_id << "-" << static_cast<char>('a' + k) << "-" << mkg << "kg";
        lc.case_id = id.str();
        lc.pose_id = pose_id;
        lc.q = c.q;
        lc.force = mkg * kStandardGravity * d;
        lc.p_load_tip = o.p_load_tip;
        lc.p_target_tip = o.p_target_tip;
        plan->cases.push_back(lc);
      }
    }
  }
}

}  // namespace

TestPlan PlanLoadTests(const dynamics::RobotModel& model, const PlanOptions& o) {
  o.Validate();
  const int n = model.num_joints();
  if (o.target_gradients.size() > 0 && o.target_gradients.rows() != n) {
    throw std::invalid_argument("PlanOptions::target_gradients: expected " + std::to_string(n) +
                                " rows (one per joint), got " + std::to_string(o.target_gradients.rows()));
  }
  const std::vector<Candidate> cands = SampleCandidates(model, o);
  TestPlan plan;
  plan.num_candidates = static_cast<int>(cands.size());
  if (static_cast<int>(cands.size()) < o.num_postures) {
    throw std::invalid_argument("PlanLoadTests: only " + std::to_string(cands.size()) +
                                " feasible postures found for " + std::to_string(o.num_postures) +
                                " requested: lower min_load_height or widen max_rope_angle");
  }
  const Selection selection = SelectPostures(cands, o, n);
  ExpectedUncertainty(cands, selection, o, model.joint_stiffness(), &plan);
  ListLoads(cands, selection, o, &plan);
  return plan;
}

}  // namespace robomach::identification
