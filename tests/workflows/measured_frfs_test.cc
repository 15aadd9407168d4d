// The measured-FRF route of the library (workflows/measured_frfs.h, issue
// #36 §1): files -> FRFs -> noise model -> usable lines, on files written
// here by hand (formats.md §3, no robomach writer) and on real UFF58 exports
// of other software when ../shared is there.

#include "robomach/workflows/measured_frfs.h"

#include <cmath>
#include <complex>
#include <filesystem>
#include <random>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/common/errors.h"
#include "robomach/io/file_kind.h"
#include "test_support.h"

namespace robomach::workflows {
namespace {

using ::testing::HasSubstr;
using robomach::testing::SourcePath;
using robomach::testing::TempDir;
using robomach::testing::WriteText;

constexpr double kPi = 3.14159265358979323846;

// A hammer-test CSV of two postures (xx and yy each), one mode each
// (receptance of a single-DOF oscillator), 2 % relative noise, with the
// coherence that noise gives for 5 averages: γ² = |H|²/(|H|² + 4 σ²),
// σ = 0.02 |H| (formats.md §3; frf-synth --help states the same rule).
// `freq_scale` 1e-3 writes the frequencies in kHz under freq_hz (a user's mistake).
std::string HammerCsv(const std::string& dir, double freq_scale = 1.0) {
  std::ostringstream s;
  s.precision(12);
  s << "# quantity: receptance\n# averages: 5\npose_id,response,excitation,freq_hz,re,im,coherence\n";
  std::mt19937 rng(5);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (const char* pose : {"P1", "P2"}) {
    for (const char* d : {"x", "y"}) {
      const double fn = (pose[1] == '1' ? 420.0 : 530.0) * (d[0] == 'x' ? 1.0 : 1.13), zeta = 0.03, m = 25.0;
      for (int k = 1; k <= 800; ++k) {
        const double f = k * 1.0, w = 2 * kPi * f, wn = 2 * kPi * fn;
        const std::complex<double> h = 1.0 / (m * std::complex<double>(wn * wn - w * w, 2 * zeta * wn * w));
        const std::complex<double> noisy = h * (1.0 + 0.02 * std::complex<double>(n01(rng), n01(rng)) / std::sqrt(2.0));
        const double coh = std::norm(h) / (std::norm(h) + 4.0 * std::pow(0.02 * std::abs(h), 2));
        s << pose << "," << d << "," << d << "," << f * freq_scale << "," << noisy.real() << "," << noisy.imag() << "," << coh
          << "\n";
      }
    }
  }
  return WriteText(dir + (freq_scale == 1.0 ? "/hammer.csv" : "/hammer_scaled.csv"), s.str());
}

// The route on a hand-written CSV: four FRFs read with their file, the
// averages the file declares and its quantity; a noise model per FRF from
// the coherence, whose relative level is the 2 % the file was written with;
// the fit data are the usable lines with σ; the messages tell what was done.
TEST(MeasuredFrfs, HandWrittenCsvGivesItsFrfsNoiseAndUsableLines) {
  const std::string path = HammerCsv(TempDir("workflows_measured"));
  MeasuredFrfOptions o;
  o.files = {path};
  std::vector<Message> said;
  const MeasuredFrfs m = ReadMeasuredFrfs(o, [&](const Message& msg) { said.push_back(msg); });
  ASSERT_EQ(m.frfs.size(), 4);
  for (const auto& [key, frf] : m.frfs) {
    EXPECT_EQ(m.file.at(key), path);
    EXPECT_EQ(m.averages.at(key), 5);
    EXPECT_EQ(m.file_power.at(key), 0);
    const calibration::FrfNoise& n = m.noise.at(key);
    EXPECT_EQ(n.source, calibration::NoiseSource::kCoherence) << n.description;
    EXPECT_NEAR(n.relative, 0.02, 0.002) << key.ToString() << ": " << n.description;
    EXPECT_GT(n.usable_lines, 700) << n.description;
  }
  EXPECT_TRUE(m.unit_findings.empty());
  const dynamics::FrfSet fit = m.FitData();
  ASSERT_EQ(fit.size(), 4);
  for (const auto& [key, frf] : fit) {
    EXPECT_EQ(frf.size(), m.noise.at(key).usable_lines);
    ASSERT_TRUE(frf.noise_sigma().has_value());
  }
  int info = 0;
  for (const Message& msg : said) info += msg.kind == Message::Kind::kInfo;
  EXPECT_EQ(info, 5) << "one line for the noise model, one per FRF";

  // Without a noise model: every line, no σ.
  o.noise_model = NoiseModelChoice::kNone;
  const MeasuredFrfs all = ReadMeasuredFrfs(o);
  EXPECT_TRUE(all.noise.empty());
  for (const auto& [key, frf] : all.FitData()) EXPECT_EQ(frf.size(), 800);
}

// Frequencies in kHz under freq_hz (lines to 0.8 "Hz"; a walkthrough's file
// to 1 kHz ended at 1.0 and passed a 1 Hz threshold): named as such, and
// the receptance is not judged on that axis; the same file in Hz is not.
TEST(MeasuredFrfs, FrequenciesInKilohertzAreNamed) {
  MeasuredFrfOptions o;
  o.noise_model = NoiseModelChoice::kNone;
  o.files = {HammerCsv(TempDir("workflows_khz"), 1e-3)};
  std::vector<Message> said;
  const MeasuredFrfs m = ReadMeasuredFrfs(o, [&](const Message& msg) { said.push_back(msg); });
  ASSERT_EQ(m.unit_findings.size(), 1u);
  EXPECT_THAT(m.unit_findings[0], HasSubstr("hammer_scaled.csv: the FRFs' highest line is at 0.8 Hz, below the 25 Hz "
                                            "a hammer test of a tool tip reaches"));
  EXPECT_THAT(m.unit_findings[0], HasSubstr("frequencies in kHz under the freq_hz header? (0.8 kHz is 800 Hz)"));
  int warned = 0;
  for (const Message& msg : said) warned += msg.kind == Message::Kind::kWarning;
  EXPECT_EQ(warned, 1);
  o.files = {HammerCsv(TempDir("workflows_khz"))};
  EXPECT_TRUE(ReadMeasuredFrfs(o).unit_findings.empty());
}

// What the route refuses, and how: a missing file (io::MissingFileError:
// the tools' exit 66), the same FRF twice, a file whose FRFs name no
// posture without a default, options out of their bounds and an option the
// data cannot meet (OptionError naming the field).
TEST(MeasuredFrfs, RefusalsNameTheFileOrTheOption) {
  const std::string dir = TempDir("workflows_refusals");
  const std::string path = HammerCsv(dir);
  MeasuredFrfOptions o;
  o.files = {dir + "/absent.csv"};
  EXPECT_THROW(ReadMeasuredFrfFiles(o), io::MissingFileError);
  o.files = {path, path};
  EXPECT_THAT(testing::CaptureError([&] { ReadMeasuredFrfFiles(o); }), HasSubstr("was already read from"));
  o.files = {path};
  o.min_snr = 0.0;
  try {
    ReadMeasuredFrfFiles(o);
    ADD_FAILURE() << "min_snr 0 accepted";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), "min_snr");
    EXPECT_THAT(e.what(), HasSubstr("[0.001, 1e6]"));
  }
  o.min_snr = 3.0;
  // A CSV without a coherence column cannot give the coherence model.
  const std::string no_coh = WriteText(dir + "/nocoh.csv",
                                       "pose_id,response,excitation,freq_hz,re,im\nP1,x,x,10,1e-7,-1e-8\n"
                                       "P1,x,x,11,1.1e-7,-1.2e-8\nP1,x,x,12,1.3e-7,-1.5e-8\nP1,x,x,13,1.6e-7,-2e-8\n");
  o.files = {no_coh};
  o.noise_model = NoiseModelChoice::kCoherence;
  const MeasuredFrfs read = ReadMeasuredFrfFiles(o);
  try {
    EstimateNoiseModels(read, o);
    ADD_FAILURE() << "the coherence model on a file without coherence";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), "noise_model");
    EXPECT_THAT(e.what(), HasSubstr("has no coherence"));
  }
  EXPECT_EQ(ParseNoiseModelChoice("scatter"), NoiseModelChoice::kScatter);
  EXPECT_THROW(ParseNoiseModelChoice("coherent"), OptionError);
}

