// frf-modes' work (calibration::AnalyseModes, issue #34 §3) against the
// model's own eigen-solution: a KR210 hammer test (xx, yy, xy; 1 % noise
// plus an additive floor, as measured data have) is analysed with common
// poles, and the tool-tip modal table must give the modes of the model's
// generalized eigenproblem K φ = λ M φ (PostureEvaluator, which shares no
// code with the modal fit): frequency, damping, in-plane modal mass and
// shape.

#include <cmath>
#include <random>
#include <tuple>

#include <Eigen/Eigenvalues>

#include <gtest/gtest.h>

#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/modal_analysis.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/common/units.h"
#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach::calibration {
namespace {

using robomach::testing::SourcePath;
constexpr double kPi = 3.14159265358979323846;

TEST(ModalAnalysis, Kr210HammerTestGivesTheModelsModes) {
  const io::RobotConfig cfg = io::LoadRobotConfig(SourcePath("config/kr210.yaml"));
  const auto model = dynamics::RobotModel::Build(cfg.description, cfg.parameters);
  Eigen::VectorXd q(6);
  q << DegToRad(10), DegToRad(-60), DegToRad(90), DegToRad(15), DegToRad(45), DegToRad(-20);
  VirtualHammerOptions o;
  o.directions = {{Axis::kX, Axis::kX}, {Axis::kY, Axis::kY}, {Axis::kX, Axis::kY}};
  o.relative_noise = 0.01;
  o.absolute_noise_m_per_s2_per_N = 2e-4;  // an accelerometer's floor
  o.seed = 3441;
  const dynamics::FrfSet measured = SynthesizeHammerTest(model, {{"P", q}}, o);
  const NoiseModels noise = EstimateNoise(measured);
  const std::vector<PoseModes> poses = AnalyseModes(measured, noise);
  ASSERT_EQ(poses.size(), 1u);
  const PoseModes& pm = poses.front();
  ASSERT_EQ(pm.groups.size(), 1u) << "the three FRFs fitted together";
  ASSERT_EQ(pm.groups[0].fit.status, SolverStatus::kConverged) << pm.groups[0].fit.message;

  dynamics::PostureEvaluator ev(model);
  const dynamics::PostureDynamics d = ev.Evaluate(q);
  // The modes visible in the xx or yy receptance: peak |p_d|²/(2ζω²) of at
  // least 10 % of the largest such peak.
  double largest = 0.0;
  for (const dynamics::Mode& m : d.modes) {
    const double w = HzToRadPerSec(m.freq_hz);
    for (int a = 0; a < 2; ++a) largest = std::max(largest, m.p_T(a) * m.p_T(a) / (2 * m.damping_ratio * w * w));
  }
  int checked = 0;
  for (const dynamics::Mode& m : d.modes) {
    const double w = HzToRadPerSec(m.freq_hz);
    double peak = 0.0;
    for (int a = 0; a < 2; ++a) peak = std::max(peak, m.p_T(a) * m.p_T(a) / (2 * m.damping_ratio * w * w));
    if (peak < 0.1 * largest) continue;
    ++checked;
    const TipMode* found = nullptr;
    for (const TipMode& t : pm.tip_modes) {
      if (std::abs(t.freq_hz - m.freq_hz) < 0.01 * m.freq_hz) found = &t;
    }
    ASSERT_NE(found, nullptr) << "model mode at " << m.freq_hz << " Hz not found";
    EXPECT_NEAR(found->freq_hz, m.freq_hz, 0.003 * m.freq_hz);
    EXPECT_NEAR(found->damping_ratio, m.damping_ratio, 0.05 * m.damping_ratio) << m.freq_hz << " Hz";
    // In-plane: 1/m_xy = p_x² + p_y², shape (p_x, p_y) / |.|.
    const double inv = m.p_T(0) * m.p_T(0) + m.p_T(1) * m.p_T(1);
    EXPECT_NEAR(found->modal_mass_kg, 1.0 / inv, 0.05 / inv) << m.freq_hz << " Hz";
    const Eigen::Vector2d u_model = m.p_T.head<2>() / std::sqrt(inv);
    const double cosine = std::abs(u_model.dot(found->shape.head<2>()));
    EXPECT_GT(cosine, 0.99) << m.freq_hz << " Hz: shape " << found->shape.transpose() << " vs " << u_model.transpose();
    EXPECT_EQ(found->directions, "xy");
  }
  EXPECT_GE(checked, 2);
  // Misfit at the noise: the noise model's σ is what the fit is judged by.
  for (double ns : pm.groups[0].fit.misfit_in_noise) EXPECT_LT(ns, 1.5);
}

// The same hammer test without its cross FRF (xx and yy only): a mode seen
// in both directions has a shape whose relative sign no FRF gives, and
// either sign couples the directions oppositely in a chatter model. The
// modal table gives such a mode once per direction (no coupling), each
// with the modal mass of its direction, 1/p_x² and 1/p_y² of the model's
// eigen-solution, and a warning names the modes and the cross FRF that
// would resolve them. (Before, both components came out positive,
// silently: stability-lobes from such a table was off by a factor 5.)
TEST(ModalAnalysis, ModeInTwoDirectionsWithoutACrossFrfIsOneModePerDirection) {
  const io::RobotConfig cfg = io::LoadRobotConfig(SourcePath("config/kr210.yaml"));
  const auto model = dynamics::RobotModel::Build(cfg.description, cfg.parameters);
  Eigen::VectorXd q(6);
  q << DegToRad(10), DegToRad(-60), DegToRad(90), DegToRad(15), DegToRad(45), DegToRad(-20);
  VirtualHammerOptions o;
  o.directions = {{Axis::kX, Axis::kX}, {Axis::kY, Axis::kY}};
  o.relative_noise = 0.01;
  o.seed = 3442;
  const dynamics::FrfSet measured = SynthesizeHammerTest(model, {{"P", q}}, o);
  const std::vector<PoseModes> poses = AnalyseModes(measured, EstimateNoise(measured));
  ASSERT_EQ(poses.size(), 1u);
  const PoseModes& pm = poses.front();
  bool warned = false;
  for (const std::string& w : pm.warnings) warned |= w.find("no cross FRF") != std::string::npos;
  EXPECT_TRUE(warned);
  dynamics::PostureEvaluator ev(model);
  const dynamics::PostureDynamics d = ev.Evaluate(q);
  int checked = 0;
  for (const dynamics::Mode& m : d.modes) {
    const double w = HzToRadPerSec(m.freq_hz);
    // Both directions clearly visible: each direction's peak |p_a|²/(2ζω²)
    // at least 5e-8 m/N (a few % of the largest).
    bool both = true;
    for (int a = 0; a < 2; ++a) both = both && m.p_T(a) * m.p_T(a) / (2 * m.damping_ratio * w * w) > 5e-8;
    if (!both) continue;
    for (int a = 0; a < 2; ++a) {
      const TipMode* found = nullptr;
      for (const TipMode& t : pm.tip_modes) {
        if (std::abs(t.freq_hz - m.freq_hz) < 0.01 * m.freq_hz && t.directions == std::string(1, "xy"[a])) found = &t;
      }
      ASSERT_NE(found, nullptr) << m.freq_hz << " Hz in " << "xy"[a];
      EXPECT_DOUBLE_EQ(found->shape(a), 1.0);
      EXPECT_EQ(found->shape.norm(), 1.0);
      const double mass = 1.0 / (m.p_T(a) * m.p_T(a));
      EXPECT_NEAR(found->modal_mass_kg, mass, 0.05 * mass) << m.freq_hz << " Hz in " << "xy"[a];
    }
    ++checked;
  }
  EXPECT_GE(checked, 1);
  for (const TipMode& t : pm.tip_modes) EXPECT_EQ(t.directions.size(), 1u) << t.freq_hz << " Hz";
}

// One transfer FRF (response at point 1, excitation at point 56, as
// ufffiles_jl's dataset58_FRF.unv is): its modes are fitted, but none has
// a modal mass, so the modal table is empty; a warning says why and where
// the modes are (before, the table came out empty without a word).
TEST(ModalAnalysis, OneTransferFrfGivesNoModalTableAndSaysWhy) {
  const io::RobotConfig cfg = io::LoadRobotConfig(SourcePath("config/kr210.yaml"));
  const auto model = dynamics::RobotModel::Build(cfg.description, cfg.parameters);
  Eigen::VectorXd q(6);
  q << 0.2, -1.0, 1.5, 0.2, 0.8, -0.3;
  VirtualHammerOptions o;
  o.directions = {{Axis::kX, Axis::kX}};
  o.relative_noise = 0.01;
  const dynamics::FrfSet one = SynthesizeHammerTest(model, {{"P", q}}, o);
  dynamics::FrfSet transfer;
  for (const auto& [key, frf] : one) {
    dynamics::FrfKey k = key;
    k.response_point = 1;
    k.excitation_point = 56;
    transfer.Insert(k, frf);
  }
  const auto poses = AnalyseModes(transfer, EstimateNoise(transfer));
  ASSERT_EQ(poses.size(), 1u);
  ASSERT_EQ(poses[0].groups.size(), 1u);
  EXPECT_FALSE(poses[0].groups[0].fit.modes.empty());
  EXPECT_TRUE(poses[0].tip_modes.empty());
  bool said = false;
  for (const std::string& w : poses[0].warnings) {
    said |= w.find("no driving-point FRF") != std::string::npos && w.find("at point 56") != std::string::npos &&
            w.find("--modal-constants") != std::string::npos;
  }
  EXPECT_TRUE(said);
  // One FRF is no roving test: no mode shapes (frf-modes' --shapes has no
  // rows), and a note naming the posture and the fit when the fit converged.
  std::vector<std::string> notes;
  EXPECT_TRUE(ShapesOfRovingTests(poses, &notes).empty());
  if (poses[0].groups[0].fit.status == SolverStatus::kConverged) {
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_EQ(notes[0].rfind("posture P, fit 1: no mode shapes: ", 0), 0u) << notes[0];
  }
}

TEST(ModalAnalysis, FrfsOnDifferentGridsAreFittedAloneWithAWarning) {
  const io::RobotConfig cfg = io::LoadRobotConfig(SourcePath("config/kr210.yaml"));
  const auto model = dynamics::RobotModel::Build(cfg.description, cfg.parameters);
  Eigen::VectorXd q(6);
  q << 0.2, -1.0, 1.5, 0.2, 0.8, -0.3;
  VirtualHammerOptions a;
  a.relative_noise = 0.01;
  VirtualHammerOptions b = a;
  b.directions = {{Axis::kY, Axis::kY}};
  a.directions = {{Axis::kX, Axis::kX}};
  b.block_samples = 10240;  // 0.5 Hz lines
  dynamics::FrfSet set = SynthesizeHammerTest(model, {{"P", q}}, a);
  set.Merge(SynthesizeHammerTest(model, {{"P", q}}, b));
  const auto poses = AnalyseModes(set, EstimateNoise(set));
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_EQ(poses[0].groups.size(), 2u);
  ASSERT_FALSE(poses[0].warnings.empty());
  EXPECT_NE(poses[0].warnings[0].find("different frequency lines"), std::string::npos) << poses[0].warnings[0];
}

// A band to fit above the measured lines (a user's --fmin-hz beyond the
// file's band): no fit, and a warning that says where the lines are, so
// that the posture is flagged rather than silently empty.
TEST(ModalAnalysis, BandWithoutAMeasuredLineIsAWarningNamingTheLines) {
  const io::RobotConfig cfg = io::LoadRobotConfig(SourcePath("config/kr210.yaml"));
  const auto model = dynamics::RobotModel::Build(cfg.description, cfg.parameters);
  Eigen::VectorXd q(6);
  q << 0.2, -1.0, 1.5, 0.2, 0.8, -0.3;
  VirtualHammerOptions h;
  h.directions = {{Axis::kX, Axis::kX}};
  h.relative_noise = 0.01;
  const dynamics::FrfSet set = SynthesizeHammerTest(model, {{"P", q}}, h);
  const double top_hz = set.begin()->second.freq_hz().maxCoeff();
  ModalAnalysisOptions o;
  o.fit.fmin_hz = 2.0 * top_hz;
  const auto poses = AnalyseModes(set, EstimateNoise(set), o);
  ASSERT_EQ(poses.size(), 1u);
  ASSERT_EQ(poses[0].groups.size(), 1u);
  EXPECT_NE(poses[0].groups[0].fit.status, SolverStatus::kConverged);
  EXPECT_TRUE(poses[0].tip_modes.empty());
  ASSERT_EQ(poses[0].warnings.size(), 1u);
  const std::string& w = poses[0].warnings[0];
  EXPECT_NE(w.find("no usable line in the band to fit"), std::string::npos) << w;
  EXPECT_NE(w.find("its lines span"), std::string::npos) << w;
  EXPECT_NE(w.find("usable "), std::string::npos) << w;
}

// A roving-sensor test of a 4-DOF chain (ground-k-m-k-m-k-m-k-m, masses
// and stiffnesses unequal, Rayleigh damping): the hammer stays at mass 2,
// the sensor roves over masses 1-4, with 1 % noise. The reference is the
// chain's own generalized eigenproblem K φ = ω² M φ (Eigen), mass-normalised
// φᵀ M φ = 1: AnalyseModes and ShapesOfRovingTest must find the roving end
// (the response), the four frequencies, and the mass-normalised shapes
// (the driving point 2 -> 2 is among the FRFs), MAC >= 0.999 and the scale
// within 2 %; the tool-tip modal mass is that of the driving point,
// 1/φ_2².
TEST(ModalAnalysis, RovingSensorOnAChainGivesItsMassNormalisedShapes) {
  const Eigen::Vector4d m(2.0, 1.5, 1.0, 0.8), k(4e5, 3e5, 2.5e5, 1.5e5);
  Eigen::Matrix4d M = m.asDiagonal(), K = Eigen::Matrix4d::Zero();
  for (int i = 0; i < 4; ++i) {
    K(i, i) += k(i);
    if (i + 1 < 4) {
      K(i, i) += k(i + 1);
      K(i, i + 1) -= k(i + 1);
      K(i + 1, i) -= k(i + 1);
    }
  }
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix4d> eig(K, M);
  const Eigen::Vector4d w2 = eig.eigenvalues();
  const Eigen::Matrix4d phi = eig.eigenvectors();  // φᵀ M φ = I
  const Eigen::Matrix4d C = 2e-4 * K + 2.0 * M;     // Rayleigh
  const double fmax = 1.3 * std::sqrt(w2(3)) / (2.0 * kPi);
  const int n = 3000;
  Eigen::VectorXd f(n);
  for (int i = 0; i < n; ++i) f(i) = (i + 1) * fmax / n;
  std::mt19937 rng(3407);
  std::normal_distribution<double> g(0.0, 1.0);
  dynamics::FrfSet set;
  const int hammer = 1;  // mass 2 (points are numbered from 1)
  for (int j = 0; j < 4; ++j) {
    Eigen::VectorXcd h(n);
    for (int i = 0; i < n; ++i) {
      const double w = 2.0 * kPi * f(i);
      const Eigen::Matrix4cd D = K.cast<std::complex<double>>() - w * w * M.cast<std::complex<double>>() +
                                 std::complex<double>(0.0, w) * C.cast<std::complex<double>>();
      Eigen::Vector4cd e = Eigen::Vector4cd::Zero();
      e(hammer) = 1.0;
      const std::complex<double> x = D.partialPivLu().solve(e)(j);
      h(i) = x * (1.0 + 0.01 / std::sqrt(2.0) * std::complex<double>(g(rng), g(rng)));
    }
    set.Insert({"R", Axis::kZ, Axis::kZ, j + 1, hammer + 1}, dynamics::Frf::FromSamples(f, h));
  }
  const auto poses = AnalyseModes(set, EstimateNoise(set));
  ASSERT_EQ(poses.size(), 1u);
  ASSERT_EQ(poses[0].groups.size(), 1u);
  const ModalGroup& grp = poses[0].groups[0];
  ASSERT_EQ(grp.fit.status, SolverStatus::kConverged) << grp.fit.message;
  ASSERT_EQ(grp.fit.modes.size(), 4u) << grp.fit.message;
  std::string why;
  const auto rs = ShapesOfRovingTest(grp, &why);
  ASSERT_TRUE(rs.has_value()) << why;
  EXPECT_EQ(rs->roving, "response");
  EXPECT_EQ(rs->fixed_point, hammer + 1);
  EXPECT_TRUE(rs->mass_normalised);
  // frf-modes' --shapes (what io::ModeShapesCsv writes): this fit's shapes,
  // and no note.
  std::vector<std::string> notes;
  const std::vector<FitRovingShapes> all = ShapesOfRovingTests(poses, &notes);
  EXPECT_TRUE(notes.empty());
  ASSERT_EQ(all.size(), 1u);
  EXPECT_EQ(all[0].pose, 0u);
  EXPECT_EQ(all[0].fit, 0u);
  EXPECT_EQ(all[0].shapes.points, rs->points);
  EXPECT_TRUE(all[0].shapes.shapes.isApprox(rs->shapes));
  for (int r = 0; r < 4; ++r) {
    const double fn = std::sqrt(w2(r)) / (2.0 * kPi);
    EXPECT_NEAR(grp.fit.modes[r].freq_hz, fn, 0.002 * fn) << "mode " << r + 1;
    Eigen::Vector4cd fitted;
    for (int j = 0; j < 4; ++j) fitted(rs->points[j] - 1) = rs->shapes(j, r);
    const Eigen::Vector4cd ref = phi.col(r).cast<std::complex<double>>();
    const double mac = std::norm(ref.dot(fitted)) / (ref.squaredNorm() * fitted.squaredNorm());
    EXPECT_GE(mac, 0.999) << "mode " << r + 1;
    const double scale = std::abs(ref.dot(fitted)) / ref.squaredNorm();
    EXPECT_NEAR(scale, 1.0, 0.02) << "mode " << r + 1;
  }
  // The modal table's mass: the driving point's, 1/φ_2².
  ASSERT_EQ(poses[0].tip_modes.size(), 4u);
  for (int r = 0; r < 4; ++r) {
    EXPECT_NEAR(poses[0].tip_modes[r].modal_mass_kg, 1.0 / std::pow(phi(hammer, r), 2),
                0.03 / std::pow(phi(hammer, r), 2))
        << "mode " << r + 1;
  }
}

// A mode whose half-power bandwidth is far under the line spacing (ζ = 2e-4
// at 100.5 Hz on 1 Hz lines: 0.04 Hz) is named: its damping is not in the
// data. The same mode on 0.005 Hz lines around it is not.
TEST(ModalAnalysis, ModeNarrowerThanTheLineSpacingIsNamed) {
  auto frf = [](double df, double f0, double f1) {
    const int n = static_cast<int>(std::round((f1 - f0) / df)) + 1;
    Eigen::VectorXd f(n);
    Eigen::VectorXcd h(n);
    for (int i = 0; i < n; ++i) {
      f(i) = f0 + i * df;
      h(i) = 0.0;
      for (const auto& [fn, z, a] : {std::tuple{100.5, 2e-4, 1.0}, std::tuple{160.25, 0.02, 2.0}}) {
        const double wn = 2.0 * kPi * fn, w = 2.0 * kPi * f(i);
        h(i) += a / (wn * wn - w * w + std::complex<double>(0.0, 2.0 * z * wn * w));
      }
    }
    dynamics::FrfSet set;
    set.Insert({"P", Axis::kX, Axis::kX}, dynamics::Frf::FromSamples(f, h));
    return set;
  };
  auto named = [](const std::vector<PoseModes>& p) {
    for (const std::string& w : p.at(0).warnings) {
      if (w.find("under half the line spacing") != std::string::npos && w.find("100.5") != std::string::npos) {
        return true;
      }
    }
    return false;
  };
  EXPECT_TRUE(named(AnalyseModes(frf(1.0, 20.0, 400.0), {})));
  const auto fine = AnalyseModes(frf(0.005, 95.0, 106.0), {});
  EXPECT_FALSE(named(fine));
  ASSERT_EQ(fine.at(0).groups.size(), 1u);
  bool found = false;
  for (const GlobalMode& m : fine[0].groups[0].fit.modes) {
    found = found || (std::abs(m.freq_hz - 100.5) < 0.01 && std::abs(m.damping_ratio - 2e-4) < 2e-5);
  }
  EXPECT_TRUE(found) << fine[0].groups[0].fit.message;
}

}  // namespace
}  // namespace robomach::calibration
