// Readers of the machine files (formats.md §8): every malformed input is
// rejected with its file and line, and the values arrive in SI.
#include "robomach/io/machine_files.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "robomach/common/units.h"
#include "robomach/io/iso_runs_file.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using ::testing::HasSubstr;
using testing::CaptureError;
using testing::SourcePath;
using testing::TempDir;
using testing::WriteText;

MachineFile DefaultMachine() { return ReadMachineFile(SourcePath("config/machine/dmu80p.yaml")); }

TEST(MachineFile, ReadsTheDefaultMachineInSi) {
  const MachineFile f = DefaultMachine();
  ASSERT_EQ(f.machine.axes.size(), 5u);
  EXPECT_EQ(f.machine.axes[0].name, "X");
  EXPECT_EQ(f.machine.axes[3].kind, machine::AxisKind::kRotary);
  EXPECT_DOUBLE_EQ(f.machine.axes[0].resolution, 0.5e-6);
  EXPECT_DOUBLE_EQ(f.machine.axes[4].resolution, DegToRad(1e-4));
  EXPECT_DOUBLE_EQ(f.geometry.pivot_length, 0.3);
  EXPECT_DOUBLE_EQ(f.geometry.pivot_length_error, 6e-6);
  EXPECT_EQ(f.controller_axes.at("AX3"), 2);
  EXPECT_EQ(f.machine.kinematic_axis, (std::vector<int>{0, 1, 2, 3, 4}));
}

TEST(MachineFile, AxisMissingForTheKinematicsIsRejected) {
  const std::string dir = TempDir("machine_files_missing_axis");
  const std::string p = WriteText(dir + "/m.yaml",
                                  "axes:\n  X: {resolution_mm: 0.0005, origin_mm: 0}\n  Y: {resolution_mm: 0.0005, origin_mm: 0}\n"
                                  "  Z: {resolution_mm: 0.0005, origin_mm: 0}\n  B: {resolution_deg: 0.0001, origin_deg: 0}\n"
                                  "kinematics:\n  type: nutating_head_rotary_table\n  nutation_deg: 45\n  pivot_length_mm: 300\n"
                                  "  tool_length_mm: 120\n  c_centre_mm: [400, -500]\n  zero_offset_mm: [0, 0, 0]\n");
  EXPECT_THAT(CaptureError([&] { ReadMachineFile(p); }), HasSubstr("m.yaml:2:3: "));
  EXPECT_THAT(CaptureError([&] { ReadMachineFile(p); }), HasSubstr("needs axis C"));
}

TEST(MachineFile, WriteThenReadRoundTrips) {
  MachineFile f = DefaultMachine();
  f.machine.axes[1].origin = -0.123456789012345;
  const std::string p = TempDir("machine_files_roundtrip") + "/m.yaml";
  WriteMachineFile(p, f);
  const MachineFile g = ReadMachineFile(p);
  EXPECT_NEAR(g.machine.axes[1].origin, f.machine.axes[1].origin, 1e-18);
  EXPECT_DOUBLE_EQ(g.geometry.c_eccentricity[0], f.geometry.c_eccentricity[0]);
  EXPECT_EQ(g.controller_axes, f.controller_axes);
}

const char* kGoodTable =
    "%_N_TEST_MPF\n"
    "CHANDATA(1)\n"
    "$AA_ENC_COMP[0,0,AX1]=0.0     ; point 0\n"
    "$AA_ENC_COMP[0,1,AX1]=0.0021\n"
    "$AA_ENC_COMP[0,2,AX1]=0.0010\n"
    "$AA_ENC_COMP_STEP[0,AX1]=50.0\n"
    "$AA_ENC_COMP_MIN[0,AX1]=0.0\n"
    "$AA_ENC_COMP_MAX[0,AX1]=100.0\n"
    "$AA_ENC_COMP_IS_MODULO[0,AX1]=0\n"
    "N10 $AN_CEC[0,0]=0.0\n"
    "$AN_CEC[0,1]=-0.0012\n"
    "$AN_CEC_INPUT_AXIS[0]=AX1\n"
    "$AN_CEC_OUTPUT_AXIS[0]=AX3\n"
    "$AN_CEC_STEP[0]=400.0\n"
    "$AN_CEC_MIN[0]=0.0\n"
    "$AN_CEC_MAX[0]=400.0\n"
    "$MA_SOMETHING[AX1]=3 ; another variable: not a table, skipped\n"
    "M17\n";

