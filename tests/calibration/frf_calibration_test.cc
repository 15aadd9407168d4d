// Calibration against virtual hammer tests with known truth (issue #4
// acceptance), the matching of measured to model modes, and fit problems
// reported as a status.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <complex>
#include <random>
#include <set>

#include "robomach/calibration/frf_calibration.h"
#include "robomach/calibration/frf_estimate.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/virtual_hammer_test.h"
#include "robomach/common/golden_section.h"
#include "robomach/common/units.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "realistic_hammer_test.h"
#include "test_support.h"

namespace robomach::calibration {
namespace {

using robomach::testing::SourcePath;
using robomach::testing::TempDir;

// The residual pair without division, atan2 or sin against its definition
// ln|Hm/H|, 2 sin(arg(Hm/H)/2): random pairs over 12 decades of magnitude
// and every phase, and phase errors near 0 and near ±π (where the two
// branches of the chord formula meet their limits).
TEST(WholeCurveResiduals, MatchTheirDefinition) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> phase(-kPi, kPi), decade(-12.0, 0.0);
  const auto reference = [](std::complex<double> hm, std::complex<double> h) {
    const std::complex<double> ratio = hm / h;
    return std::array<double, 2>{std::log(std::abs(ratio)), 2.0 * std::sin(0.5 * std::arg(ratio))};
  };
  const auto check = [&](std::complex<double> hm, std::complex<double> h) {
    const auto a = WholeCurveResiduals(hm, h);
    const auto b = reference(hm, h);
    EXPECT_NEAR(a[0], b[0], 1e-13 * (1.0 + std::abs(b[0]))) << hm << " " << h;
    EXPECT_NEAR(a[1], b[1], 1e-13) << hm << " " << h;
  };
  for (int i = 0; i < 20000; ++i) {
    const std::complex<double> h = std::polar(std::pow(10.0, decade(rng)), phase(rng));
    check(std::polar(std::pow(10.0, decade(rng)), phase(rng)), h);
    // Phase errors of 1e-9..1e-3 rad and within that of ±π.
    const double d = std::pow(10.0, -9.0 + 6.0 * (i % 1000) / 1000.0) * (i % 2 ? 1.0 : -1.0);
    check(h * std::polar(1.3, d), h);
    check(h * std::polar(0.7, kPi - std::abs(d)), h);
    check(h * std::polar(0.7, -kPi + std::abs(d)), h);
  }
}

struct TestCampaign {
  io::RobotConfig cfg;
  dynamics::ParameterSet truth;
  std::vector<NamedPosture> fit_postures, holdout_postures;
  PostureMap postures;
};

// Truth: m6, d6, alpha, beta off the defaults by +20 %, −15 %, +30 %, −25 %
// ("up to 30 %", issue #4). Held-out postures: three more inside the joint
// limits, away from the wrist singularity (q5 far from 0).
TestCampaign MakeSetup() {
  TestCampaign s{io::LoadRobotConfig(SourcePath("config/kr210.yaml")), {}, {}, {}, {}};
  s.truth = s.cfg.parameters;
  s.truth.Set("m6_kg", 1.20 * s.cfg.parameters.Get("m6_kg"));
  s.truth.Set("d6_m", 0.85 * s.cfg.parameters.Get("d6_m"));
  s.truth.Set("alpha_s", 1.30 * s.cfg.parameters.Get("alpha_s"));
  s.truth.Set("beta_per_s", 0.75 * s.cfg.parameters.Get("beta_per_s"));
  for (const io::Posture& p : io::ReadPostureFile(SourcePath("config/postures_demo.csv"), 6)) {
    s.fit_postures.push_back({p.id, p.q});
    s.postures[p.id] = p.q;
  }
  const std::vector<std::pair<std::string, std::vector<double>>> held = {
      {"H1", {15, -70, 95, 20, 50, -30}}, {"H2", {-30, -85, 110, -20, 35, 45}}, {"H3", {45, -50, 70, 0, -55, 0}}};
  for (const auto& [id, deg] : held) {
    Eigen::VectorXd q(6);
    for (int j = 0; j < 6; ++j) q(j) = DegToRad(deg[j]);
    s.holdout_postures.push_back({id, q});
    s.postures[id] = q;
  }
  return s;
}

VirtualHammerOptions NoisyTest(unsigned seed) {
  VirtualHammerOptions o;  // 0.25..500 Hz, 2000 lines, xx and yy
  o.relative_noise = 0.02;
  o.seed = seed;
  return o;
}

void ExpectAcceptance(const TestCampaign& s, const CalibrationResult& r, const dynamics::FrfSet& holdout,
                      const std::string& what) {
  // Issue #4 acceptance targets, stated there: m6 and d6 within 1 %, alpha
  // and beta within 5 %, after calibration natural-frequency errors below
  // 0.5 % and peak-amplitude errors below 3 % at all postures, held-out ones
  // included.
  EXPECT_EQ(r.status, FitStatus::kConverged) << what << ": " << r.message;
  for (const auto& [name, tol] : std::vector<std::pair<std::string, double>>{
           {"m6_kg", 0.01}, {"d6_m", 0.01}, {"alpha_s", 0.05}, {"beta_per_s", 0.05}}) {
    EXPECT_NEAR(r.parameters.Get(name) / s.truth.Get(name), 1.0, tol) << what << ": " << name;
  }
  const auto model = dynamics::RobotModel::Build(s.cfg.description, r.parameters);
  std::vector<std::string> poses_with_matches;
  for (const auto& [label, set] : {std::pair<std::string, const dynamics::FrfSet*>{"fit", nullptr},
                                   {"holdout", &holdout}}) {
    const std::vector<ModeMatch>& matches =
        set ? CompareWithMeasurement(model, s.postures, *set, ExtractFeatures(*set)).matches : r.matches_after;
    std::set<std::string> poses;
    for (const ModeMatch& m : matches) {
      poses.insert(m.key.pose_id);
      EXPECT_LT(std::abs(m.freq_error()), 0.005)
          << what << " " << label << " " << m.key.ToString() << " at " << m.measured_freq_hz << " Hz";
      EXPECT_LT(std::abs(m.peak_error()), 0.03)
          << what << " " << label << " " << m.key.ToString() << " at " << m.measured_freq_hz << " Hz";
    }
    // Every posture contributes matched modes (the table covers all of them).
    EXPECT_EQ(poses.size(), set ? s.holdout_postures.size() : s.fit_postures.size()) << what << " " << label;
  }
}

TEST(FrfCalibration, AcceptanceTwoStageRecoversTruthFromNoisyHammerTests) {
  const TestCampaign s = MakeSetup();
  const auto truth_model = dynamics::RobotModel::Build(s.cfg.description, s.truth);
  const dynamics::FrfSet measured = SynthesizeHammerTest(truth_model, s.fit_postures, NoisyTest(11));
  const dynamics::FrfSet holdout = SynthesizeHammerTest(truth_model, s.holdout_postures, NoisyTest(12));
  const MeasuredFeatures features = ExtractFeatures(measured);
  const CalibrationResult r = Calibrate(s.cfg.description, s.cfg.parameters, s.postures, measured, features);
  ExpectAcceptance(s, r, holdout, "two-stage");
  ASSERT_EQ(r.stages.size(), 2u);
  // The frequency stage holds exactly the parameters that move undamped
  // frequencies; Rayleigh damping does not.
  EXPECT_EQ(r.stages[0].parameters, (std::vector<std::string>{"m6_kg", "d6_m"}));
  EXPECT_EQ(r.stages[1].parameters, (std::vector<std::string>{"alpha_s", "beta_per_s"}));
  // The reported 1-sigma uncertainties are consistent with the actual error:
  // |error| < 5 sigma for every parameter.
  for (const ParameterEstimate& e : r.estimates) {
    EXPECT_LT(std::abs(e.value - s.truth.Get(e.name)), 5.0 * e.std_dev) << e.name;
    EXPECT_FALSE(e.weakly_identified) << e.name;
  }
  // The covariance (issue #37): its diagonal is the reported σ², the stages
  // are independent blocks, and the truth lies inside the 99.9 % ellipsoid
  // of each stage's pair (χ²₂ = 13.8) with the correlation taken into account.
  ASSERT_EQ(r.covariance.rows(), 4);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(std::sqrt(r.covariance(i, i)) / r.estimates[i].std_dev, 1.0, 1e-9) << r.estimates[i].name;
    for (int j = 0; j < 4; ++j) {
      EXPECT_NEAR(r.covariance(i, j), r.covariance(j, i), 1e-12 * r.covariance.cwiseAbs().maxCoeff());
      if ((i < 2) != (j < 2)) {
        EXPECT_EQ(r.covariance(i, j), 0.0) << i << "," << j;
      }
    }
  }
  for (int b = 0; b < 4; b += 2) {
    const Eigen::Matrix2d c = r.covariance.block<2, 2>(b, b);
    EXPECT_LT(std::abs(c(0, 1)) / std::sqrt(c(0, 0) * c(1, 1)), 1.0);
    const Eigen::Vector2d d(r.estimates[b].value - s.truth.Get(r.estimates[b].name),
                            r.estimates[b + 1].value - s.truth.Get(r.estimates[b + 1].name));
    EXPECT_LT(d.dot(c.inverse() * d), 13.8) << r.estimates[b].name << ", " << r.estimates[b + 1].name;
  }
  // What --uncertainty-out writes: log scale, the relative covariance.
  const FittedUncertainty fu = FittedParameterUncertainty(r, "test");
  ASSERT_EQ(fu.uncertainty.parameters.size(), 4u);
  EXPECT_TRUE(fu.left_out.empty());
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(fu.uncertainty.parameters[i].scale, dynamics::UncertainScale::kLog);
    EXPECT_NEAR(std::sqrt(fu.uncertainty.covariance(i, i)), r.estimates[i].std_dev / r.estimates[i].value, 1e-12);
  }
  EXPECT_NO_THROW(dynamics::CheckValid(fu.uncertainty));
}

