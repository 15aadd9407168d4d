#include "robomach/identification/campaign_synth.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

#include "robomach/common/errors.h"
#include "robomach/common/option_validate.h"
#include "robomach/common/units.h"
#include "robomach/identification/compliance_model.h"

namespace robomach::identification {
namespace {

Eigen::Vector3d Noise(std::mt19937& rng, double sigma) {
  // std::normal_distribution requires sigma > 0; zero noise is exact readings.
  if (!(sigma > 0.0)) return Eigen::Vector3d::Zero();
  std::normal_distribution<double> nd(0.0, sigma);
  const double a = nd(rng), b = nd(rng), c = nd(rng);  // fixed evaluation order
  return {a, b, c};
}

}  // namespace

void CampaignOptions::Validate() const {
  if (masses_kg.empty()) throw OptionError("masses_kg", "masses_kg: expected at least one mass, got none");
  for (const double m : masses_kg) {
    CheckOptionAbove("masses_kg", m, 0.0);
    CheckOptionFinite("masses_kg", m);
  }
  CheckOptionAtLeast("tracker_noise", tracker_noise, 0.0);
  CheckOptionFinite("tracker_noise", tracker_noise);
  CheckOptionAtLeast("num_outliers", num_outliers, 0);
  CheckOptionAtLeast("outlier_size", outlier_size, 0.0);
  CheckOptionFinite("outlier_size", outlier_size);
  CheckOptionAtLeast("rope_A_distance", rope_A_distance, 0.0);
  if (!(rope_B_distance > rope_A_distance) || !std::isfinite(rope_B_distance)) {
    std::ostringstream s;
    s << "rope_B_distance: expected a value > rope_A_distance " << rope_A_distance << ", got " << rope_B_distance;
    throw OptionError("rope_B_distance", s.str());
  }
  CheckOptionAtLeast("min_reach", min_reach, 0.0);
}

std::vector<Eigen::VectorXd> CampaignPostures(const dynamics::RobotModel& model, int count,
                                              const CampaignOptions& options, unsigned seed) {
  options.Validate();
  const int n = model.num_joints();
  const auto& limits = model.chain().limits();
  const Eigen::Vector3d tcp = TcpInTip(model);
  std::mt19937 rng(seed);
  std::vector<Eigen::VectorXd> out;
  const double margin = DegToRad(5.0);
  constexpr int kTries = 100000;
  int tries = 0;
  for (; tries < kTries && static_cast<int>(out.size()) < count; ++tries) {
    Eigen::VectorXd q(n);
    for (int j = 0; j < n; ++j) {
      double lo = -kPi, hi = kPi;
      if (limits[j].bounded) {
        lo = limits[j].lower + margin;
        hi = limits[j].upper - margin;
      }
      if (j == 0) {
        lo = std::max(lo, DegToRad(-45.0));
        hi = std::min(hi, DegToRad(45.0));
      }
      q(j) = std::uniform_real_distribution<double>(lo, hi)(rng);
    }
    LoadCase c;
    c.q = q;
    c.p_load_tip = options.p_load_tip.value_or(tcp);
    c.p_target_tip = options.p_target_tip.value_or(tcp);
    const CaseKinematics k = EvaluateCaseKinematics(model, c);
    if (k.p_BL.z() < 0.3 || k.p_BL.head<2>().norm() < options.min_reach) continue;
    bool ok = true;
    for (const Eigen::Vector3d& pulley : options.pulleys) {
      const Eigen::Vector3d d = pulley - k.p_BL;
      // Within 60° of vertical: −d_z ≥ cos 60° |d|.
      if (-d.z() < 0.5 * d.norm()) ok = false;
    }
    if (ok) out.push_back(q);
  }
  if (static_cast<int>(out.size()) < count) {
    // The count first, so that a tool can name its option in its place.
    std::ostringstream m;
    m << "count " << count << ": only " << out.size() << " of " << tries
      << " random postures hold the load point 0.3 m above the floor and at least " << options.min_reach
      << " m from the base axis (the least reach), with every pulley within 60 degrees of vertical; ";
    if (!out.empty()) m << "ask for at most " << out.size() << ", ";
    m << "lower the least reach, or place the pulleys elsewhere";
    throw std::invalid_argument(m.str());
  }
  return out;
}

std::vector<TrackerMeasurement> SimulateCampaign(const dynamics::RobotModel& model,
                                                 const std::vector<std::string>& pose_ids,
                                                 const std::vector<Eigen::VectorXd>& postures,
                                                 const Eigen::VectorXd& kq,
                                                 const CampaignOptions& o,
                                                 std::vector<int>* outlier_cases) {
  return SimulateCampaign(model, pose_ids, postures,
                          std::vector<std::vector<Eigen::Vector3d>>(postures.size(), o.pulleys), kq, o,
                          outlier_cases);
}

std::vector<TrackerMeasurement> SimulateCampaign(
    const dynamics::RobotModel& model, const std::vector<std::string>& pose_ids,
    const std::vector<Eigen::VectorXd>& postures,
    const std::vector<std::vector<Eigen::Vector3d>>& pulleys, const Eigen::VectorXd& kq,
    const CampaignOptions& o, std::vector<int>* outlier_cases) {
  o.Validate();
  if (pose_ids.size() != postures.size() || pulleys.size() != postures.size()) {
    throw std::invalid_argument("SimulateCampaign: pose_ids and postures differ in size");
  }
  const Eigen::Vector3d tcp = TcpInTip(model);
  std::mt19937 rng(o.seed);
  std::vector<TrackerMeasurement> out;
  int counter = 0;
  for (size_t p = 0; p < postures.size(); ++p) {
    LoadCase base;
    base.q = postures[p];
    base.p_load_tip = o.p_load_tip.value_or(tcp);
    base.p_target_tip = o.p_target_tip.value_or(tcp);
    const CaseKinematics k = EvaluateCaseKinematics(model, base);
    for (size_t u = 0; u < pulleys[p].size(); ++u) {
      const Eigen::Vector3d rope = pulleys[p][u] - k.p_BL;
      if (rope.norm() < 1e-6) {
        throw std::invalid_argument("SimulateCampaign: pulley " + std::to_string(u + 1) +
                                    " coincides with the load point at posture " + pose_ids[p]);
      }
      const Eigen::Vector3d d = rope.normalized();
      if (!(d.z() < 0.0)) {
        std::ostringstream msg;
        msg << "SimulateCampaign: pulley " << u + 1 << " is not below the load point at posture "
            << pose_ids[p] << " (load point z = " << k.p_BL.z() << " m, pulley z = " << pulleys[p][u].z()
            << " m): a rope to a floor pulley pulls downwards";
        throw std::invalid_argument(msg.str());
      }
      for (double mkg : o.masses_kg) {
        LoadCase lc = base;
        lc.force = mkg * kStandardGravity * d;
        const Eigen::Vector3d D = SolveStaticDeflection(model, lc, kq);
        TrackerMeasurement m;
        std::ostringstream id;
        id << "C" << ++counter;
        m.case_id = id.str();
        m.pose_id = pose_ids[p];
        m.q = postures[p];
        m.p0 = k.p_BT + Noise(rng, o.tracker_noise);
        m.p1 = k.p_BT + D + Noise(rng, o.tracker_noise);
        if (o.force_form) {
          m.force = lc.force;
        } else {
          m.mass_kg = mkg;
          m.rope_A = k.p_BL + o.rope_A_distance * d + Noise(rng, o.tracker_noise);
          m.rope_B = k.p_BL + o.rope_B_distance * d + Noise(rng, o.tracker_noise);
        }
        m.p_load_tip = o.p_load_tip;
        m.p_target_tip = o.p_target_tip;
        out.push_back(std::move(m));
      }
    }
  }
  if (o.num_outliers > static_cast<int>(out.size())) {
    throw std::invalid_argument("SimulateCampaign: more outliers than cases");
  }
  std::vector<int> idx(out.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<int>(i);
  std::vector<int> chosen;
  for (int i = 0; i < o.num_outliers; ++i) {
    const int pick = std::uniform_int_distribution<int>(i, static_cast<int>(idx.size()) - 1)(rng);
    std::swap(idx[i], idx[pick]);
    chosen.push_back(idx[i]);
    out[idx[i]].p1 += o.outlier_size * Noise(rng, 1.0).normalized();
  }
  std::sort(chosen.begin(), chosen.end());
  if (outlier_cases) *outlier_cases = chosen;
  return out;
}

}  // namespace robomach::identification