std::string Table(const std::string& dir, const std::string& text) { return WriteText(TempDir(dir) + "/t.mpf", text); }

TEST(CompensationFile, ReadsTablesInSi) {
  const MachineFile m = DefaultMachine();
  const CompensationTables t = ReadCompensationFile(Table("comp_good", kGoodTable), m);
  ASSERT_EQ(t.encoder.size(), 1u);
  EXPECT_EQ(t.encoder[0].axis, 0);
  EXPECT_DOUBLE_EQ(t.encoder[0].table.step, 0.05);
  EXPECT_DOUBLE_EQ(t.encoder[0].table.values[1], 2.1e-6);
  ASSERT_EQ(t.cross_axis.size(), 1u);
  EXPECT_EQ(t.cross_axis[0].input_axis, 0);
  EXPECT_EQ(t.cross_axis[0].output_axis, 2);
  EXPECT_DOUBLE_EQ(t.cross_axis[0].table.values[1], -1.2e-6);
}

TEST(CompensationFile, TheDefaultFileReads) {
  const MachineFile m = DefaultMachine();
  const CompensationTables t = ReadCompensationFile(SourcePath("config/machine/dmu80p_comp.mpf"), m);
  EXPECT_EQ(t.encoder.size(), 4u);
  EXPECT_EQ(t.cross_axis.size(), 2u);
}

// A file of another kind given as the tables was read as "no assignments"
// and the acquisition ran uncompensated with exit 0. Each is now named as
// what it is (io::SniffFileKind), and a text without a single table
// assignment is refused: it holds nothing to compensate with.
TEST(CompensationFile, AFileOfAnotherKindOrWithoutTablesIsNamedNotIgnored) {
  const MachineFile m = DefaultMachine();
  const auto error = [&](const std::string& path, const std::string& option = "") {
    return CaptureError([&] { ReadCompensationFile(path, m, option); });
  };
  const std::string temperature = error(SourcePath("config/machine/dmu80p_temperature.csv"), "--compensation");
  EXPECT_THAT(temperature, HasSubstr("dmu80p_temperature.csv: this is a CSV table; --compensation expects the Siemens "
                                     "compensation tables"));
  EXPECT_THAT(temperature, HasSubstr("docs/formats.md §8.4"));
  EXPECT_THAT(temperature, HasSubstr("(its columns are those of the temperature log of docs/formats.md §8.4)"));
  EXPECT_THAT(error(SourcePath("docs/img/stability-map.png")), HasSubstr("stability-map.png: this is a PNG image; expected "
                                                                         "the Siemens compensation tables"));
  EXPECT_THAT(error(SourcePath("config/machine/dmu80p.yaml")), HasSubstr("this is a YAML file"));
  const std::string dir = TempDir("comp_other_kinds");
  EXPECT_THAT(error(WriteText(dir + "/hello.txt", "\nhello world\n"), "--compensation"),
              HasSubstr("hello.txt:2: this is a text file without a single $AA_ENC_COMP or $AN_CEC table assignment; "
                        "--compensation expects the Siemens compensation tables"));
  EXPECT_THAT(error(WriteText(dir + "/hello.txt", "\nhello world\n")), HasSubstr("(this line is \"hello world\")"));
  // A part program of other variables is an MPF, but holds no table.
  EXPECT_THAT(error(WriteText(dir + "/other.mpf", "%_N_OTHER_MPF\n$MA_SOMETHING[AX1]=3\nM30\n")),
              HasSubstr("other.mpf:1: this is a Siemens MPF file (a part program or table archive of the control) "
                        "without a single $AA_ENC_COMP or $AN_CEC table assignment"));
  EXPECT_THAT(error(WriteText(dir + "/empty.mpf", "")), HasSubstr("this is an empty file without a single"));
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const size_t i = s.find(from);
  EXPECT_NE(i, std::string::npos) << from;
  return s.replace(i, from.size(), to);
}

std::string ErrorOf(const std::string& name, const std::string& text) {
  const MachineFile m = DefaultMachine();
  return CaptureError([&] { ReadCompensationFile(Table(name, text), m); });
}

TEST(CompensationFile, MaxNotMinPlusPointsTimesStepIsRejectedWithItsLine) {
  const std::string e = ErrorOf("comp_bad_max", Replace(kGoodTable, "_MAX[0,AX1]=100.0", "_MAX[0,AX1]=150.0"));
  EXPECT_THAT(e, HasSubstr("t.mpf:8: "));
  EXPECT_THAT(e, HasSubstr("_MAX 150 must equal _MIN + (points - 1) * _STEP = 0 + 2 * 50 = 100"));
}

