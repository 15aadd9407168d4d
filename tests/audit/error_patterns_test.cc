// Error patterns of the model audit (issue #5 §2.2) on virtual hammer tests
// with a known, planted pattern: an error that grows with one posture
// descriptor must correlate most strongly with that descriptor; a model mode
// removed from the "measured" data must be reported as unmatched, and a mode
// added to them as a measured mode without a model counterpart.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "robomach/audit/error_patterns.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/gravity_torque.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "robomach/io/robot_config.h"
#include "robomach/kinematics/serial_chain.h"
#include "test_support.h"

namespace robomach::audit {
namespace {

using calibration::NamedPosture;
using robomach::testing::SourcePath;

struct Campaign {
  std::shared_ptr<const dynamics::RobotModel> model;
  std::vector<NamedPosture> poses;
  calibration::PostureMap postures;
};

// n seeded postures of the KR210 spread over a working region (inside the
// limits, q5 away from the wrist singularity), so that reach, height, the
// joint angles and the gravity torques vary without being collinear.
Campaign MakeCampaign(int n, unsigned seed) {
  Campaign c{io::LoadRobotConfig(SourcePath("config/kr210.yaml")).Build(), {}, {}};
  std::mt19937 rng(seed);
  const double lo[6] = {-0.8, -1.9, 0.9, -0.8, 0.4, -1.0}, hi[6] = {0.8, -0.7, 2.1, 0.8, 1.3, 1.0};
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd q(6);
    for (int j = 0; j < 6; ++j) q(j) = std::uniform_real_distribution<double>(lo[j], hi[j])(rng);
    const std::string id = "S" + std::to_string(i + 1);
    c.poses.push_back({id, q});
    c.postures[id] = q;
  }
  return c;
}

// Multiplies every FRF of posture p by exp(gain · x(p)): a log-magnitude
// error of exactly gain · x(p) on every line (a known, posture-dependent
// error, e.g. a transducer whose sensitivity drifts with cable length).
dynamics::FrfSet WithLogGain(const dynamics::FrfSet& in, const std::map<std::string, double>& x, double gain) {
  dynamics::FrfSet out;
  for (const auto& [key, frf] : in) {
    out.Insert(key, dynamics::Frf::FromSamples(frf.freq_hz(), frf.receptance() * std::exp(gain * x.at(key.pose_id))));
  }
  return out;
}

AuditResult ResultWithErrorsOnly(const Campaign& c, const dynamics::FrfSet& measured) {
  AuditResult r;
  r.errors_before = ComputeErrors(c.model, c.postures, measured, 0.0, 1e9, 8);
  r.noise_floor = EstimateNoiseFloor(measured, 0.0, 1e9);
  return r;
}

int Column(const PostureDescriptors& d, const std::string& name) {
  const auto it = std::find(d.names.begin(), d.names.end(), name);
  EXPECT_NE(it, d.names.end()) << name;
  return static_cast<int>(it - d.names.begin());
}

// The descriptors against independent computations: reach and height from
// the TCP position of EvaluatePosture (X_BT, assembled by the posture
// evaluator's own FK solver), the gravity torques from central differences
// of the potential energy m g z summed over the chain's bodies (as in
// gravity_torque_test.cc, tolerance derived there).
TEST(ErrorPatterns, DescriptorsMatchIndependentComputations) {
  const Campaign c = MakeCampaign(3, 5);
  std::vector<std::string> ids;
  for (const auto& p : c.poses) ids.push_back(p.id);
  const PostureDescriptors d = DescribePostures(*c.model, c.postures, ids);
  ASSERT_EQ(d.names, (std::vector<std::string>{"q1", "q2", "q3", "q4", "q5", "q6", "reach", "height",
                                               "gravity_torque_j2", "gravity_torque_j3"}));
  ASSERT_EQ(d.values.rows(), 3);
  const kinematics::SerialChain& chain = c.model->chain();
  auto V = [&](const Eigen::VectorXd& q) {
    double v = 0.0;
    for (int s = 0; s < chain.num_segments(); ++s) {
      const kinematics::Inertial b = chain.segment_inertial(s);
      v += b.mass * kStandardGravity * (kinematics::SegmentPose(chain, q, s) * b.com).z();
    }
    return v;
  };
  for (int i = 0; i < 3; ++i) {
    const Eigen::VectorXd& q = c.poses[i].q;
    const Eigen::Vector3d p = dynamics::EvaluatePosture(c.model, q).X_BT.translation();
    // Two FK evaluations of the same chain: rounding ≈ eps · 3 m.
    EXPECT_NEAR(d.values(i, Column(d, "reach")), std::sqrt(p.x() * p.x() + p.y() * p.y()), 1e-12);
    EXPECT_NEAR(d.values(i, Column(d, "height")), p.z(), 1e-12);
    EXPECT_EQ(d.values.row(i).head(6).transpose(), q);
    const double h = 1e-4;
    for (int j : {1, 2}) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(6, j);
      const double fd = (V(q + h * e) - V(q - h * e)) / (2.0 * h);
      EXPECT_NEAR(d.values(i, Column(d, "gravity_torque_j" + std::to_string(j + 1))), fd, 1e-3);
    }
  }
  EXPECT_THROW(DescribePostures(*c.model, c.postures, {"nowhere"}), std::invalid_argument);
}