TEST(FittedParameterUncertainty, LeavesOutWhatTheDataDoNotDetermine) {
  CalibrationResult r;
  r.estimates = {{"m6_kg", "kg", 10, 12, 0.3}, {"d6_m", "m", 0.3, 0.25, 0.5}, {"alpha_s", "s", 1, 1, NAN},
                 {"beta_per_s", "1/s", 1, -0.5, 0.1}};
  r.estimates[2].at_bound = true;
  r.covariance = Eigen::MatrixXd::Constant(4, 4, NAN);
  r.covariance(0, 0) = 0.09;
  r.covariance(1, 1) = 0.25;
  r.covariance(3, 3) = 0.01;
  r.covariance(0, 3) = r.covariance(3, 0) = 0.015;  // correlation 0.5
  r.covariance(0, 1) = r.covariance(1, 0) = 0.0;
  r.covariance(1, 3) = r.covariance(3, 1) = 0.0;
  const FittedUncertainty fu = FittedParameterUncertainty(r, "test");
  ASSERT_EQ(fu.uncertainty.parameters.size(), 2u);
  EXPECT_EQ(fu.uncertainty.parameters[0].name, "m6_kg");
  EXPECT_EQ(fu.uncertainty.parameters[0].scale, dynamics::UncertainScale::kLog);
  EXPECT_EQ(fu.uncertainty.parameters[1].name, "beta_per_s");
  EXPECT_EQ(fu.uncertainty.parameters[1].scale, dynamics::UncertainScale::kLinear);  // a value <= 0
  // log m6: σ 0.3 / 12; the cross term 0.015 / 12 (only m6 on the log scale).
  EXPECT_NEAR(fu.uncertainty.covariance(0, 0), 0.09 / 144, 1e-15);
  EXPECT_NEAR(fu.uncertainty.covariance(0, 1), 0.015 / 12, 1e-15);
  EXPECT_NEAR(fu.uncertainty.covariance(1, 1), 0.01, 1e-15);
  ASSERT_EQ(fu.left_out.size(), 2u);
  EXPECT_NE(fu.left_out[0].find("d6_m: not determined, σ 200 %"), std::string::npos) << fu.left_out[0];
  EXPECT_NE(fu.left_out[1].find("alpha_s: held on a bound"), std::string::npos) << fu.left_out[1];
}