TEST(CompensationFile, ModuloTableIsRejectedWithItsLine) {
  EXPECT_THAT(ErrorOf("comp_modulo", Replace(kGoodTable, "IS_MODULO[0,AX1]=0", "IS_MODULO[0,AX1]=1")),
              HasSubstr("t.mpf:9: $AA_ENC_COMP_IS_MODULO: modulo tables are not supported"));
}

TEST(CompensationFile, UnknownAxisIsRejectedWithItsLine) {
  EXPECT_THAT(ErrorOf("comp_axis", Replace(kGoodTable, "$AA_ENC_COMP[0,1,AX1]", "$AA_ENC_COMP[0,1,AX9]")),
              HasSubstr("t.mpf:4: $AA_ENC_COMP: unknown axis 'AX9'"));
  EXPECT_THAT(ErrorOf("comp_axis2", Replace(kGoodTable, "OUTPUT_AXIS[0]=AX3", "OUTPUT_AXIS[0]=Q1")),
              HasSubstr("t.mpf:13: $AN_CEC_OUTPUT_AXIS: unknown axis 'Q1'"));
}

TEST(CompensationFile, OutOfScopeSettingsAreRejectedNotIgnored) {
  EXPECT_THAT(ErrorOf("comp_sys1", Replace(kGoodTable, "$AA_ENC_COMP[0,2,AX1]", "$AA_ENC_COMP[1,2,AX1]")),
              HasSubstr("t.mpf:5: $AA_ENC_COMP: only measuring system 0"));
  EXPECT_THAT(ErrorOf("comp_dir", Replace(kGoodTable, "M17", "$AN_CEC_DIRECTION[0]=1\nM17")),
              HasSubstr("t.mpf:18: $AN_CEC_DIRECTION: only 0"));
  EXPECT_THAT(ErrorOf("comp_mult", Replace(kGoodTable, "M17", "$AN_CEC_MULT_BY_TABLE[0]=2\nM17")),
              HasSubstr("t.mpf:18: $AN_CEC_MULT_BY_TABLE"));
}

TEST(CompensationFile, GapsDuplicatesAndBadNumbersAreRejected) {
  EXPECT_THAT(ErrorOf("comp_gap", Replace(kGoodTable, "$AA_ENC_COMP[0,1,AX1]=0.0021\n", "")),
              HasSubstr("t.mpf:4: $AA_ENC_COMP table of axis X: point 1 is missing before point 2"));
  EXPECT_THAT(ErrorOf("comp_dup", Replace(kGoodTable, "M17", "$AN_CEC[0,1]=0.5\nM17")),
              HasSubstr("t.mpf:18: $AN_CEC is assigned twice for the same index (first on line 11)"));
  EXPECT_THAT(ErrorOf("comp_num", Replace(kGoodTable, "=0.0021", "=0,0021")),
              HasSubstr("t.mpf:4: $AA_ENC_COMP: expected"));
  EXPECT_THAT(ErrorOf("comp_step", Replace(kGoodTable, "$AN_CEC_STEP[0]=400.0\n", "")),
              HasSubstr("t.mpf:10: $AN_CEC table 0: _STEP is missing"));
}

std::string CountsError(const std::string& name, const std::string& text) {
  const MachineFile m = DefaultMachine();
  const std::string p = WriteText(TempDir(name) + "/c.csv", text);
  return CaptureError([&] { ReadCountsFile(p, m); });
}

TEST(CountsFile, ReadsByColumnNameInMachineOrder) {
  const MachineFile m = DefaultMachine();
  const std::string p = WriteText(TempDir("counts_good") + "/c.csv",
                                  "# sample_rate_hz: 8000\nC_count,t_s,extra,X_count,Y_count,Z_count,B_count\n"
                                  "0,0.0,7,0,0,0,0\n12,0.000125,8,3,-1,0,0\n");
  const machine::CountsRecord r = ReadCountsFile(p, m);
  ASSERT_EQ(r.rows(), 2);
  EXPECT_EQ(r.counts[5 + 0], 3);
  EXPECT_EQ(r.counts[5 + 1], -1);
  EXPECT_EQ(r.counts[5 + 4], 12);
  EXPECT_DOUBLE_EQ(r.t_s[1], 0.000125);
}