// A planted error that grows with a descriptor x: log gain a·x on top of 1 %
// measurement noise. The per-posture error is then √((a x)² + s²) with
// s = 0.01/√2 the noise in ln|H| (see model_audit_test.cc), so with
// a x ≥ 0.1 ≫ s it is linear in x to < 0.5 % and r(x) > 0.99; the other
// descriptors vary with x only partly across these random postures.
void ExpectStrongestTrendOn(const std::string& descriptor, double gain) {
  const Campaign c = MakeCampaign(8, 11);
  calibration::VirtualHammerOptions o;
  o.relative_noise = 0.01;
  o.seed = 3;
  const dynamics::FrfSet clean = calibration::SynthesizeHammerTest(c.model, c.poses, o);
  std::vector<std::string> ids;
  for (const auto& p : c.poses) ids.push_back(p.id);
  const PostureDescriptors d = DescribePostures(*c.model, c.postures, ids);
  std::map<std::string, double> x;
  for (int i = 0; i < 8; ++i) x[ids[i]] = d.values(i, Column(d, descriptor));
  const dynamics::FrfSet measured = WithLogGain(clean, x, gain);
  const AuditResult r = ResultWithErrorsOnly(c, measured);
  const ErrorPatterns p = AnalyzeErrorPatterns(r, c.model, c.postures, measured, calibration::MeasuredFeatures{});

  ASSERT_EQ(p.trends.n, 8);
  // Published 5 % critical value of r for n = 8 (Fisher & Yates): 0.707.
  EXPECT_NEAR(p.trends.critical_correlation, 0.707, 5e-4);
  // The per-posture error is the planted one: |a x| ⊕ noise (see above);
  // 1 % relative covers the noise term (s / (a x) ≤ 0.07, squared < 0.5 %).
  for (int i = 0; i < 8; ++i) {
    EXPECT_NEAR(p.trends.error_before(i) / std::abs(gain * x[ids[i]]), 1.0, 0.01) << ids[i];
  }
  const Trend* strongest = nullptr;
  for (const Trend& t : p.trends.trends) {
    std::cout << "  " << t.descriptor << " r = " << t.correlation_before << (t.significant_before ? " *" : "")
              << "\n";
    if (!strongest || std::abs(t.correlation_before) > std::abs(strongest->correlation_before)) strongest = &t;
  }
  ASSERT_NE(strongest, nullptr);
  EXPECT_EQ(strongest->descriptor, descriptor);
  EXPECT_GT(std::abs(strongest->correlation_before), 0.99);
  EXPECT_TRUE(strongest->significant_before);
  EXPECT_TRUE(std::isnan(strongest->correlation_after));  // no accepted candidate
  EXPECT_EQ(p.trends.error_after.size(), 0);
}

TEST(ErrorPatterns, ErrorGrowingWithReachCorrelatesMostWithReach) { ExpectStrongestTrendOn("reach", 0.1); }

TEST(ErrorPatterns, ErrorGrowingWithAJointAngleCorrelatesMostWithThatAngle) {
  // q3 ∈ [0.9, 2.1] rad here: a = 0.1 /rad gives 0.09 … 0.21.
  ExpectStrongestTrendOn("q3", 0.1);
}