TEST(FrfCalibration, AcceptanceJointAndWholeCurveObjectives) {
  const TestCampaign s = MakeSetup();
  const auto truth_model = dynamics::RobotModel::Build(s.cfg.description, s.truth);
  const dynamics::FrfSet measured = SynthesizeHammerTest(truth_model, s.fit_postures, NoisyTest(21));
  const dynamics::FrfSet holdout = SynthesizeHammerTest(truth_model, s.holdout_postures, NoisyTest(22));
  const MeasuredFeatures features = ExtractFeatures(measured);
  for (Objective obj : {Objective::kModalJoint, Objective::kWholeCurve}) {
    CalibrationOptions o;
    o.objective = obj;
    const CalibrationResult r = Calibrate(s.cfg.description, s.cfg.parameters, s.postures, measured, features, o);
    ExpectAcceptance(s, r, holdout, ToString(obj));
  }
}

// Issue #33 §4, the second line of defence: outlier lines that the noise
// model kept (its outlier detection off here; 300 × the noise, at three
// lines of every FRF, away from the mains) pull a least-squares fit off the
// truth; with the Huber loss at 3 σ (CalibrationOptions::robust_scale) the
// whole-curve fit lands where the fit of the clean data lands. Expected:
// m6 and d6 within 0.5 % of the clean fit, and less than half the spikes'
// pull on the plain fit.
TEST(FrfCalibration, RobustLossKeepsTheFitOffOutliersTheNoiseModelKept) {
  const TestCampaign s = MakeSetup();
  const auto truth_model = dynamics::RobotModel::Build(s.cfg.description, s.truth);
  const dynamics::FrfSet clean = SynthesizeHammerTest(truth_model, s.fit_postures, NoisyTest(33));
  NoiseOptions keep;
  keep.exclude_outlier_lines = false;
  dynamics::FrfSet spiked;
  for (const auto& [key, frf] : clean) {
    Eigen::VectorXcd h = frf.receptance();
    for (double f : {37.25, 143.75, 311.0}) {
      const int i = static_cast<int>(std::lround(f / 0.25)) - 1;
      h(i) *= 1.0 + 300.0 * 0.02;  // 300 × the 2 % noise, in phase
    }
    spiked.Insert(key, dynamics::Frf::FromSamples(frf.freq_hz(), h));
  }
  const dynamics::FrfSet clean_data = UsableData(clean, EstimateNoise(clean, keep));
  const dynamics::FrfSet spiked_data = UsableData(spiked, EstimateNoise(spiked, keep));
  const auto fit = [&](const dynamics::FrfSet& data, double robust) {
    CalibrationOptions o;
    o.objective = Objective::kWholeCurve;
    o.robust_scale = robust;
    return Calibrate(s.cfg.description, s.cfg.parameters, s.postures, data, ExtractFeatures(data), o);
  };
  const CalibrationResult reference = fit(clean_data, 0.0);
  const CalibrationResult plain = fit(spiked_data, 0.0);
  const CalibrationResult robust = fit(spiked_data, 3.0);
  double pull_plain = 0.0, pull_robust = 0.0;
  for (const std::string name : {"m6_kg", "d6_m"}) {
    const double ref = reference.parameters.Get(name);
    pull_plain = std::max(pull_plain, std::abs(plain.parameters.Get(name) / ref - 1.0));
    pull_robust = std::max(pull_robust, std::abs(robust.parameters.Get(name) / ref - 1.0));
    std::printf("%s: clean %.6g, plain %.6g, robust %.6g\n", name.c_str(), ref, plain.parameters.Get(name),
                robust.parameters.Get(name));
  }
  EXPECT_EQ(robust.status, FitStatus::kConverged) << robust.message;
  EXPECT_LT(pull_robust, 0.005);
  EXPECT_LT(pull_robust, 0.5 * pull_plain);  // the loss is what keeps it there
  EXPECT_THROW(fit(spiked_data, -1.0), std::invalid_argument);
}

