// End to end in the library: synthesize what the machine records for a
// programmed path (rotary errors and compensation tables on), write the raw
// quadrature capture with glitches, decode it, acquire the tool path; the
// programmed tool tip comes back within the encoder resolution. With the
// compensation and the rotary errors switched off in the acquisition, the
// error is what they predict.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "robomach/common/units.h"
#include "robomach/machine/acquisition.h"
#include "robomach/machine/nutating_head_rotary_table.h"
#include "robomach/machine/quadrature_decoder.h"
#include "robomach/machine/synthesis.h"

namespace robomach::machine {
namespace {

NutatingHeadGeometry Geometry() {
  NutatingHeadGeometry g;
  g.nutation = DegToRad(45.0);
  g.pivot_length = 0.300;
  g.tool_length = 0.120;
  g.c_centre = {0.400, -0.500};
  g.zero_offset = {0.350, -0.520, -0.600};
  g.b_eccentricity = {4e-6, -3e-6};
  g.pivot_length_error = 6e-6;
  g.c_eccentricity = {5e-6, 2e-6};
  return g;
}

Machine MakeMachine(const NutatingHeadGeometry& g) {
  Machine m;
  m.axes = {{"X", AxisKind::kLinear, 0.5e-6, 0.0},  {"Y", AxisKind::kLinear, 0.5e-6, 0.0},
            {"Z", AxisKind::kLinear, 0.5e-6, 0.0},  {"B", AxisKind::kRotary, DegToRad(1e-4), 0.0},
            {"C", AxisKind::kRotary, DegToRad(1e-4), 0.0}};
  m.kinematics = std::make_shared<NutatingHeadRotaryTable>(g);
  m.kinematic_axis = MapKinematicAxes(m.axes, *m.kinematics);
  return m;
}

// Tables of a few micrometres on X, Y, Z, sag of Z over X, temperature on X
// switching at 0.5 s; with_rotary adds a C table.
Compensation MakeCompensation(bool with_rotary) {
  std::vector<EncoderCompensation> enc{
      {0, {0.0, 0.05, {0.0, 2.1e-6, 1.0e-6, -0.5e-6, 0.8e-6, 1.6e-6, 2.0e-6, 1.1e-6, 0.3e-6, 0.0, -1e-6,
                       -2e-6, -1e-6, 0.0, 1e-6, 2e-6, 2.5e-6}}},
      {1, {-1.05, 0.15, {0.0, -1.5e-6, -2.5e-6, -1.0e-6, 0.5e-6, 1.5e-6, 0.0, -0.5e-6}}},
      {2, {-0.85, 0.1, {1e-6, 2e-6, 3e-6, 2e-6, 1e-6, 0.0, -1e-6, -2e-6, -1e-6, 0.0}}}};
  if (with_rotary) enc.push_back({4, {0.0, DegToRad(30.0), std::vector<double>(13, DegToRad(0.0015))}});
  for (int i = 0; with_rotary && i < 13; ++i) enc.back().table.values[i] = DegToRad(0.0015 * std::sin(i * kPi / 6));
  std::vector<CrossAxisCompensation> cec{{0, 2, {0.0, 0.1, {0.0, -0.4e-6, -0.8e-6, -1.1e-6, -1.2e-6, -1.1e-6, -0.8e-6,
                                                             -0.4e-6, 0.0}}}};
  std::vector<TemperatureCompensation> temp{{0, {{0.0, 1e-6, 1.2e-5, 0.4}, {0.5, 2e-6, 1.5e-5, 0.4}}}};
  return Compensation(5, enc, cec, temp);
}

ProgrammedPath Path() {
  // 21 mm in workpiece coordinates with the tool axis tilting ~17-20° and
  // turning ~30° about Z (B and C both move).
  return ProgrammedPath({{0.0, 0.0, 0.02}, {0.010, 0.005, 0.02}, {0.015, 0.015, 0.025}},
                        {{0.3, 0.0, 1.0}, {0.3, 0.1, 1.0}, {0.25, 0.15, 1.0}});
}

struct SynthRun {
  CountsRecord decoded;
  SynthesisResult synth;
  SynthesisOptions options;
};

SynthRun SynthesizeAndDecode(const Machine& truth, const Compensation& comp) {
  SynthRun run;
  run.options.feed = 0.010;  // 600 mm/min
  run.options.sample_rate_hz = 8000.0;
  run.options.initial_guess = {0, 0, 0, DegToRad(-90.0), 0};
  const ProgrammedPath path = Path();
  const std::vector<double> origin = StartMeasured(truth, &comp, path, run.options);
  run.synth = SynthesizeCounts(truth, &comp, path, run.options, origin);
  EXPECT_TRUE(run.synth.ok) << run.synth.message;
  const auto& rec = run.synth.record;
  // Capture at 64 x 8 kHz with glitches; decoded with a 2-sample glitch filter
  // and read every 64th sample.
  const int every = 64;
  CaptureSynthesizer cap(5, every, 2, 0.02, 9);
  std::vector<std::uint16_t> words;
  cap.Start(rec.counts.data(), &words);
  for (long r = 1; r < rec.rows(); ++r) cap.Next(rec.counts.data() + r * 5, &words);
  EXPECT_GT(cap.glitches(), 1000);
  QuadratureDecoder dec({.num_axes = 5, .glitch_filter_samples = 2});
  run.decoded.num_axes = 5;
  for (size_t s = 0; s < words.size(); s += every) {
    dec.Decode(words.data() + (s == 0 ? 0 : s - every + 1), s == 0 ? 1 : every);
    run.decoded.t_s.push_back(static_cast<double>(s / every) / run.options.sample_rate_hz);
    for (int a = 0; a < 5; ++a) run.decoded.counts.push_back(dec.count(a));
  }
  for (int a = 0; a < 5; ++a) EXPECT_EQ(dec.error_events()[a], 0);
  return run;
}

TEST(EndToEnd, SynthCaptureDecodeAcquireGivesBackTheProgrammedTipWithinEncoderResolution) {
  Machine truth = MakeMachine(Geometry());
  const Compensation comp = MakeCompensation(/*with_rotary=*/true);
  const SynthRun run = SynthesizeAndDecode(truth, comp);
  // Decoding gives back the counts exactly.
  ASSERT_EQ(run.decoded.counts.size(), run.synth.record.counts.size());
  EXPECT_EQ(run.decoded.counts, run.synth.record.counts);

  Machine acquired_machine = truth;
  for (int a = 0; a < 5; ++a) acquired_machine.axes[a].origin = run.synth.start_measured[a];
  Acquisition acq(acquired_machine, &comp);
  const ProgrammedPath path = Path();
  ContourTracker tracker(path);
  double worst_tip = 0.0, worst_axis = 0.0, worst_contour = 0.0;
  for (long r = 0; r < run.decoded.rows(); ++r) {
    const double t = run.decoded.t_s[r];
    const AcquiredSample& s = acq.Process(t, run.decoded.counts.data() + r * 5);
    const ToolPose want = path.At(std::max(0.0, t - run.options.dwell) * run.options.feed);
    worst_tip = std::max(worst_tip, (s.pose.p_W - want.p_W).norm());
    worst_axis = std::max(worst_axis, std::acos(std::min(1.0, s.pose.k_W.dot(want.k_W))));
    worst_contour = std::max(worst_contour, tracker.Next(s.pose).distance);
  }
  // Quantisation alone: +-0.25 µm per linear axis (0.43 µm together), B +-5e-5°
  // at the 420 mm pivot-to-tip arm (0.37 µm), C +-5e-5° at < 0.2 m from its
  // axis (0.17 µm): < 1 µm. The seed's accuracy scale is +-2 µm.
  EXPECT_LT(worst_tip, 1.0e-6);
  EXPECT_LT(worst_contour, worst_tip + 1e-12);
  // Axis: B and C quantisation, each <= 5e-5°: < 1e-4°.
  EXPECT_LT(RadToDeg(worst_axis), 1e-4);
  std::cout << "worst tip error " << worst_tip * 1e6 << " um, axis " << RadToDeg(worst_axis) << " deg\n";
}

TEST(EndToEnd, WithoutCompensationAndRotaryErrorsTheErrorIsWhatTheyPredict) {
  const NutatingHeadGeometry g = Geometry();
  Machine truth = MakeMachine(g);
  const Compensation comp = MakeCompensation(/*with_rotary=*/false);
  const SynthRun run = SynthesizeAndDecode(truth, comp);
  // The acquisition ignores the tables and uses the error-free kinematics.
  Machine naive = truth;
  naive.kinematics = truth.kinematics->WithoutErrors();
  for (int a = 0; a < 5; ++a) naive.axes[a].origin = run.synth.start_measured[a];
  Acquisition acq(naive, nullptr);
  const Eigen::Vector3d u(0.0, std::sin(g.nutation), std::cos(g.nutation));
  const Eigen::Vector3d PB(g.b_eccentricity[0], g.b_eccentricity[1], 0.0), PC(g.c_eccentricity[0], g.c_eccentricity[1], 0.0);
  double worst_miss = 0.0, smallest_error = 1.0, largest_error = 0.0;
  std::vector<double> measured(5), offset(5);
  for (long r = 0; r < run.decoded.rows(); r += 7) {
    const double t = run.decoded.t_s[r];
    const AcquiredSample& s = acq.Process(t, run.decoded.counts.data() + r * 5);
    const ToolPose truth_pose = Path().At(std::max(0.0, t - run.options.dwell) * run.options.feed);
    // Prediction from formats.md §8.3 by hand: with measured = real - offset
    // on X, Y, Z (no rotary tables here), the machine-frame tip moves by
    // dp_m = -offset - PB + R(u, B)(0, 0, dL), and the workpiece tip by
    // Rz(-C) dp_m + (Rz(-C) - I) PC.
    for (int a = 0; a < 5; ++a) measured[a] = s.real[a];  // no compensation: real == measured
    comp.Offsets(t, measured.data(), offset.data());
    const double B = s.real[3], C = s.real[4];
    const Eigen::Vector3d dp_m = -Eigen::Vector3d(offset[0], offset[1], offset[2]) - PB +
                                 Eigen::AngleAxisd(B, u) * Eigen::Vector3d(0.0, 0.0, g.pivot_length_error);
    const Eigen::Matrix3d Rz = Eigen::AngleAxisd(-C, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d predicted = Rz * dp_m + (Rz - Eigen::Matrix3d::Identity()) * PC;
    const Eigen::Vector3d actual = s.pose.p_W - truth_pose.p_W;
    worst_miss = std::max(worst_miss, (actual - predicted).norm());
    smallest_error = std::min(smallest_error, actual.norm());
    largest_error = std::max(largest_error, actual.norm());
  }
  // The error itself is several micrometres...
  EXPECT_GT(smallest_error, 3e-6);
  // ...and the prediction matches it to the quantisation (< 1 µm, see above)
  // plus the offsets evaluated at measured instead of real positions
  // (slope 1e-4 x 1e-5 m: negligible).
  EXPECT_LT(worst_miss, 1.0e-6);
  std::cout << "error " << smallest_error * 1e6 << " .. " << largest_error * 1e6 << " um, prediction off by at most "
            << worst_miss * 1e6 << " um\n";
}

}  // namespace
}  // namespace robomach::machine

namespace robomach::machine {
namespace {

// The windowed search against the exhaustive one along a closed circle
// traversed twice, with noise: same distances; and a closed path is
// followed from its start.
TEST(ContourTracker, FollowsAClosedPathLikeTheExhaustiveSearch) {
  std::vector<Eigen::Vector3d> tips, axes;
  for (int i = 0; i <= 360; ++i) {
    const double a = DegToRad(i);
    tips.emplace_back(0.045 * std::cos(a), 0.045 * std::sin(a), 0.02);
    axes.emplace_back(0.2 * std::cos(a), 0.2 * std::sin(a), 1.0);
  }
  const ProgrammedPath path(tips, axes);
  ContourTracker tracker(path);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 2e-6);
  for (int k = 0; k <= 4000; ++k) {
    const double s = path.length() * k / 4000.0;
    ToolPose p = path.At(s);
    p.p_W += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    const ContourError e = tracker.Next(p);
    const ContourError full = tracker.Nearest(p);
    // Followed in order, from the start to the end of the closed path.
    ASSERT_NEAR(e.s, s, 1e-4) << "sample " << k;
    if (k > 0 && k < 4000) {
      ASSERT_NEAR(e.distance, full.distance, 1e-15) << "sample " << k;
    } else {
      // Start and end coincide: the tracker keeps to its end of the path,
      // at most the 10 µm start preference farther than the global nearest.
      ASSERT_LE(e.distance, full.distance + 1e-5) << "sample " << k;
    }
  }
}

// Unit plausibility of contour errors: the 45 mm circle in the xy plane
// followed at a constant normal offset d (the tip moved radially, so the
// contour error is d exactly and the axis error 0). 0.9 mm passes, 1.1 mm
// is flagged (limit 1 mm); an axis tilted by 2° about the tangent is
// flagged (limit 1°), by 0.5° not. X and Y of the machine swapped (the tip
// mirrored about x = y on a circle centred at (20, 0) mm) is flagged.
TEST(ContourUnitFindings, FlagsErrorsBeyondWhatAMachineCanBeOff) {
  std::vector<Eigen::Vector3d> tips, axes;
  for (int i = 0; i <= 360; ++i) {
    const double a = DegToRad(i);
    tips.emplace_back(0.02 + 0.045 * std::cos(a), 0.045 * std::sin(a), 0.02);
    axes.emplace_back(0.0, 0.0, 1.0);
  }
  const ProgrammedPath path(tips, axes);
  auto run = [&](double offset, double tilt, bool swap) {
    ContourTracker tracker(path);
    std::vector<ContourError> c;
    for (int k = 0; k <= 720; ++k) {
      ToolPose p = path.At(path.length() * k / 720.0);
      const Eigen::Vector3d radial = Eigen::Vector3d(p.p_W.x() - 0.02, p.p_W.y(), 0.0).normalized();
      p.p_W += offset * radial;
      const Eigen::Vector3d tangent = Eigen::Vector3d::UnitZ().cross(radial);
      p.k_W = Eigen::AngleAxisd(tilt, tangent) * p.k_W;
      if (swap) std::swap(p.p_W.x(), p.p_W.y());
      c.push_back(tracker.Next(p));
    }
    EXPECT_EQ(JudgeContour(c, path).findings.size(), ContourUnitFindings(c, path).size());
    return ContourUnitFindings(c, path);
  };
  EXPECT_TRUE(run(0.0, 0.0, false).empty());
  EXPECT_TRUE(run(0.9e-3, DegToRad(0.5), false).empty());
  const auto f = run(1.1e-3, 0.0, false);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NE(f[0].find("contour error up to 1.1 mm"), std::string::npos) << f[0];
  EXPECT_NE(f[0].find("swapped"), std::string::npos);
  const auto g = run(0.0, DegToRad(2.0), false);
  ASSERT_EQ(g.size(), 1u);
  EXPECT_NE(g[0].find("tool axis error up to 2 deg"), std::string::npos) << g[0];
  EXPECT_EQ(run(0.0, 0.0, true).size(), 1u);
}

// axis-acquire's verdict: one finding per sentence, prefixed, and exit 3.
TEST(JudgeContour, FlagsEachImplausibleErrorWithItsPrefix) {
  std::vector<Eigen::Vector3d> tips, axes;
  for (int i = 0; i <= 10; ++i) {
    tips.emplace_back(0.01 * i, 0.0, 0.0);
    axes.emplace_back(0.0, 0.0, 1.0);
  }
  const ProgrammedPath path(tips, axes);
  ContourTracker ok_tracker(path), off_tracker(path);
  std::vector<ContourError> ok, off;
  for (int k = 0; k <= 100; ++k) {
    ToolPose p = path.At(path.length() * k / 100.0);
    ok.push_back(ok_tracker.Next(p));
    p.p_W.y() += 5e-3;  // 5 mm off a 100 mm path: beyond the 1 mm limit
    off.push_back(off_tracker.Next(p));
  }
  EXPECT_FALSE(JudgeContour(ok, path).flagged());
  const RunFindings v = JudgeContour(off, path);
  ASSERT_TRUE(v.flagged());
  EXPECT_EQ(v.status(), RunStatus::kFlagged);
  for (const Finding& f : v.findings) {
    EXPECT_EQ(f.message.rfind("implausible (unit or column mistake?): ", 0), 0u) << f.message;
  }
}

}  // namespace
}  // namespace robomach::machine
