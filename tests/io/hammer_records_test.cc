// Reader of raw hammer records (docs/frf-estimate.md): layouts, units by
// column suffix, and bad input located by file:line:column.
#include "robomach/io/hammer_records.h"

#include <cmath>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "robomach/io/prediction_files.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using calibration::ResponseQuantity;
using ::testing::HasSubstr;
using robomach::testing::CaptureError;
using robomach::testing::TempDir;
using robomach::testing::WriteText;

// n rows of one hit at 1 kHz starting at t0, with a hit column if `hit` is
// not empty.
std::string Rows(const std::string& hit, int n, double t0 = 0.0) {
  std::ostringstream s;
  for (int i = 0; i < n; ++i) {
    if (!hit.empty()) s << hit << ',';
    s << t0 + i * 0.001 << ',' << (i == 2 ? 100.0 : 0.0) << ',' << 1e-6 * i << ',' << 0.5 * i << '\n';
  }
  return s.str();
}

TEST(HammerRecords, HitColumnSplitsHitsAndSuffixesGiveQuantities) {
  const std::string dir = TempDir("hammer_records_hits");
  const std::string path = WriteText(dir + "/run.csv", "# two hits\nhit,time_s,force_N,tip_x_m,acc_y_m_per_s2\n" +
                                                           Rows("1", 20) + Rows("2", 20, 5.0));
  const HammerRecords r = ReadHammerRecords({path});
  ASSERT_EQ(r.channels.size(), 2u);
  EXPECT_EQ(r.channels[0].name, "tip_x");
  EXPECT_EQ(r.channels[0].quantity, ResponseQuantity::kDisplacement);
  EXPECT_EQ(r.channels[1].name, "acc_y");
  EXPECT_EQ(r.channels[1].quantity, ResponseQuantity::kAcceleration);
  ASSERT_EQ(r.hits.size(), 2u);
  EXPECT_EQ(r.hits[0].id, "1");
  EXPECT_EQ(r.hits[1].id, "2");
  EXPECT_EQ(r.hits[1].source, path + ":23");
  EXPECT_DOUBLE_EQ(r.hits[1].start_time_s, 5.0);
  // 1 ms steps written with 6 significant digits: 1/dt is 1 kHz to that
  // precision, and snapped to it exactly.
  EXPECT_EQ(r.hits[0].sample_rate_hz, 1000.0);
  EXPECT_EQ(r.hits[0].force_N(2), 100.0);
  EXPECT_DOUBLE_EQ(r.hits[0].response(3, 1), 1.5);
}

// Ranges given by channel name come back in channel order, 0 where none is
// given; an unknown name or a negative range is refused with the entry.
TEST(HammerRecords, ResponseRangesByChannelName) {
  const std::string dir = TempDir("hammer_records_ranges");
  const std::string path =
      WriteText(dir + "/run.csv", "hit,time_s,force_N,tip_x_m,acc_y_m_per_s2\n" + Rows("1", 20));
  const HammerRecords r = ReadHammerRecords({path});
  EXPECT_TRUE(ResponseRanges(r, {}).empty());
  EXPECT_EQ(ResponseRanges(r, {{"acc_y", 490.0}}), (std::vector<double>{0.0, 490.0}));
  EXPECT_EQ(ResponseRanges(r, {{"acc_y", 490.0}, {"tip_x", 0.002}}), (std::vector<double>{0.002, 490.0}));
  EXPECT_THAT(CaptureError([&] { ResponseRanges(r, {{"acc", 50.0}}); }),
              HasSubstr("acc=50: no response channel 'acc'"));
  EXPECT_THAT(CaptureError([&] { ResponseRanges(r, {{"tip_x", -1.0}}); }),
              HasSubstr("tip_x=-1: expected a finite range >= 0"));
}