// With an accepted candidate the trends are given after it too; errors at
// the noise floor at every posture are no failure, so none of their
// correlations is flagged, however large (noise correlates by chance).
TEST(ErrorPatterns, TrendsAfterTheBestCandidate) {
  const Campaign c = MakeCampaign(5, 11);
  calibration::VirtualHammerOptions o;
  o.relative_noise = 0.01;
  const dynamics::FrfSet measured = calibration::SynthesizeHammerTest(c.model, c.poses, o);
  std::map<std::string, double> x;
  for (const auto& p : c.poses) x[p.id] = p.q(2);
  AuditResult r = ResultWithErrorsOnly(c, WithLogGain(measured, x, 0.1));
  CandidateResult cand;
  cand.errors = ComputeErrors(c.model, c.postures, measured, 0.0, 1e9, 8);  // the pattern removed
  r.candidates.push_back(cand);
  r.best = 0;
  const ErrorPatterns p = AnalyzeErrorPatterns(r, c.model, c.postures, measured, calibration::MeasuredFeatures{});
  ASSERT_EQ(p.trends.error_after.size(), 5);
  // After: the noise alone, s = 0.01/√2 per posture. An rms over N lines
  // scatters by 1/√(2N) relative: 1.1 % for the 4000 lines of a posture (xx
  // and yy, 2000 each); 0.06 is about 5σ so five postures do not fail by
  // chance.
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(p.trends.error_after(i) / (0.01 / std::sqrt(2.0)), 1.0, 0.06);
  EXPECT_TRUE(p.trends.failing_before);
  EXPECT_FALSE(p.trends.failing_after);
  for (const Trend& t : p.trends.trends) {
    EXPECT_TRUE(std::isfinite(t.correlation_after)) << t.descriptor;
    EXPECT_FALSE(t.significant_after) << t.descriptor;
  }
  // The planted pattern (log gain 0.1 q3) is still found before.
  int q3 = 0;
  for (const Trend& t : p.trends.trends) {
    if (t.descriptor == "q3") {
      EXPECT_TRUE(t.significant_before);
      ++q3;
    }
  }
  EXPECT_EQ(q3, 1);
}

// Mode error map from a real matching (truth m6 +10 %, d6 −5 %): each cell
// holds the ModeMatch of its posture and model mode with the largest
// measured peak; cells without a match are NaN; columns are the matched
// model modes in ascending order.
TEST(ErrorPatterns, ModeErrorMapHoldsTheMostVisibleMatchPerCell) {
  const Campaign c = MakeCampaign(3, 7);
  io::RobotConfig cfg = io::LoadRobotConfig(SourcePath("config/kr210.yaml"));
  dynamics::ParameterSet truth = cfg.parameters;
  truth.Set("m6_kg", 1.10 * truth.Get("m6_kg"));
  truth.Set("d6_m", 0.95 * truth.Get("d6_m"));
  calibration::VirtualHammerOptions o;
  o.relative_noise = 0.01;
  const dynamics::FrfSet measured =
      calibration::SynthesizeHammerTest(dynamics::RobotModel::Build(cfg.description, truth), c.poses, o);
  const calibration::MeasuredFeatures features = calibration::ExtractFeatures(measured, AuditModalFitOptions({}));
  AuditResult r = ResultWithErrorsOnly(c, measured);
  r.modes_before = calibration::CompareWithMeasurement(c.model, c.postures, measured, features);
  ASSERT_FALSE(r.modes_before.matches.empty());
  const ErrorPatterns p = AnalyzeErrorPatterns(r, c.model, c.postures, measured, features);
  const ModeErrorMap& m = p.mode_map;
  ASSERT_EQ(m.pose_ids, measured.pose_ids());
  ASSERT_TRUE(std::is_sorted(m.modes.begin(), m.modes.end()));
  for (size_t i = 0; i < m.pose_ids.size(); ++i) {
    for (size_t k = 0; k < m.modes.size(); ++k) {
      const calibration::ModeMatch* best = nullptr;
      for (const auto& mm : r.modes_before.matches) {
        if (mm.key.pose_id == m.pose_ids[i] && mm.model_mode + 1 == m.modes[k] &&
            (!best || mm.measured_peak > best->measured_peak)) {
          best = &mm;
        }
      }
      const auto ii = static_cast<Eigen::Index>(i), kk = static_cast<Eigen::Index>(k);
      if (!best) {
        EXPECT_TRUE(std::isnan(m.freq_error(ii, kk)) && std::isnan(m.peak_error(ii, kk)));
        EXPECT_EQ(m.match(ii, kk), -1);
        continue;
      }
      // By hand from the matched frequencies and peaks.
      EXPECT_DOUBLE_EQ(m.freq_error(ii, kk), best->model_freq_hz / best->measured_freq_hz - 1.0);
      EXPECT_DOUBLE_EQ(m.peak_error(ii, kk), best->model_peak / best->measured_peak - 1.0);
    }
  }
  // A heavier, shorter end effector in the truth: the model's (lighter)
  // modes are stiffer somewhere, so some frequency error is clearly non-zero.
  EXPECT_GT(m.freq_error.array().isNaN().select(0.0, m.freq_error.array().abs()).maxCoeff(), 0.005);
}