// ---------------------------------------------------------------------------
// Issue #10: hammer data as they really come. Accelerance files of a
// 5120 Hz test (0.625..2560 Hz, 4096 lines) at 6 postures, 2 % relative
// noise plus an additive floor: flat in acceleration (the accelerometer),
// flat in receptance, and raised above the hammer's 1 kHz cutoff, so that
// the signal-to-noise ratio falls below 1 above roughly 300 Hz and at the
// lowest lines. The end effector is 3 kg heavier and 15 mm longer than the
// config and the damping differs.

TestCampaign MakeRealisticSetup() {
  TestCampaign s{io::LoadRobotConfig(SourcePath("config/kr210.yaml")), {}, {}, {}, {}};
  s.truth = s.cfg.parameters;
  s.truth.Set("m6_kg", s.cfg.parameters.Get("m6_kg") + 3.0);
  s.truth.Set("d6_m", s.cfg.parameters.Get("d6_m") + 0.015);
  s.truth.Set("alpha_s", 1.4 * s.cfg.parameters.Get("alpha_s"));
  s.truth.Set("beta_per_s", 0.8 * s.cfg.parameters.Get("beta_per_s"));
  const std::vector<std::pair<std::string, std::vector<double>>> fit = {
      {"P1", {0, -90, 90, 0, 45, 0}},       {"P2", {30, -60, 100, 10, -40, 20}}, {"P3", {0, -45, 60, 0, 60, 0}},
      {"P4", {-20, -100, 120, 30, 30, 0}}, {"P5", {10, -80, 80, -45, 70, 90}},  robomach::testing::SixthPostureDeg()};
  const std::vector<std::pair<std::string, std::vector<double>>> held = {
      {"H1", {15, -70, 95, 20, 50, -30}}, {"H2", {-30, -85, 110, -20, 35, 45}}};
  for (const auto& [list, out] : {std::pair{&fit, &s.fit_postures}, std::pair{&held, &s.holdout_postures}}) {
    for (const auto& [id, deg] : *list) {
      Eigen::VectorXd q(6);
      for (int j = 0; j < 6; ++j) q(j) = DegToRad(deg[j]);
      out->push_back({id, q});
      s.postures[id] = q;
    }
  }
  return s;
}

VirtualHammerOptions RealisticTest(unsigned seed, bool coherence) {
  return robomach::testing::RealisticHammerTest(seed, coherence);
}

// Through an accelerance CSV file and back, as a user's export would come.
dynamics::FrfSet ViaAccelerance(const dynamics::FrfSet& frfs, const std::string& name, int averages) {
  const std::string path = TempDir("frf_calibration_" + name) + "/" + name + ".csv";
  io::WriteFrfCsv(path, frfs, io::FrfQuantity::kAccelerance, averages);
  const io::FrfReadResult r = io::ReadFrfCsv(path);
  EXPECT_EQ(r.file_quantity, io::FrfQuantity::kAccelerance);
  EXPECT_EQ(r.averages, averages);
  return r.frfs;
}