// Issue #36, one axis parser: a channel name's direction suffix and the
// direction pairs go through ParseAxis, so a capital is taken as ParseAxis
// takes it ("tip_X", "XY"); anything else is refused with the messages of
// before.
TEST(HammerRecords, DirectionSuffixAndPairsTakeCapitalsAsParseAxis) {
  const std::string dir = TempDir("hammer_records_capitals");
  const HammerRecords r = ReadHammerRecords(
      {WriteText(dir + "/run.csv", "hit,time_s,force_N,tip_X_m,acc_y_m_per_s2\n" + Rows("1", 20))});
  const auto keys = ChannelKeys(r, "P1", Axis::kZ);
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_EQ(keys[0].response, Axis::kX);
  EXPECT_EQ(keys[1].response, Axis::kY);
  const HammerRecords w = ReadHammerRecords(
      {WriteText(dir + "/w.csv", "hit,time_s,force_N,tip_w_m,acc_y_m_per_s2\n" + Rows("1", 20))});
  EXPECT_THAT(CaptureError([&] { ChannelKeys(w, "P1", Axis::kZ); }),
              HasSubstr("tip_w: response channel 'tip_w' has no direction in its name"));
  EXPECT_EQ(ParseDirectionPairs("XY,yz"), (DirectionPairs{{0, 1}, {1, 2}}));
  EXPECT_THAT(CaptureError([] { ParseDirectionPairs("xq"); }),
              HasSubstr("direction pair 'xq': expected two of x, y, z such as xx or xy"));
  EXPECT_THAT(CaptureError([] { ParseDirectionPairs("xx,XX"); }), HasSubstr("direction pair 'XX' is given twice"));
}

// A rate that is not a whole number of hertz stays as it is: 1/(1.0005 ms)
// = 999.50 Hz, 0.5 Hz from 1000 while the times' rounding (1e-9 s over
// 19 ms) allows 1e-4 Hz.
TEST(HammerRecords, UnevenRateIsNotSnapped) {
  const std::string dir = TempDir("hammer_records_rate");
  std::ostringstream s;
  s.precision(12);
  s << "time_s,force_N,x_m\n";
  for (int i = 0; i < 20; ++i) s << i * 0.0010005 << ",0,0\n";
  const HammerRecords r = ReadHammerRecords({WriteText(dir + "/r.csv", s.str())});
  EXPECT_NEAR(r.hits[0].sample_rate_hz, 1.0 / 0.0010005, 1e-6);
}

TEST(HammerRecords, OneFilePerHitNamedByStemColumnsReordered) {
  const std::string dir = TempDir("hammer_records_files");
  const std::string a = WriteText(dir + "/hit_01.csv", "time_s,force_N,v_z_m_per_s,x_m\n" + Rows("", 16));
  // Same responses in another order: the values follow their names.
  std::string rows = Rows("", 16);
  const std::string b = WriteText(dir + "/hit_02.csv", "time_s,force_N,x_m,v_z_m_per_s\n" + rows);
  const HammerRecords r = ReadHammerRecords({a, b});
  ASSERT_EQ(r.hits.size(), 2u);
  EXPECT_EQ(r.hits[0].id, "hit_01");
  EXPECT_EQ(r.hits[1].id, "hit_02");
  EXPECT_EQ(r.channels[0].quantity, ResponseQuantity::kVelocity);
  // In hit_02 the third column (1e-6 i) is x_m, the fourth (0.5 i) v_z.
  EXPECT_DOUBLE_EQ(r.hits[1].response(4, 0), 2.0);   // v_z
  EXPECT_DOUBLE_EQ(r.hits[1].response(4, 1), 4e-6);  // x
}