TEST(CountsFile, RejectsBadInputWithFileAndLine) {
  const std::string h = "t_s,X_count,Y_count,Z_count,B_count,C_count\n";
  EXPECT_THAT(CountsError("counts_first", h + "0,0,0,1,0,0\n"),
              HasSubstr("c.csv:2: column Z_count: the first row is the reference position and must hold 0"));
  EXPECT_THAT(CountsError("counts_time", h + "0,0,0,0,0,0\n0.1,1,0,0,0,0\n0.1,2,0,0,0,0\n"),
              HasSubstr("c.csv:4: column t_s: time must increase"));
  EXPECT_THAT(CountsError("counts_frac", h + "0,0,0,0,0,0\n0.1,1.5,0,0,0,0\n"),
              HasSubstr("c.csv:3: column X_count: expected a whole number of counts, got \"1.5\""));
  EXPECT_THAT(CountsError("counts_missing", "t_s,X_count,Y_count,Z_count,B_count\n0,0,0,0,0\n"),
              HasSubstr("c.csv:1: missing required column 'C_count'"));
  EXPECT_THAT(CountsError("counts_nan", h + "nan,0,0,0,0,0\n"), HasSubstr("c.csv:2: column t_s: expected a number"));
}

// A time before the reference row's clock is refused; the median step
// decides the ms finding, so one pause in an 8 kHz record does not flag it
// and ms typed for s (a step of 0.125 "s") does. References: the steps as
// written, against kMaxPlausibleCountsStepS = 0.1 s.
TEST(CountsFile, NegativeTimeIsRefusedAndAMillisecondStepIsFlagged) {
  const std::string h = "t_s,X_count,Y_count,Z_count,B_count,C_count\n";
  EXPECT_THAT(CountsError("counts_negative", h + "-0.5,0,0,0,0,0\n0,1,0,0,0,0\n"),
              HasSubstr("c.csv:2: column t_s: expected a time >= 0 s on the clock the first row"));
  const MachineFile m = DefaultMachine();
  const std::string dir = TempDir("counts_step");
  std::vector<std::string> w;
  // 8 kHz with one pause of 5 s: the median step is 0.000125 s.
  ReadCountsFile(WriteText(dir + "/pause.csv", h + "0,0,0,0,0,0\n0.000125,1,0,0,0,0\n0.00025,2,0,0,0,0\n"
                                                   "5.00025,3,0,0,0,0\n5.000375,4,0,0,0,0\n"),
                 m, &w);
  EXPECT_TRUE(w.empty()) << w.front();
  // 10 Hz, the slowest plausible rate: not flagged.
  ReadCountsFile(WriteText(dir + "/ten.csv", h + "0,0,0,0,0,0\n0.1,1,0,0,0,0\n0.2,2,0,0,0,0\n"), m, &w);
  EXPECT_TRUE(w.empty()) << w.front();
  // The same 8 kHz in ms: the median step of 0.125 is flagged at the row
  // where that step ends (line 3).
  ReadCountsFile(WriteText(dir + "/ms.csv", h + "0,0,0,0,0,0\n0.125,1,0,0,0,0\n0.25,2,0,0,0,0\n5000.25,3,0,0,0,0\n"), m,
                 &w);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_THAT(w[0], HasSubstr("implausible (unit mistake?): " + dir + "/ms.csv:3: column t_s: the rows are 0.125 s apart "
                              "(the median step; 8 Hz), more than the 0.1 s (10 Hz)"));
  EXPECT_THAT(w[0], HasSubstr("a time in ms typed in the s column?"));
}

TEST(CountsFile, WriterOutputReadsBack) {
  const MachineFile m = DefaultMachine();
  std::ostringstream out;
  CountsWriter w(out, m.machine.axes, {{"sample_rate_hz", "8000"}});
  const std::int64_t c0[5] = {0, 0, 0, 0, 0}, c1[5] = {-3, 4, 123456789012, -1, 7};
  w.Row(0.0, c0);
  w.Row(0.000125, c1);
  const std::string p = WriteText(TempDir("counts_rt") + "/c.csv", out.str());
  const auto r = ReadCountsFile(p, m);
  EXPECT_EQ(r.counts[5 + 2], 123456789012);
  EXPECT_EQ(r.t_s[1], 0.000125);
}