// The pipeline of frf-calibrate with its defaults: noise model per FRF,
// usable lines with their σ, modal fit, calibration.
dynamics::FrfSet Usable(const dynamics::FrfSet& read, int averages) {
  NoiseOptions no;
  no.averages = averages;
  return UsableData(read, EstimateNoise(read, no));
}

TEST(FrfCalibration, AcceptanceRealisticHammerDataWithAndWithoutCoherence) {
  const TestCampaign s = MakeRealisticSetup();
  const auto truth_model = dynamics::RobotModel::Build(s.cfg.description, s.truth);
  for (bool coherence : {false, true}) {
    const std::string what = coherence ? "with coherence" : "without coherence";
    const int averages = coherence ? 5 : 0;
    const dynamics::FrfSet measured = Usable(
        ViaAccelerance(SynthesizeHammerTest(truth_model, s.fit_postures, RealisticTest(31, coherence)),
                       "realistic_fit_" + std::to_string(coherence), averages),
        averages);
    const dynamics::FrfSet holdout = Usable(
        ViaAccelerance(SynthesizeHammerTest(truth_model, s.holdout_postures, RealisticTest(32, coherence)),
                       "realistic_holdout_" + std::to_string(coherence), averages),
        averages);
    ASSERT_EQ(measured.size(), 12) << what;
    const MeasuredFeatures features = ExtractFeatures(measured);
    for (const auto& [key, fit] : features.fits) {
      EXPECT_EQ(fit.status, SolverStatus::kConverged) << what << " " << key.ToString() << ": " << fit.message;
    }
    const CalibrationResult r = Calibrate(s.cfg.description, s.cfg.parameters, s.postures, measured, features);
    ExpectAcceptance(s, r, holdout, what);
    EXPECT_LT(r.misfit_final, r.misfit_start) << what;
    // A model that is right leaves about one noise variance per residual.
    int lines = 0;
    for (const auto& [k, f] : measured) lines += f.size();
    EXPECT_LT(r.misfit_final / (2.0 * lines), 1.3 * 1.3) << what;
    // frf-calibrate's verdict computes the same rms and does not flag the fit.
    const CalibrationVerdict v = JudgeCalibration(r, measured, CalibrationOptions{});
    EXPECT_EQ(v.residuals, 2 * lines) << what;
    EXPECT_NEAR(v.rms_per_residual_in_noise_units, std::sqrt(r.misfit_final / (2.0 * lines)), 1e-12) << what;
    for (const Finding& f : v.verdict.findings) EXPECT_EQ(f.message.find("misses the data"), std::string::npos) << what;
  }
}

// A hopeless start, and data from another robot (all joints 2.5 times
// softer): whatever the fit does, the result never fits worse than the start.
TEST(FrfCalibration, NeverWorseThanTheStart) {
  const TestCampaign s = MakeRealisticSetup();
  dynamics::ParameterSet other = s.truth;
  for (int j = 1; j <= 6; ++j) {
    const std::string n = "kq" + std::to_string(j) + "_Nm_per_rad";
    other.Set(n, other.Get(n) / 2.5);
  }
  const auto other_model = dynamics::RobotModel::Build(s.cfg.description, other);
  const dynamics::FrfSet measured =
      Usable(SynthesizeHammerTest(other_model, s.fit_postures, RealisticTest(41, false)), 0);
  const MeasuredFeatures features = ExtractFeatures(measured);
  dynamics::ParameterSet hopeless = s.cfg.parameters;
  hopeless.Set("m6_kg", 120.0);
  hopeless.Set("beta_per_s", 200.0);
  for (const auto& [label, start] : {std::pair<std::string, const dynamics::ParameterSet*>{"config", &s.cfg.parameters},
                                     {"hopeless", &hopeless}}) {
    const CalibrationResult r = Calibrate(s.cfg.description, *start, s.postures, measured, features);
    const double m0 = WholeCurveMisfit(s.cfg.description, *start, s.postures, measured);
    const double m1 = WholeCurveMisfit(s.cfg.description, r.parameters, s.postures, measured);
    EXPECT_DOUBLE_EQ(r.misfit_start, m0) << label;
    EXPECT_DOUBLE_EQ(r.misfit_final, m1) << label;
    EXPECT_LE(m1, m0) << label;
    if (r.status == FitStatus::kNotImproved) {
      EXPECT_EQ(r.parameters.values(), start->values()) << label;
      // No covariance of the start values: --uncertainty-out writes none of them.
      const FittedUncertainty fu = FittedParameterUncertainty(r, label);
      EXPECT_TRUE(fu.uncertainty.parameters.empty()) << label;
      EXPECT_EQ(fu.left_out.size(), r.estimates.size()) << label;
    }
    // Another robot: the calibrated model still misses the data by far more
    // than the noise, which the caller reports (frf-calibrate exits 3).
    int lines = 0;
    for (const auto& [k, f] : measured) lines += f.size();
    EXPECT_GT(m1 / (2.0 * lines), 1.3 * 1.3) << label;
    const CalibrationVerdict v = JudgeCalibration(r, measured, CalibrationOptions{});
    EXPECT_EQ(v.status(), RunStatus::kFlagged) << label;
    EXPECT_NEAR(v.rms_per_residual_in_noise_units, std::sqrt(m1 / (2.0 * lines)), 1e-12 * std::sqrt(m1)) << label;
    ASSERT_FALSE(v.verdict.findings.empty()) << label;
    EXPECT_NE(v.verdict.findings.back().message.find("misses the data by"), std::string::npos) << v.verdict.findings.back().message;
    // Without noise models the misfit is no chi^2: no rms, no misfit finding.
    dynamics::FrfSet bare;
    for (const auto& [k, f] : measured) bare.Insert(k, dynamics::Frf::FromSamples(f.freq_hz(), f.receptance()));
    const CalibrationVerdict b = JudgeCalibration(r, bare, CalibrationOptions{});
    EXPECT_TRUE(std::isnan(b.rms_per_residual_in_noise_units)) << label;
    for (const Finding& f : b.verdict.findings) EXPECT_EQ(f.message.find("misses the data"), std::string::npos) << label;
  }
}