TEST(HammerRecords, BadInputNamesFileLineAndColumn) {
  const std::string dir = TempDir("hammer_records_bad");
  const std::string head = "time_s,force_N,x_m,a_m_per_s2\n";
  // Line 1 header, data from line 2; row 6 (line 7) goes back in time.
  std::string rows = Rows("", 20);
  {
    std::istringstream in(rows);
    std::string line, out;
    for (int i = 0; std::getline(in, line); ++i) out += (i == 5 ? "0.0035,0,0,0" : line) + "\n";
    const std::string p = WriteText(dir + "/back.csv", head + out);
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({p}); }),
                HasSubstr("back.csv:7:1: column time_s: expected a time > 0.004 (the previous row), got 0.0035"));
  }
  {
    const std::string p = WriteText(dir + "/noforce.csv", "time_s,x_m\n" + std::string("0,1\n"));
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({p}); }),
                HasSubstr("noforce.csv:1: missing required column 'force_N'"));
  }
  {
    std::string out = head;
    for (int i = 0; i < 20; ++i) out += std::to_string(i * 0.001) + ",0," + (i == 9 ? "nan" : "0") + ",0\n";
    const std::string p = WriteText(dir + "/nan.csv", out);
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({p}); }),
                HasSubstr("nan.csv:11:3: column x_m: expected a number, got \"nan\" (nan and inf are not allowed)"));
  }
  {
    // A decimal comma in a quoted cell, and unquoted (more cells).
    const std::string p = WriteText(dir + "/comma.csv", head + "0,\"12,5\",0,0\n");
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({p}); }),
                HasSubstr("comma.csv:2:2: column force_N: expected a number, got \"12,5\" (decimal comma?)"));
    const std::string q = WriteText(dir + "/comma2.csv", head + "0,12,5,0,0\n");
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({q}); }), HasSubstr("comma2.csv:2: expected at most 4 cells"));
    const std::string s = WriteText(dir + "/semicolon.csv", "time_s;force_N;x_m\n0;12,5;0\n");
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({s}); }), HasSubstr("semicolon.csv:1: the header 'time_s;force_N;x_m' is separated by semicolons; robomach's CSV files separate cells with commas"));
    const std::string s2 = WriteText(dir + "/semicolon2.csv", "time_s;force_N;x_m\n0;12.5;0\n");
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({s2}); }), HasSubstr("semicolon2.csv:1: the header"));
  }
  {
    const std::string p = WriteText(dir + "/unit.csv", "time_s,force_N,x_mm\n" + std::string("0,0,0\n"));
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({p}); }), HasSubstr("unit.csv:1:3: unknown column 'x_mm'"));
  }
  {
    const std::string p = WriteText(dir + "/split.csv", "hit,time_s,force_N,x_m,a_m_per_s2\n" + Rows("1", 20) +
                                                             Rows("2", 20) + Rows("1", 20, 1.0));
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({p}); }),
                HasSubstr("split.csv:42:1: column hit: hit '1' appears again (its rows were lines 2-21)"));
  }
  {
    std::string out = head;
    for (int i = 0; i < 20; ++i) out += std::to_string((i < 10 ? i : i + 1) * 0.001) + ",0,0,0\n";
    const std::string p = WriteText(dir + "/gap.csv", out);
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({p}); }), HasSubstr("gap.csv:12:1: column time_s: uneven sampling"));
  }
  {
    const std::string a = WriteText(dir + "/a.csv", head + Rows("", 16));
    std::string rows3;
    for (int i = 0; i < 16; ++i) rows3 += std::to_string(i * 0.001) + ",0,0\n";
    const std::string b = WriteText(dir + "/b.csv", "time_s,force_N,x_m\n" + rows3);
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({a, b}); }), HasSubstr("b.csv: response columns x_m differ"));
  }
  {
    const std::string p = WriteText(dir + "/short.csv", head + Rows("", 5));
    EXPECT_THAT(CaptureError([&] { ReadHammerRecords({p}); }), HasSubstr("has 5 samples"));
  }
}