TEST(TemperatureLog, ReadsPerAxisAndRejectsBadRows) {
  const MachineFile m = DefaultMachine();
  const auto t = ReadTemperatureLog(SourcePath("config/machine/dmu80p_temperature.csv"), m);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0].axis, 0);
  EXPECT_EQ(t[0].rows.size(), 2u);
  EXPECT_DOUBLE_EQ(t[0].rows[1].k0, 1.8e-6);
  const std::string dir = TempDir("temp_bad");
  const std::string h = "t_s,axis,K0_mm,tan_beta,P0_mm\n";
  EXPECT_THAT(CaptureError([&] { ReadTemperatureLog(WriteText(dir + "/a.csv", h + "0,Q,0,0,0\n"), m); }),
              HasSubstr("a.csv:2: column axis: unknown axis 'Q'"));
  EXPECT_THAT(CaptureError([&] { ReadTemperatureLog(WriteText(dir + "/b.csv", h + "5,X,0,0,0\n5,X,0,0,0\n"), m); }),
              HasSubstr("b.csv:3: column t_s: time must increase for axis X"));
  EXPECT_THAT(CaptureError([&] { ReadTemperatureLog(WriteText(dir + "/c.csv", h + "5,C,0,0,0\n"), m); }),
              HasSubstr("c.csv:2: column axis: axis C is rotary"));
}

// The compensation tables given as the log failed on a "decimal comma";
// now the MPF is named as what it is, as are other kinds.
TEST(TemperatureLog, ACompensationFileOrAnotherKindIsNamed) {
  const MachineFile m = DefaultMachine();
  const auto error = [&](const std::string& path) { return CaptureError([&] { ReadTemperatureLog(path, m); }); };
  EXPECT_THAT(error(SourcePath("config/machine/dmu80p_comp.mpf")),
              HasSubstr("dmu80p_comp.mpf: this is a Siemens MPF file (a part program or table archive of the control); "
                        "expected the temperature log CSV t_s,axis,K0_mm,tan_beta,P0_mm of docs/formats.md §8.4"));
  const std::string dir = TempDir("temp_other_kinds");
  // An MPF without the %_N_ header line, comments first.
  EXPECT_THAT(error(WriteText(dir + "/t.mpf", "; tables, exported\nN10 $AA_ENC_COMP[0,0,AX1]=0.0\n")),
              HasSubstr("this is a Siemens MPF file"));
  EXPECT_THAT(error(SourcePath("docs/img/stability-map.png")), HasSubstr("this is a PNG image; expected the temperature log"));
  EXPECT_THAT(error(SourcePath("config/machine/dmu80p.yaml")), HasSubstr("this is a YAML file; expected the temperature log"));
}

// The shipped log gives no finding; a row a day after the counts' clock
// started (86 400 s) is a time in ms, named at its line.
TEST(TemperatureLog, TimeBeyondADayIsFlaggedAsMilliseconds) {
  const MachineFile m = DefaultMachine();
  std::vector<std::string> w;
  ReadTemperatureLog(SourcePath("config/machine/dmu80p_temperature.csv"), m, &w);
  EXPECT_TRUE(w.empty()) << w.front();
  const std::string h = "t_s,axis,K0_mm,tan_beta,P0_mm\n";
  ReadTemperatureLog(WriteText(TempDir("temp_ms") + "/ms.csv", h + "0,X,0.001,1e-05,0\n86400,X,0.002,1e-05,0\n"
                                                                  "90000,X,0.002,1e-05,0\n"),
                     m, &w);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_THAT(w[0], HasSubstr("ms.csv:4: column t_s: 90000 s is after the 86400 s (a day) of counts records"));
  EXPECT_THAT(w[0], HasSubstr("a time in ms typed in the s column?"));
}

TEST(IsoRuns, ReadsAndWrapsRotaryDeviations) {
  const std::string dir = TempDir("iso_runs");
  const auto r = ReadIsoRuns(WriteText(dir + "/c.csv",
                                       "axis,target_deg,run,direction,measured_deg\nC,0,1,+,359.999\nC,0,1,-,0.002\n"));
  EXPECT_TRUE(r.rotary);
  EXPECT_NEAR(r.approaches.at("C")[0].deviation, -0.001, 1e-12);
  EXPECT_THAT(CaptureError([&] {
                ReadIsoRuns(WriteText(dir + "/d.csv", "axis,target_mm,run,direction,measured_mm\nX,0,1,up,0.1\n"));
              }),
              HasSubstr("d.csv:2: column direction: expected + or -, got \"up\""));
  EXPECT_THAT(CaptureError([&] {
                ReadIsoRuns(WriteText(dir + "/e.csv", "axis,target_mm,run,direction,measured_deg\nX,0,1,+,0.1\n"));
              }),
              HasSubstr("not both"));
}

}  // namespace
}  // namespace robomach::io