// The same data as CSV and as a UFF58 copy: frf-synth rounds to UFF58's 13
// digits, so both files hold identical numbers, and the calibration (a
// deterministic computation) must give bit-identical results.
TEST(FrfCalibration, UffCopyGivesIdenticalResults) {
  const TestCampaign s = MakeSetup();
  const auto truth_model = dynamics::RobotModel::Build(s.cfg.description, s.truth);
  const dynamics::FrfSet synth = SynthesizeHammerTest(truth_model, s.fit_postures, NoisyTest(31));
  const std::string dir = TempDir("calibration_uff_copy");
  io::WriteFrfCsv(dir + "/hammer.csv", synth);
  io::WriteUff58(dir + "/hammer.uff", synth);
  const dynamics::FrfSet from_csv = io::ReadFrfFile(dir + "/hammer.csv").frfs;
  const dynamics::FrfSet from_uff = io::ReadFrfFile(dir + "/hammer.uff").frfs;
  ASSERT_EQ(from_csv.keys(), from_uff.keys());
  for (const auto& [k, f] : from_csv) {
    ASSERT_EQ(f.freq_hz(), from_uff.at(k).freq_hz());
    ASSERT_EQ(f.receptance(), from_uff.at(k).receptance());
  }
  const CalibrationResult a = Calibrate(s.cfg.description, s.cfg.parameters, s.postures, from_csv,
                                        ExtractFeatures(from_csv));
  const CalibrationResult b = Calibrate(s.cfg.description, s.cfg.parameters, s.postures, from_uff,
                                        ExtractFeatures(from_uff));
  ASSERT_EQ(a.estimates.size(), b.estimates.size());
  for (size_t i = 0; i < a.estimates.size(); ++i) {
    EXPECT_EQ(a.estimates[i].value, b.estimates[i].value) << a.estimates[i].name;
    EXPECT_EQ(a.estimates[i].std_dev, b.estimates[i].std_dev) << a.estimates[i].name;
  }
  EXPECT_EQ(a.status, b.status);
}

// Second method: on noise-free data of the default model, the modal fit of
// the "measured" FRFs and the model's own eigen-solution must agree for every
// matched mode. The fitter keeps a mode only if its own peak reaches
// ModalFitOptions::min_relative_contribution (0.5 %) of the local |H|, so a
// very weak mode may be left out; it leaves a misfit of at most ~0.5 % over
// its half-power band (N_hp ≤ 40 of the 2000 lines), i.e. a relative rms over
// the band ≤ 0.5 % · √(40/2000) ≈ 7e-4 per omitted mode: fit residual < 1e-3.
// The matched (strong) modes are fitted with the data's full precision, so
// their natural frequencies agree to ≲ ζ · 1e-3 ≈ 3e-5 and the curve peaks,
// which the omitted modes barely touch (< 0.5 % of |H| spread over their own
// bands, not at these peaks), to a few 1e-4: tolerances 1e-4 and 5e-4.
TEST(FrfCalibration, MatchedModesAgreeWithModelEigenSolutionOnCleanData) {
  const TestCampaign s = MakeSetup();
  const auto model = s.cfg.Build();
  VirtualHammerOptions o;
  o.round_to_uff_precision = false;
  const dynamics::FrfSet clean = SynthesizeHammerTest(model, s.fit_postures, o);
  const MeasuredFeatures features = ExtractFeatures(clean);
  for (const auto& [k, fit] : features.fits) EXPECT_LT(fit.relative_rms_error, 1e-3) << k.ToString();
  const Comparison c = CompareWithMeasurement(model, s.postures, clean, features);
  EXPECT_GE(c.matches.size(), 15u);
  for (const ModeMatch& m : c.matches) {
    EXPECT_LT(std::abs(m.freq_error()), 1e-4) << m.key.ToString() << " " << m.measured_freq_hz;
    EXPECT_LT(std::abs(m.peak_error()), 5e-4) << m.key.ToString() << " " << m.measured_freq_hz;
    // Matched by direction too: the model mode moves the tip along the
    // measured direction (|u| component above 0.1).
    EXPECT_GT(std::abs(m.model_shape_T(static_cast<int>(m.key.response))), 0.1) << m.key.ToString();
  }
  for (const auto& [k, e] : c.whole_curve_error) EXPECT_LT(e, 1e-9) << k.ToString();
}