// The estimate's file reads back with the FRF reader: metadata lines before
// the format's own are ignored, averages and coherence survive, and the
// values round-trip exactly (WriteFrfCsv writes them so).
TEST(HammerRecords, EstimatedFrfFileReadsBack) {
  const std::string dir = TempDir("hammer_records_write");
  Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(4, 1.0, 4.0);
  Eigen::VectorXcd h(4);
  h << std::complex<double>(1e-6, -2e-7), std::complex<double>(2e-6, -1e-6), std::complex<double>(-1e-6, -3e-6),
      std::complex<double>(-3e-7, -1e-8);
  Eigen::VectorXd g(4);
  g << 0.99, 0.95, 0.5, 0.91;
  dynamics::FrfSet set;
  set.Insert({"P1", Axis::kY, Axis::kX}, dynamics::Frf::FromSamples(f, h, g));
  const std::string p = dir + "/est.csv";
  WriteEstimatedFrfCsv(p, set, FrfQuantity::kAccelerance, 6,
                       {{"estimator", "H1"}, {"exponential_window_tau_s", "0.1"}});
  const FrfReadResult r = ReadFrfCsv(p);
  EXPECT_EQ(r.averages, 6);
  EXPECT_EQ(r.file_quantity, FrfQuantity::kAccelerance);
  const dynamics::Frf& back = r.frfs.at({"P1", Axis::kY, Axis::kX});
  ASSERT_EQ(back.size(), 4);
  // Through accelerance and back: −ω² and its inverse, a few ulp.
  for (int k = 0; k < 4; ++k) EXPECT_LE(std::abs(back.receptance()(k) - h(k)), 1e-15 * std::abs(h(k)));
  EXPECT_EQ(*back.coherence(), g);
  EXPECT_THROW(WriteEstimatedFrfCsv(p, set, FrfQuantity::kReceptance, 6, {{"averages", "3"}}),
               std::invalid_argument);
}

// frf-estimate's FRFs: an accelerance channel becomes receptance by
// H = -A / omega^2 (e^{i omega t}), a displacement channel stays as it is;
// the FRFs come in key order with their channel; the header lines name the
// estimator and the rejected hits.
TEST(ToEstimatedFrfs, ConvertsEachChannelToReceptanceInKeyOrder) {
  HammerRecords rec;
  rec.channels = {{"acc_z", calibration::ResponseQuantity::kAcceleration},
                  {"disp_x", calibration::ResponseQuantity::kDisplacement}};
  calibration::FrfEstimateResult r;
  r.status = calibration::FrfEstimateStatus::kOk;
  r.freq_hz = Eigen::Vector3d(10.0, 20.0, 30.0);
  r.averages = 2;
  r.hits.resize(3);
  r.hits[2].id = "h3";
  r.hits[2].status = calibration::HitStatus::kDoubleHit;
  r.force_window_s = -1.0;
  r.channels.resize(2);
  for (auto& ch : r.channels) {
    ch.h1 = Eigen::Vector3cd(std::complex<double>(1, 2), std::complex<double>(3, -1), std::complex<double>(-2, 0.5));
    ch.h2 = 2.0 * ch.h1;
    ch.coherence = Eigen::Vector3d(0.9, 0.95, 0.99);
  }
  const std::vector<dynamics::FrfKey> keys = {{"P1", Axis::kZ, Axis::kZ}, {"P1", Axis::kX, Axis::kZ}};
  const EstimatedFrfs e = ToEstimatedFrfs(r, rec, keys, false);
  ASSERT_EQ(e.labels.size(), 2u);
  EXPECT_EQ(e.labels[0], "disp_x (Hxz)");  // key order: x before z
  EXPECT_EQ(e.channel_of, (std::vector<int>{1, 0}));
  const dynamics::Frf& acc = e.frfs.at(keys[0]);
  const dynamics::Frf& disp = e.frfs.at(keys[1]);
  for (int k = 0; k < 3; ++k) {
    const double w = 2 * M_PI * r.freq_hz(k);
    EXPECT_LT(std::abs(acc.receptance()(k) - (-r.channels[0].h1(k) / (w * w))), 1e-15 * std::abs(r.channels[0].h1(k)));
    EXPECT_EQ(disp.receptance()(k), r.channels[1].h1(k));
  }
  std::map<std::string, std::string> meta(e.metadata.begin(), e.metadata.end());
  EXPECT_EQ(meta["estimator"], "H1");
  EXPECT_EQ(meta["hits_averaged"], "2 of 3");
  EXPECT_EQ(meta["hits_rejected"], "h3 (double hit)");
  EXPECT_EQ(meta["force_window_s"], "off");
  EXPECT_EQ(ToEstimatedFrfs(r, rec, keys, true).frfs.at(keys[1]).receptance()(0), r.channels[1].h2(0));
}

}  // namespace
}  // namespace robomach::io