// Receptance of a proportionally damped system as a sum of its modes,
// H_re(ω) = Σ_k p_r p_e / (ω_k² − ω² + 2iζ_k ω_k ω) [Ewins 2000, §2.3],
// optionally without mode `skip`.
Eigen::VectorXcd ModalSum(const dynamics::PostureDynamics& d, const dynamics::FrfKey& key, const Eigen::VectorXd& f,
                          int skip) {
  Eigen::VectorXcd h = Eigen::VectorXcd::Zero(f.size());
  const int r = static_cast<int>(key.response), e = static_cast<int>(key.excitation);
  for (size_t k = 0; k < d.modes.size(); ++k) {
    if (static_cast<int>(k) == skip) continue;
    const dynamics::Mode& m = d.modes[k];
    const double wk = HzToRadPerSec(m.freq_hz);
    for (int i = 0; i < f.size(); ++i) {
      const double w = HzToRadPerSec(f(i));
      h(i) += m.p_T(r) * m.p_T(e) / std::complex<double>(wk * wk - w * w, 2.0 * m.damping_ratio * wk * w);
    }
  }
  return h;
}

// The modal sum with every mode is the model's receptance (a check that the
// construction below changes only what it means to); without the second
// most visible mode of Hyy the audit must name that mode at every posture; an
// extra single-DOF mode at 400 Hz (above every model mode by more than the
// matching's ±40 % window) must come out as a measured mode without a model
// counterpart.
TEST(ErrorPatterns, ReportsModesWithoutCounterpartBothWays) {
  const Campaign c = MakeCampaign(3, 7);
  const Eigen::VectorXd f = calibration::HammerTestGrid({});
  constexpr double kExtraHz = 400.0, kExtraZeta = 0.03;
  dynamics::FrfSet complete, edited;
  std::map<dynamics::FrfKey, int> removed;
  std::map<dynamics::FrfKey, double> removed_visibility;
  for (const auto& p : c.poses) {
    const dynamics::PostureDynamics d = dynamics::EvaluatePosture(c.model, p.q);
    const auto H = dynamics::Receptance(d, f);
    for (Axis a : {Axis::kX, Axis::kY}) {
      const dynamics::FrfKey key{p.id, a, a};
      Eigen::VectorXcd h(f.size());
      for (int i = 0; i < f.size(); ++i) h(i) = H[i](static_cast<int>(a), static_cast<int>(a));
      // Proportional (Rayleigh) damping: the sum is exact up to rounding.
      EXPECT_LE((ModalSum(d, key, f, -1) - h).cwiseAbs().maxCoeff(), 1e-9 * h.cwiseAbs().maxCoeff());
      complete.Insert(key, dynamics::Frf::FromSamples(f, h));
      // The second most visible mode of Hyy is removed (Hxx keeps all).
      // Not the most visible: that would rescale every other mode's
      // relative visibility in this FRF, on the measured side only.
      int skip = -1;
      if (a == Axis::kY) {
        std::vector<std::pair<double, int>> vis;
        for (size_t k = 0; k < d.modes.size(); ++k) {
          const dynamics::Mode& m = d.modes[k];
          vis.push_back({m.p_T(1) * m.p_T(1) / (2 * m.damping_ratio * std::pow(HzToRadPerSec(m.freq_hz), 2)),
                         static_cast<int>(k)});
        }
        std::sort(vis.rbegin(), vis.rend());
        ASSERT_GE(vis[1].first, 0.1 * vis[0].first) << "the removed mode must be visible by the 10 % rule";
        skip = vis[1].second;
        std::cout << key.ToString() << ": model mode " << skip + 1 << " (" << d.modes[skip].freq_hz
                  << " Hz, relative visibility " << vis[1].first / vis[0].first << ") removed\n";
        removed[key] = skip;
        removed_visibility[key] = vis[1].first / vis[0].first;
      }
      Eigen::VectorXcd g = ModalSum(d, key, f, skip);
      // The extra mode: a peak contribution A / (2ζω²) of 30 % of the
      // largest model mode's in this FRF, well above the 10 % visibility rule.
      double vis_max = 0.0;
      for (const dynamics::Mode& m : d.modes) {
        const double pa = m.p_T(static_cast<int>(a));
        vis_max = std::max(vis_max, pa * pa / (2 * m.damping_ratio * std::pow(HzToRadPerSec(m.freq_hz), 2)));
      }
      const double wx = HzToRadPerSec(kExtraHz);
      const double A = 0.3 * vis_max * 2 * kExtraZeta * wx * wx;
      for (int i = 0; i < f.size(); ++i) {
        const double w = HzToRadPerSec(f(i));
        g(i) += A / std::complex<double>(wx * wx - w * w, 2 * kExtraZeta * wx * w);
      }
      edited.Insert(key, dynamics::Frf::FromSamples(f, g));
    }
  }
  const calibration::ModalFitOptions fo = AuditModalFitOptions({});
  auto analyse = [&](const dynamics::FrfSet& measured) {
    const calibration::MeasuredFeatures features = calibration::ExtractFeatures(measured, fo);
    AuditResult r = ResultWithErrorsOnly(c, measured);
    r.modes_before = calibration::CompareWithMeasurement(c.model, c.postures, measured, features);
    return AnalyzeErrorPatterns(r, c.model, c.postures, measured, features);
  };
  const ErrorPatterns ok = analyse(complete);

  EXPECT_TRUE(ok.unmatched_model.empty()) << ok.unmatched_model.size() << " model modes unmatched, first at "
                                          << ok.unmatched_model.front().key.ToString() << ", "
                                          << ok.unmatched_model.front().freq_hz << " Hz";
  EXPECT_TRUE(ok.unmatched_measured.empty());
  EXPECT_TRUE(ok.frfs_without_modal_fit.empty());

  const ErrorPatterns p = analyse(edited);
  for (const auto& [key, k] : removed) {
    bool found = false;
    for (const UnmatchedMode& u : p.unmatched_model) {
      if (u.key == key && u.model_mode == k) {
        found = true;
        EXPECT_EQ(u.measured_mode, -1);
        // Model modes are unchanged by the edit: the same ratio as above
        // (the band 0.25–500 Hz holds every model mode).
        EXPECT_NEAR(u.relative_visibility, removed_visibility.at(key), 1e-12);
      }
    }
    EXPECT_TRUE(found) << "model mode " << k + 1 << " removed from " << key.ToString() << " is not reported";
  }
  for (const UnmatchedMode& u : p.unmatched_model) {
    EXPECT_TRUE(removed.count(u.key) && removed.at(u.key) == u.model_mode)
        << "unexpected: model mode " << u.model_mode + 1 << " at " << u.key.ToString() << ", " << u.freq_hz << " Hz";
  }
  // The 400 Hz mode in every FRF, fitted within 0.5 % (noise-free data).
  std::set<dynamics::FrfKey> seen;
  for (const UnmatchedMode& u : p.unmatched_measured) {
    EXPECT_NEAR(u.freq_hz / kExtraHz, 1.0, 0.005) << u.key.ToString();
    EXPECT_EQ(u.model_mode, -1);
    seen.insert(u.key);
  }
  EXPECT_EQ(seen.size(), static_cast<size_t>(edited.size()));
}