// One FRF in a band with one mode cannot determine both alpha and beta (one
// peak residual, two parameters): a status in the result, not an exception.
TEST(FrfCalibration, UnidentifiableDampingIsAStatusNotAnException) {
  const TestCampaign s = MakeSetup();
  const auto model = s.cfg.Build();
  VirtualHammerOptions o;
  o.directions = {{Axis::kY, Axis::kY}};
  o.fmin_hz = 12.0;
  o.fmax_hz = 30.0;  // P1: only the 19 Hz mode in y
  const dynamics::FrfSet one = SynthesizeHammerTest(model, {s.fit_postures[0]}, o);
  CalibrationOptions co;
  co.free_parameters = {"alpha_s", "beta_per_s"};
  co.extra_starts = false;  // the modal objective alone (a whole-curve start would see the curve's shape)
  CalibrationResult r;
  ASSERT_NO_THROW(r = Calibrate(s.cfg.description, s.cfg.parameters, s.postures, one, ExtractFeatures(one), co));
  EXPECT_NE(r.status, FitStatus::kConverged);
  EXPECT_FALSE(r.weakly_identified.empty());
  EXPECT_NE(r.message.find("fewer residuals"), std::string::npos) << r.message;
}

TEST(FrfCalibration, RejectsUnknownParameterAndPosture) {
  const TestCampaign s = MakeSetup();
  const auto model = s.cfg.Build();
  VirtualHammerOptions o;
  const dynamics::FrfSet d = SynthesizeHammerTest(model, {{"P9", s.postures.at("P1")}}, o);
  CalibrationOptions co;
  co.free_parameters = {"m7_kg"};
  EXPECT_THROW(Calibrate(s.cfg.description, s.cfg.parameters, s.postures, d, {}, co), std::invalid_argument);
  try {
    Calibrate(s.cfg.description, s.cfg.parameters, s.postures, d, ExtractFeatures(d));
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("posture P9 of the measured FRFs is not in the posture file"),
              std::string::npos);
  }
}