// A real UFF58 export whose records name no posture (UFFFiles.jl's
// dataset58_FRF.unv, a measured mobility between nodes 1 and 56): refused
// without a posture, with a message that names the option to give it; read
// as posture P1 with default_pose, its point numbers kept, its quantity
// (mobility) kept for the misfits, a noise model with usable lines.
TEST(MeasuredFrfs, RealUffWithoutPostureNeedsOne) {
  const std::string uff = SourcePath("../shared/external/frf_uff58/ufffiles_jl/dataset58_FRF.unv");
  if (!std::filesystem::exists(uff)) GTEST_SKIP() << "../shared/external is absent (a clone without ../shared)";
  MeasuredFrfOptions o;
  o.files = {uff};
  o.pose_option = "--pose";
  EXPECT_THAT(testing::CaptureError([&] { ReadMeasuredFrfFiles(o); }), HasSubstr("--pose P1="));
  o.default_pose = "P1";
  o.keep_points = true;
  const MeasuredFrfs m = ReadMeasuredFrfs(o);
  ASSERT_GE(m.frfs.size(), 1);
  for (const auto& [key, frf] : m.frfs) {
    EXPECT_EQ(key.pose_id, "P1");
    EXPECT_EQ(key.response_point, 1);
    EXPECT_EQ(key.excitation_point, 56);
    EXPECT_EQ(m.file_power.at(key), 1) << "mobility";
    EXPECT_GT(m.noise.at(key).usable_lines, 0);
  }
}

}  // namespace
}  // namespace robomach::workflows