TEST(ErrorPatterns, RejectsFeaturesThatAreNotTheAuditsAndBadOptions) {
  const Campaign c = MakeCampaign(2, 7);
  const dynamics::FrfSet measured = calibration::SynthesizeHammerTest(c.model, c.poses, {});
  const calibration::MeasuredFeatures features = calibration::ExtractFeatures(measured, AuditModalFitOptions({}));
  AuditResult r = ResultWithErrorsOnly(c, measured);
  r.modes_before = calibration::CompareWithMeasurement(c.model, c.postures, measured, features);
  ASSERT_FALSE(r.modes_before.matches.empty());
  const std::string msg = robomach::testing::CaptureError(
      [&] { AnalyzeErrorPatterns(r, c.model, c.postures, measured, calibration::MeasuredFeatures{}); });
  EXPECT_NE(msg.find("not those of the audit result"), std::string::npos) << msg;
  ErrorPatternOptions bad;
  bad.matching.min_relative_visibility = 0.0;
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
  // Two postures: no correlation is defined (n − 2 = 0 degrees of freedom).
  const ErrorPatterns p = AnalyzeErrorPatterns(r, c.model, c.postures, measured, features);
  EXPECT_TRUE(std::isnan(p.trends.critical_correlation));
  for (const Trend& t : p.trends.trends) {
    EXPECT_TRUE(std::isnan(t.correlation_before)) << t.descriptor;
    EXPECT_FALSE(t.significant_before);
  }
}

}  // namespace
}  // namespace robomach::audit