// Issue #34 item 6: the peak of a weak mode is searched within its own
// half-power band, cut at the midpoints to its neighbours, not in
// f_n (1 ± 3ζ), which reached the peak of a stronger neighbour 5-7 % away
// and gave it to the weak mode. Two pairs of close modes of unequal
// strength (ζ = 0.03 each), summed in closed form
// H = Σ 1/(k_r (1 − (f/f_r)²) + i 2 ζ_r k_r f/f_r), noise-free on 2 Hz
// lines of 500-3500 Hz:
// - a 1268 Hz mode 3 x stiffer than a 1180 Hz one 7.5 % below: |H| keeps a
//   local maximum of its own (at 1269.6 Hz, about half the strong peak,
//   after a minimum at 1244.4 Hz: a 0.01 Hz scan of the formula in NumPy),
//   a kMaximum; reference: that local maximum of the analytic |H|, by
//   golden section on [1250, 1300] Hz, where |H| is unimodal;
// - a 2753 Hz mode 10 x stiffer than a 2617 Hz one 5.2 % below: |H| rises
//   monotonically through it towards the strong mode (no extremum in
//   2616-2950 Hz, the same scan), a kShoulder; reference: the analytic |H| at
//   its own resonance 2753 √(1 − 2·0.03²) Hz.
// Tolerances: the fit of noise-free data from four modes reproduces f_n to
// about 1e-4 and |H| to better than 1e-3 (FitModes' own tests). A maximum
// is stationary, so 0.5 %; the shoulder's |H| at f_r moves by ~13 % per 1 %
// of f_r on the neighbour's flank, so 1e-4 in f_n gives 0.13 %; 1 %.
TEST(ExtractFeatures, PeakOfAWeakModeIsItsOwnNotItsStrongNeighbours) {
  struct M {
    double f, z, k;
  };
  const std::vector<M> modes{{1180.0, 0.03, 1e7}, {1268.0, 0.03, 3e7}, {2617.0, 0.03, 1.5e7}, {2753.0, 0.03, 1.5e8}};
  auto H = [&](double f) {
    std::complex<double> h = 0.0;
    for (const M& m : modes) {
      const double r = f / m.f;
      h += 1.0 / std::complex<double>(m.k * (1.0 - r * r), 2.0 * m.z * m.k * r);
    }
    return h;
  };
  const auto mag = [&](double f) { return std::abs(H(f)); };
  const int n = 1501;  // 2 Hz lines: 35 and more in each half-power band
  Eigen::VectorXd f(n);
  Eigen::VectorXcd h(n);
  for (int i = 0; i < n; ++i) {
    f(i) = 500.0 + 2.0 * i;
    h(i) = H(f(i));
  }
  dynamics::FrfSet set;
  const dynamics::FrfKey key{"P1", Axis::kX, Axis::kX};
  set.Insert(key, dynamics::Frf::FromSamples(f, h));
  ModalFitOptions o;
  o.fmin_hz = 500.0;
  o.fmax_hz = 3500.0;
  const MeasuredFeatures feat = ExtractFeatures(set, o);
  ASSERT_EQ(feat.modes.size(), 4u) << feat.fits.at(key).message;
  for (size_t i = 0; i < modes.size(); ++i) {
    EXPECT_NEAR(feat.modes[i].fit.freq_hz / modes[i].f, 1.0, 1e-3) << "mode " << modes[i].f << " Hz";
  }
  const MeasuredMode& weak_peak = feat.modes[1];
  const MeasuredMode& shoulder = feat.modes[3];

  // The weak mode with a maximum of its own: that maximum.
  const auto [f_max, h_max] = GoldenSectionMaximum(mag, 1250.0, 1300.0, 200, 1e-12);
  ASSERT_GT(f_max, 1251.0);  // interior: a local maximum of the formula, not an end of the bracket
  ASSERT_LT(f_max, 1299.0);
  EXPECT_EQ(weak_peak.peak_kind, PeakKind::kMaximum);
  EXPECT_NEAR(weak_peak.peak_magnitude / h_max, 1.0, 0.005);
  EXPECT_NEAR(weak_peak.peak_freq_hz, f_max, 0.5);

  // The shoulder: |H| at its own resonance.
  const double f_r = 2753.0 * std::sqrt(1.0 - 2.0 * 0.03 * 0.03);
  EXPECT_EQ(shoulder.peak_kind, PeakKind::kShoulder);
  EXPECT_NEAR(shoulder.peak_magnitude / mag(f_r), 1.0, 0.01);
  EXPECT_NEAR(shoulder.peak_freq_hz / f_r, 1.0, 1e-3);

  // The strong modes keep their own maxima.
  for (int i : {0, 2}) {
    const auto [fs, hs] = GoldenSectionMaximum(mag, 0.95 * modes[i].f, 1.03 * modes[i].f, 200, 1e-12);
    EXPECT_EQ(feat.modes[i].peak_kind, PeakKind::kMaximum);
    EXPECT_NEAR(feat.modes[i].peak_magnitude / hs, 1.0, 0.005) << "mode " << modes[i].f << " Hz";
    // The weak neighbour's feature is not this peak (as it was with f_n (1 ± 3ζ)).
    EXPECT_LT(feat.modes[i + 1].peak_magnitude, 0.8 * hs);
  }

  // The window by its definition: the half-power band, cut at midpoints.
  const auto [a, b] = PeakSearchWindow(2617.0, 0.03, {1180.0, 2753.0});
  EXPECT_DOUBLE_EQ(a, 2617.0 * 0.97);
  EXPECT_DOUBLE_EQ(b, 0.5 * (2617.0 + 2753.0));
}

// One vocabulary (issue #36): every value of the calibration's enums goes
// through its name and back, and a name that is not one is refused.
TEST(CalibrationNames, RoundTripThroughTheirNames) {
  for (Objective o : {Objective::kModalTwoStage, Objective::kModalJoint, Objective::kWholeCurve}) {
    EXPECT_EQ(ParseObjective(ToString(o)), o) << ToString(o);
  }
  EXPECT_THROW(ParseObjective("modal_joint"), std::invalid_argument);
  for (NoiseSource s : {NoiseSource::kCoherence, NoiseSource::kScatter}) {
    EXPECT_EQ(ParseNoiseSource(ToString(s)), s) << ToString(s);
  }
  EXPECT_THROW(ParseNoiseSource("spread"), std::invalid_argument);
  for (HitStatus s : {HitStatus::kAccepted, HitStatus::kDoubleHit, HitStatus::kOverload}) {
    EXPECT_EQ(ParseHitStatus(ToString(s)), s) << ToString(s);
  }
  EXPECT_THROW(ParseHitStatus("double_hit"), std::invalid_argument);
}

}  // namespace
}  // namespace robomach::calibration
