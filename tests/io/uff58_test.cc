// UFF as other people's software writes it (issue #18): files this test
// writes by hand in the layouts of [SDRC 1993] (binary 58b in both byte
// orders, dataset 164 units, the datasets modal software adds, entity-name
// directions, padding, unit labels), and the real exports in
// ../shared/external/frf_uff58, read where they lie (skipped with a message
// when ../shared is absent; never copied into the project). The references
// are analytic FRFs, an independent whitespace reading of the ASCII data
// blocks, each binary file's ASCII twin, and the values SOURCES.md states.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "robomach/common/units.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/io/frf_files.h"
#include "robomach/io/uff58.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using dynamics::Frf;
using dynamics::FrfKey;
using ::testing::HasSubstr;
using ::testing::Not;
using robomach::testing::CaptureError;
using robomach::testing::SourcePath;
using robomach::testing::TempDir;
using robomach::testing::WriteText;

// ------------------------------------------------------------ unit labels --

TEST(UffUnits, ParsesTheLabelsExportsWrite) {
  struct Case {
    const char* label;
    double factor;
    int l, f, t;
  };
  const Case cases[] = {
      {"(m/s)/N", 1.0, 1, -1, -1},
      {"(1/N)*(m/s\xB2)", 1.0, 1, -1, -2},      // Latin-1 superscript two (pyuff's non_ascii_header)
      {"(1/N)*(m/s\xC2\xB2)", 1.0, 1, -1, -2},  // the same in UTF-8
      {"m/s^2/N", 1.0, 1, -1, -2},
      {"m s^-2 / N", 1.0, 1, -1, -2},
      {"m/s**2", 1.0, 1, 0, -2},
      {"m/s2", 1.0, 1, 0, -2},
      {"mm/s^2", 1e-3, 1, 0, -2},
      {"g/lbf", 9.80665 / 4.4482216152605, 1, -1, -2},
      {"in/s/lbf", 0.0254 / 4.4482216152605, 1, -1, -1},
      {"\xC2\xB5m/N", 1e-6, 1, -1, 0},
      {"Hz", 1.0, 0, 0, -1},
      {"(Sec)", 1.0, 0, 0, 1},
      {"1", 1.0, 0, 0, 0},
  };
  for (const Case& c : cases) {
    const UnitDimension d = ParseUnitLabel(c.label);
    EXPECT_TRUE(d.given) << c.label;
    EXPECT_NEAR(d.factor, c.factor, 1e-15 * c.factor) << c.label;
    EXPECT_EQ(d.length, c.l) << c.label;
    EXPECT_EQ(d.force, c.f) << c.label;
    EXPECT_EQ(d.time, c.t) << c.label;
  }
  EXPECT_FALSE(ParseUnitLabel("NONE").given);
  EXPECT_FALSE(ParseUnitLabel("  ").given);
  EXPECT_THAT(CaptureError([] { ParseUnitLabel("V/N"); }), HasSubstr("unit 'V' (in \"V/N\")"));
  EXPECT_THAT(CaptureError([] { ParseUnitLabel("V/N"); }), HasSubstr("voltage"));
  EXPECT_THAT(CaptureError([] { ParseUnitLabel("m/(s"); }), HasSubstr("expected ')'"));
  // Exponents are bounded (issue #22): a long one threw std::out_of_range
  // from std::stoi, nested powers overflowed the integer dimensions.
  EXPECT_THAT(CaptureError([] { ParseUnitLabel("m^99999999999/N"); }),
              HasSubstr("exponent 99999999999 is out of range (at most 12)"));
  EXPECT_THAT(CaptureError([] { ParseUnitLabel("((m^9)^9)/N"); }),
              HasSubstr("dimension exponent 81 is out of range"));
  EXPECT_EQ(ParseUnitLabel("(m^2)^3/N").length, 6);
}

// ------------------------------------------------------- files written here --

// A 2-DOF receptance in m/N with modes at 40 and 95 Hz (an analytic reference
// independent of the reader).
std::complex<double> Receptance2Dof(double f_hz) {
  const double w = HzToRadPerSec(f_hz);
  std::complex<double> h = 0.0;
  for (const auto& [fn, zeta, a] : {std::tuple{40.0, 0.03, 0.8}, std::tuple{95.0, 0.02, 0.5}}) {
    const double wn = HzToRadPerSec(fn);
    h += a / (wn * wn - w * w + std::complex<double>(0.0, 2.0 * zeta * wn * w));
  }
  return h * 1e-2;
}

std::string E(double v, const char* fmt = "%13.5E") {
  char b[40];
  std::snprintf(b, sizeof(b), fmt, v);
  return b;
}

std::string Pad(std::string s, size_t n = 80) {
  s.resize(std::max(s.size(), n), ' ');
  return s;
}

// Record 6 with entity names and direction codes, format 2(I5,I10),2(1X,10A1,I10,I4).
std::string Record6(int ftype, const std::string& rent, int rnode, int rdir, const std::string& eent, int enode,
                    int edir) {
  char b[128];
  std::snprintf(b, sizeof(b), "%5d%10d%5d%10d %-10s%10d%4d %-10s%10d%4d", ftype, 0, 0, 0, rent.c_str(), rnode, rdir,
                eent.c_str(), enode, edir);
  return b;
}

// Records 8-11: I10,3I5,2(1X,20A1).
std::string Axis(int spec, int lexp, int fexp, const std::string& label, const std::string& units) {
  char b[128];
  std::snprintf(b, sizeof(b), "%10d%5d%5d%5d %-20s %-20s", spec, lexp, fexp, 0, label.c_str(), units.c_str());
  return b;
}

struct Header {
  std::string id1 = "NONE";
  std::string r6;
  int ord_type = 5;
  long n = 0;
  bool even = true;
  double xmin = 0, dx = 0;
  std::string r8 = Axis(18, 0, 0, "Frequency", "Hz");
  std::string r9, r10 = Axis(13, 0, 1, "Force", "N");
};

std::string HeaderLines(const Header& h) {
  char r7[128];
  std::snprintf(r7, sizeof(r7), "%10d%10ld%10d%13.5E%13.5E%13.5E", h.ord_type, h.n, h.even ? 1 : 0, h.xmin, h.dx, 0.0);
  return Pad(h.id1) + "\n" + Pad("NONE") + "\n" + Pad("01-Jan-26 00:00:00") + "\n" + Pad("NONE") + "\n" +
         Pad("NONE") + "\n" + h.r6 + "\n" + r7 + "\n" + h.r8 + "\n" + h.r9 + "\n" + h.r10 + "\n" +
         Axis(0, 0, 0, "NONE", "NONE") + "\n";
}

// An ASCII record of complex values (E13.5 as single precision is written),
// with `padding` zeros after the announced points.
std::string AsciiRecord(const Header& h, const std::vector<double>& values, int padding = 0) {
  std::string s = "    -1\n    58\n" + HeaderLines(h);
  std::vector<double> v = values;
  v.insert(v.end(), padding, 0.0);
  for (size_t k = 0; k < v.size(); ++k) {
    s += E(v[k], h.ord_type == 6 || h.ord_type == 4 ? "%20.12E" : "%13.5E");
    if (k % 6 == 5 || k + 1 == v.size()) s += "\n";
  }
  return s + "    -1\n";
}

// The same as 58b: IEEE values of `width` bytes in the given byte order; an
// uneven abscissa as 4-byte floats (it is E13.5 in ASCII).
std::string BinaryRecord(const Header& h, const std::vector<double>& values, bool big_endian, bool crlf = false) {
  std::string data;
  const int width = h.ord_type == 4 || h.ord_type == 6 ? 8 : 4;
  const int per = (h.ord_type >= 5 ? 2 : 1) + (h.even ? 0 : 1);
  for (size_t k = 0; k < values.size(); ++k) {
    const bool abscissa = !h.even && k % per == 0;
    unsigned char b[8];
    int w = abscissa ? 4 : width;
    if (w == 4) {
      const float f = static_cast<float>(values[k]);
      std::memcpy(b, &f, 4);
    } else {
      std::memcpy(b, &values[k], 8);
    }
    if (big_endian) std::reverse(b, b + w);  // this machine is little endian (x86-64)
    data.append(reinterpret_cast<char*>(b), w);
  }
  char hb[128];
  std::snprintf(hb, sizeof(hb), "%6d%1s%6d%6d%12d%12zu%6d%6d%12d%12d", 58, "b", big_endian ? 2 : 1, 2, 11,
                data.size(), 0, 0, 0, 0);
  std::string head = "    -1\n" + std::string(hb) + "\n" + HeaderLines(h);
  if (crlf) {
    std::string t;
    for (char c : head) {
      if (c == '\n') t += '\r';
      t += c;
    }
    head = t;
  }
  return head + data + "    -1" + (crlf ? "\r\n" : "\n");
}

std::string WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// What commercial modal software exports around its FRFs: a 151 header,
// 164 units in mm and mN, nodes (15 and 2411), a mode shape (55) and trace
// lines (82), and an accelerance in mm/s^2 per mN whose records 9-10 carry
// no unit labels, only the length and force exponents. Directions come from
// the entity names (codes 0), the data block is padded with zeros.
TEST(Uff58, ReadsAnExportWithOtherDatasetsUnitsAndEntityDirections) {
  const std::string dir = TempDir("uff58_export");
  std::vector<double> v;
  const int n = 200;
  const double df = 0.5;
  for (int k = 0; k < n; ++k) {
    const double f = (k + 1) * df;
    const double w = HzToRadPerSec(f);
    // Accelerance A = -w^2 H in mm/s^2 per mN: 1 (m/s^2)/N = 1000 mm/s^2 / 1000 mN = 1.
    const std::complex<double> a = -w * w * Receptance2Dof(f) * (1e3 / 1e3);
    v.push_back(a.real());
    v.push_back(a.imag());
  }
  Header h;
  h.r6 = Record6(4, ".7.Y-", 0, 0, ".7.Y+", 0, 0);
  h.n = n;
  h.xmin = df;
  h.dx = df;
  h.r9 = Axis(12, 1, 0, "Accelerance", "NONE");
  h.r10 = Axis(13, 0, 1, "NONE", "NONE");
  std::string file =
      "    -1\n   151\nmodel\nNONE\nTest.Lab\n01-Jan-26\n    -1\n"
      "    -1\n   164\n         5mm (milli newton)            2\n"
      "  1.00000000000000000D+03  1.00000000000000000D+03  1.00000000000000000D+00\n"
      "  2.73150000000000000D+02\n    -1\n"
      "    -1\n    15\n         1         0         0         0  0.0000000E+00  0.0000000E+00  0.0000000E+00\n    -1\n"
      "    -1\n  2411\n         7         1         1        11\n"
      "   0.0000000000000000E+00   0.0000000000000000E+00   0.0000000000000000E+00\n    -1\n"
      "    -1\n    55\nmode 1\nNONE\nNONE\nNONE\nNONE\n         1         2         3         8         2         6\n"
      "         2         4         1         1\n  4.00000E+01  1.00000E+00  0.00000E+00\n"
      "         7         6\n  1.00000E+00  0.00000E+00  0.00000E+00  0.00000E+00  0.00000E+00  0.00000E+00\n    -1\n"
      "    -1\n    82\n         1         2         0\nline\n         7         7\n    -1\n" +
      AsciiRecord(h, v, 4);
  WriteText(dir + "/export.unv", file);
  const FrfReadResult r = ReadFrfFile(dir + "/export.unv");
  const FrfKey key{"", Axis::kY, Axis::kY};
  ASSERT_EQ(r.frfs.keys(), std::vector<FrfKey>{key});
  EXPECT_EQ(r.file_quantity, FrfQuantity::kAccelerance);
  const Frf& g = r.frfs.at(key);
  ASSERT_EQ(g.size(), n);
  // The response points along -y, the reference along +y: one negation.
  // E13.5 keeps 6 significant digits: 5e-6 relative per number.
  double worst = 0.0;
  for (int k = 0; k < n; ++k) {
    const std::complex<double> want = -Receptance2Dof(g.freq_hz()(k));
    worst = std::max(worst, std::abs(g.receptance()(k) - want) / std::abs(want));
  }
  EXPECT_LT(worst, 1e-5);
  EXPECT_NEAR(g.freq_hz()(n - 1), n * df, 1e-9);
  std::string notes;
  for (const auto& s : r.notes) notes += s + "\n";
  EXPECT_THAT(notes, HasSubstr("skipped datasets other than 58 and 164: 15 (1x"));
  EXPECT_THAT(notes, HasSubstr("151 (1x"));
  EXPECT_THAT(notes, HasSubstr("2411 (1x"));
  EXPECT_THAT(notes, HasSubstr("55 (1x"));
  EXPECT_THAT(notes, HasSubstr("82 (1x"));
  EXPECT_THAT(notes, HasSubstr("units of dataset 164: mm (milli newton)"));
  EXPECT_THAT(notes, HasSubstr("directions from the entity names \".7.Y-\" and \".7.Y+\""));
  EXPECT_THAT(notes, HasSubstr("4 padding zeros after the 200 points"));
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();

  // The same values with unit labels in mm/s^2 per N (no 164): 1e-3 times
  // the SI accelerance of the mN file's numbers.
  Header hl = h;
  hl.r6 = Record6(4, "NONE", 7, 2, "NONE", 7, 2);
  hl.r9 = Axis(12, 0, 0, "Accelerance", "mm/s^2");
  hl.r10 = Axis(13, 0, 0, "Force", "N");
  WriteText(dir + "/labels.unv", AsciiRecord(hl, v));
  const FrfReadResult rl = ReadFrfFile(dir + "/labels.unv");
  const Frf& gl = rl.frfs.at(key);
  for (int k = 0; k < n; k += 37) {
    EXPECT_NEAR(std::abs(gl.receptance()(k) / (-g.receptance()(k)) - 1e-3), 0.0, 1e-12);
  }
}

// A mobility whose record 9 says nothing (specific type 0) and whose label
// word is wrong ("Receptance"), as dataset58_FRF.unv is: the unit (m/s)/N
// decides, the word is named in a note.
TEST(Uff58, QuantityFromTheUnitLabelWhenRecord9SaysNothing) {
  const std::string dir = TempDir("uff58_mobility");
  std::vector<double> v;
  const int n = 100;
  for (int k = 0; k < n; ++k) {
    const double f = k * 1.0;  // from 0 Hz: that line has no receptance
    const std::complex<double> y = std::complex<double>(0.0, HzToRadPerSec(f)) * Receptance2Dof(f);
    v.push_back(y.real());
    v.push_back(y.imag());
  }
  Header h;
  h.id1 = "pose=P3 tap test";
  h.r6 = Record6(4, "NONE", 1, 1, "NONE", 1, 1);
  h.n = n;
  h.dx = 1.0;
  h.r9 = Axis(0, 0, 0, "Receptance", "(m/s)/N");
  h.r10 = Axis(0, 0, 0, "NONE", "NONE");
  WriteText(dir + "/y.uff", AsciiRecord(h, v));
  const FrfReadResult r = ReadFrfFile(dir + "/y.uff");
  EXPECT_EQ(r.file_quantity, FrfQuantity::kMobility);
  const Frf& g = r.frfs.at({"P3", Axis::kX, Axis::kX});
  ASSERT_EQ(g.size(), n - 1);
  for (int k = 0; k < g.size(); ++k) {
    const std::complex<double> want = Receptance2Dof(g.freq_hz()(k));
    ASSERT_LT(std::abs(g.receptance()(k) - want) / std::abs(want), 1e-5) << g.freq_hz()(k);
  }
  std::string notes;
  for (const auto& s : r.notes) notes += s + "\n";
  EXPECT_THAT(notes, HasSubstr("its unit (m/s)/N makes it a mobility, although its axis label says \"Receptance\"; read as mobility"));
  EXPECT_THAT(notes, HasSubstr("0 Hz line of a mobility"));
}

// 58b in every ordinate type, both byte orders and CR-LF header lines, against
// the same record in ASCII (E20.12 for double, E13.5 for single).
TEST(Uff58, BinaryRecordsEqualTheirAsciiTwins) {
  const std::string dir = TempDir("uff58_binary");
  for (int type : {2, 4, 5, 6}) {
    for (bool even : {true, false}) {
      for (bool big : {false, true}) {
        const int n = 64;
        std::vector<double> v;
        for (int k = 0; k < n; ++k) {
          const double f = 10.0 + 2.0 * k + (even ? 0.0 : 0.25 * (k % 3));  // uneven: jittered
          if (!even) v.push_back(f);
          const std::complex<double> h = Receptance2Dof(f);
          v.push_back(h.real());
          if (type >= 5) v.push_back(h.imag());
        }
        Header h;
        h.r6 = Record6(type >= 5 ? 4 : 6, "NONE", 1, 3, "NONE", 1, 3);
        h.ord_type = type;
        h.n = n;
        h.even = even;
        h.xmin = even ? 10.0 : 0.0;
        h.dx = even ? 2.0 : 0.0;
        h.r9 = Axis(type >= 5 ? 8 : 0, 1, 0, "Displacement", "m");
        h.r10 = Axis(13, 0, 1, "Force", "N");
        const std::string tag = std::to_string(type) + (even ? "e" : "u") + (big ? "B" : "L");
        // A real record is a coherence (function type 6); give it an FRF to attach to.
        std::string prefix;
        if (type < 5) {
          Header hf = h;
          hf.r6 = Record6(4, "NONE", 1, 3, "NONE", 1, 3);
          hf.ord_type = 5;
          std::vector<double> fv;
          for (int k = 0; k < n; ++k) {
            if (!even) fv.push_back(v[2 * k]);
            fv.push_back(1e-6);
            fv.push_back(0.0);
          }
          prefix = AsciiRecord(hf, fv);
          // Coherence must be in [0, 1].
          for (int k = 0; k < n; ++k) {
            double& c = v[even ? k : 2 * k + 1];
            c = 0.5 + 0.4 * std::sin(0.3 * k);
          }
        }
        WriteBytes(dir + "/a" + tag + ".uff", prefix + AsciiRecord(h, v));
        WriteBytes(dir + "/b" + tag + ".uff", prefix + BinaryRecord(h, v, big, big));
        const UffFile a = ReadUffFile(dir + "/a" + tag + ".uff");
        const UffFile b = ReadUffFile(dir + "/b" + tag + ".uff");
        ASSERT_EQ(a.records.size(), b.records.size()) << tag;
        const Uff58Record& ra = a.records.back();
        const Uff58Record& rb = b.records.back();
        EXPECT_TRUE(rb.binary);
        ASSERT_EQ(rb.y.size(), n) << tag;
        // Single precision: float32 keeps 2^-24 = 6e-8 relative, E13.5 5e-6;
        // double: E20.12 keeps 5e-13. The abscissa is 4-byte in both: 6e-8.
        const double tol = type == 2 || type == 5 ? 6e-6 : 1e-12;
        for (int k = 0; k < n; ++k) {
          ASSERT_LE(std::abs(ra.y(k) - rb.y(k)), tol * std::abs(ra.y(k))) << tag << " point " << k;
          ASSERT_LE(std::abs(ra.x(k) - rb.x(k)), 1e-6 * ra.x(k)) << tag << " point " << k;
        }
        // And at the FRF level.
        const FrfReadResult fa = ReadFrfFile(dir + "/a" + tag + ".uff");
        const FrfReadResult fb = ReadFrfFile(dir + "/b" + tag + ".uff");
        ASSERT_EQ(fa.frfs.keys(), fb.frfs.keys()) << tag;
        if (type < 5) {
          ASSERT_TRUE(fb.frfs.at({"", Axis::kZ, Axis::kZ}).coherence().has_value()) << tag;
        }
      }
    }
  }
}

// A unit that makes the record an accelerance is named with its article
// ("an accelerance", not "a accelerance"), and so is its 0 Hz line.
TEST(Uff58, NamesAnAccelerancePerItsUnitWithTheRightArticle) {
  const std::string dir = TempDir("uff58_article");
  Header h;
  h.r6 = Record6(4, "NONE", 1, 3, "NONE", 1, 3);
  h.n = 3;
  h.dx = 1.0;
  h.r9 = Axis(0, 0, 0, "Accelerance", "m/s^2");
  WriteText(dir + "/a.uff", AsciiRecord(h, {1e-3, 0, 2e-3, 0, 3e-3, 0}));
  const FrfReadResult r = ReadFrfFile(dir + "/a.uff");
  std::string notes;
  for (const auto& s : r.notes) notes += s + "\n";
  for (const auto& s : r.warnings) notes += s + "\n";
  EXPECT_THAT(notes, HasSubstr("makes it an accelerance"));
  EXPECT_THAT(notes, HasSubstr("the 0 Hz line of an accelerance FRF"));
  EXPECT_THAT(notes, Not(HasSubstr("a accelerance")));
}

TEST(Uff58, SaysWhatARecordIsWhenItIsNotAnFrf) {
  const std::string dir = TempDir("uff58_not_frf");
  Header h;
  h.r6 = Record6(1, "NONE", 1, 3, "NONE", 1, 3);
  h.ord_type = 2;
  h.n = 8;
  h.dx = 1e-3;
  h.r8 = Axis(17, 0, 0, "Time", "s");
  h.r9 = Axis(0, 0, 1, "Force", "N");
  h.r10 = Axis(0, 0, 0, "NONE", "NONE");
  const std::string time = AsciiRecord(h, {0, 1, 2, 3, 2, 1, 0, 0});
  WriteText(dir + "/t.uff", time);
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(dir + "/t.uff"); }),
              HasSubstr("t.uff: no frequency response function (dataset 58, function type 4) in the file: it holds a "
                        "time response (function type 1) at line 2"));
  // Time records are a hammer test's raw data: the message names the tool
  // that turns them into FRFs (frf-estimate reads UFF58 function type 1).
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(dir + "/t.uff"); }),
              HasSubstr("; to turn impact-hammer time records (per hit the force record, then its response records) "
                        "into an FRF file, run frf-estimate on them (docs/frf-estimate.md)"));
  // Beside an FRF the time record is skipped with a note.
  Header hf;
  hf.r6 = Record6(4, "NONE", 1, 3, "NONE", 1, 3);
  hf.n = 2;
  hf.dx = 1.0;
  hf.xmin = 1.0;
  hf.r9 = Axis(8, 1, 0, "Displacement", "m");
  WriteText(dir + "/tf.uff", time + AsciiRecord(hf, {1e-6, 0, 2e-6, 0}));
  const FrfReadResult r = ReadFrfFile(dir + "/tf.uff");
  EXPECT_EQ(r.frfs.size(), 1);
  ASSERT_FALSE(r.notes.empty());
  EXPECT_THAT(r.notes.back(), HasSubstr("skipped 1 record that are not FRFs: time response (function type 1)"));
}

TEST(Uff58, BadInputIsNamed) {
  const std::string dir = TempDir("uff58_bad");
  Header h;
  h.r6 = Record6(4, "NONE", 1, 3, "NONE", 1, 3);
  h.n = 3;
  h.dx = 1.0;
  h.xmin = 1.0;
  h.r9 = Axis(0, 0, 0, "NONE", "V");
  h.r10 = Axis(0, 0, 0, "NONE", "N");
  const std::vector<double> v = {1, 0, 2, 0, 3, 0};
  WriteText(dir + "/volt.uff", AsciiRecord(h, v));
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(dir + "/volt.uff"); }),
              HasSubstr("volt.uff:11:48: record 9 units label: unit 'V' (in \"V\") is not a unit robomach can convert"));
  h.r9 = Axis(12, 0, 0, "NONE", "m/s");
  WriteText(dir + "/conflict.uff", AsciiRecord(h, v));
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(dir + "/conflict.uff"); }),
              HasSubstr("conflict.uff:11:1: record 9 says accelerance (specific data type 12) but the unit labels say "
                        "mobility"));
  h.r9 = Axis(8, 0, 0, "NONE", "m");
  h.r6 = Record6(4, "NONE", 1, 5, "NONE", 1, 3);
  WriteText(dir + "/rot.uff", AsciiRecord(h, v));
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(dir + "/rot.uff"); }),
              HasSubstr("rot.uff:8:52: record 6: response direction 5 is rotational"));
  h.r6 = Record6(4, "NONE", 1, 3, "NONE", 1, 3);
  // Fewer numbers than announced.
  WriteText(dir + "/short.uff", AsciiRecord(h, {1, 0, 2, 0}));
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(dir + "/short.uff"); }),
              HasSubstr("short.uff:9: record 7 announces 3 points (6 numbers), but the data block holds only 4"));
  // A binary block shorter than declared, and one whose count is off by 8.
  std::string bin = BinaryRecord(h, v, false);
  WriteBytes(dir + "/trunc.uff", bin.substr(0, bin.size() - 20));
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(dir + "/trunc.uff"); }), HasSubstr("the file ends before them"));
  const std::string declared = "          24";  // 3 complex single values
  const size_t at = bin.find(declared);
  ASSERT_NE(at, std::string::npos);
  std::string off = bin;
  off.replace(at, declared.size(), "          16");
  WriteBytes(dir + "/off.uff", off);
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(dir + "/off.uff"); }),
              HasSubstr("need 24"));
  // Two records of other nodes with the same directions.
  Header h2 = h;
  h2.r9 = Axis(8, 0, 0, "NONE", "m");
  h2.r6 = Record6(4, "NONE", 2, 3, "NONE", 1, 3);
  Header h1 = h2;
  h1.r6 = Record6(4, "NONE", 1, 3, "NONE", 1, 3);
  WriteText(dir + "/two.uff", AsciiRecord(h1, v) + AsciiRecord(h2, v));
  // A roving test: the tool-tip read refuses it and says what to do; with
  // the points kept (frf-modes) both FRFs are there, numbered.
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(dir + "/two.uff"); }),
              HasSubstr("the FRFs hold 2 measurement-point pairs (response->excitation 1->1, 2->1): a roving test"));
  {
    const FrfReadResult kept = ReadFrfFile(dir + "/two.uff", "", true);
    ASSERT_EQ(kept.frfs.size(), 2);
    const FrfKey k1{"", Axis::kZ, Axis::kZ, 1, 1}, k2{"", Axis::kZ, Axis::kZ, 2, 1};
    EXPECT_EQ(kept.frfs.keys(), (std::vector<FrfKey>{k1, k2}));
    EXPECT_TRUE(k1.IsDrivingPoint());
    EXPECT_FALSE(k2.IsDrivingPoint());
    EXPECT_EQ(k2.ToString(), "response z at point 2, excitation z at point 1");
    EXPECT_EQ(k2.Label(), "H2z,1z");
  }
  // The same record twice (same nodes and directions) is an error at the
  // second.
  WriteText(dir + "/twice.uff", AsciiRecord(h1, v) + AsciiRecord(h1, v));
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(dir + "/twice.uff", "", true); }),
              HasSubstr("are both response z at point 1, excitation z at point 1: the same FRF twice"));
  // Not UFF at all, by extension.
  WriteText(dir + "/csv.uff", "pose_id,response\n");
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(dir + "/csv.uff"); }),
              HasSubstr("csv.uff:1: expected the UFF dataset delimiter \"    -1\", got \"pose_id,response\" (is this a "
                        "Universal File Format file?)"));
}

// -------------------------------------------- the real files in ../shared --

std::string External(const std::string& relative) {
  return SourcePath("../shared/external/frf_uff58/" + relative);
}

#define SKIP_WITHOUT_SHARED()                                                                        \
  if (!std::filesystem::exists(External("SOURCES.md"))) {                                           \
    GTEST_SKIP() << "../shared/external/frf_uff58 is absent (a clone without ../shared): real UFF " \
                    "exports not tested";                                                            \
  }

// An independent reading of an ASCII record's data block: every whitespace-
// separated token of the lines after its 13th line (delimiter, number and
// records 1-11), up to the closing -1.
std::vector<double> WhitespaceReading(const std::string& path, int first_line_of_record) {
  std::ifstream in(path);
  std::string s;
  std::vector<double> v;
  int line = 0;
  while (std::getline(in, s)) {
    ++line;
    if (line < first_line_of_record + 13) continue;
    std::istringstream t(s);
    std::string tok;
    if (s.find("-1") != std::string::npos && s.find_first_not_of(" -1\r") == std::string::npos) break;
    while (t >> tok) v.push_back(std::stod(tok));
  }
  return v;
}

// dataset58_FRF.unv: a measured mobility, response ".1.Z-", reference
// ".56.Z", 1600 lines 0-799.5 Hz, 4 padding zeros, "Receptance" as label.
TEST(Uff58External, MeasuredMobilityFrf) {
  SKIP_WITHOUT_SHARED();
  const std::string path = External("ufffiles_jl/dataset58_FRF.unv");
  const FrfReadResult r = ReadFrfFile(path);
  const FrfKey key{"", Axis::kZ, Axis::kZ};
  ASSERT_EQ(r.frfs.keys(), std::vector<FrfKey>{key});
  EXPECT_EQ(r.file_quantity, FrfQuantity::kMobility);
  const Frf& g = r.frfs.at(key);
  ASSERT_EQ(g.size(), 1599);  // the 0 Hz line has no receptance
  EXPECT_DOUBLE_EQ(g.freq_hz()(0), 0.5);
  EXPECT_DOUBLE_EQ(g.freq_hz()(1598), 799.5);
  // Values: Y = i w H, negated once (response along -z).
  const std::vector<double> raw = WhitespaceReading(path, 1);
  ASSERT_EQ(raw.size(), 3204u);  // 1600 complex values and 4 padding zeros (SOURCES.md)
  double worst = 0.0;
  for (int k = 0; k < g.size(); ++k) {
    const std::complex<double> y(raw[2 * (k + 1)], raw[2 * (k + 1) + 1]);
    const std::complex<double> back = -std::complex<double>(0.0, HzToRadPerSec(g.freq_hz()(k))) * g.receptance()(k);
    worst = std::max(worst, std::abs(back - y) / std::max(std::abs(y), 1e-30));
  }
  EXPECT_LT(worst, 1e-12);  // the same decimal numbers, and two conversions
  // Modes SOURCES.md names: |Y| has a local maximum within one line of each.
  for (double fm : {81.5, 175.0, 376.5, 464.0, 544.0}) {
    const int k = static_cast<int>(std::lround(fm / 0.5)) - 1;
    double best = 0.0;
    int arg = -1;
    for (int j = k - 3; j <= k + 3; ++j) {
      const double a = std::abs(g.receptance()(j)) * g.freq_hz()(j);
      if (a > best) {
        best = a;
        arg = j;
      }
    }
    EXPECT_NEAR(g.freq_hz()(arg), fm, 0.5 + 1e-9) << fm;
  }
  std::string notes;
  for (const auto& s : r.notes) notes += s + "\n";
  EXPECT_THAT(notes, HasSubstr("directions from the entity names \".1.Z-\" and \".56.Z\""));
  EXPECT_THAT(notes, HasSubstr("4 padding zeros after the 1600 points"));
  EXPECT_THAT(notes, HasSubstr("record 9 gives no physical ordinate type (0); its unit (m/s)/N makes it a mobility"));
  // Points 1 and 56 (from the entity names): not a tool-tip (driving-point)
  // FRF; frf-modes keeps the numbers.
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_THAT(r.warnings[0], HasSubstr("a transfer FRF between two points (response point 1, excitation point 56)"));
  const FrfKey numbered{"", Axis::kZ, Axis::kZ, 1, 56};
  EXPECT_EQ(ReadFrfFile(path, "", true).frfs.keys(), std::vector<FrfKey>{numbered});
}

TEST(Uff58External, CoherenceTimeAndSpectrumAreNamedNotMisread) {
  SKIP_WITHOUT_SHARED();
  // Coherence alone: the FRF reader says what the file holds; the record
  // reader gives its values: SOURCES.md's mean 0.988 is over the 1602
  // values pyuff returns, the two padding zeros included.
  const std::string coh = External("ufffiles_jl/dataset58_coh.unv");
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(coh); }), HasSubstr("it holds a coherence (function type 6) without its FRF at line 2"));
  const UffFile c = ReadUffFile(coh);
  ASSERT_EQ(c.records.size(), 1u);
  EXPECT_EQ(c.records[0].function_type, 6);
  EXPECT_EQ(c.records[0].num_points, 1600);
  EXPECT_EQ(c.records[0].trailing_values, 2);
  EXPECT_NEAR(c.records[0].y.real().sum() / 1602.0, 0.988, 0.0005);
  // The hammer record: an impulse of 114.8 N at 0.060 s.
  const std::string time = External("ufffiles_jl/dataset58_time.unv");
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(time); }), HasSubstr("it holds a time response (function type 1)"));
  const UffFile t = ReadUffFile(time);
  ASSERT_EQ(t.records.size(), 1u);
  Eigen::Index at = 0;
  const double peak = t.records[0].y.real().maxCoeff(&at);
  EXPECT_EQ(t.records[0].num_points, 4096);
  EXPECT_NEAR(peak, 114.8, 0.05);
  EXPECT_NEAR(t.records[0].x(at), 0.060, 4.88281e-4);
  // A vibrometer spectrum: 6400 lines from 1.25 Hz.
  const std::string spec = External("ufffiles_jl/dataset58_spectrum.unv");
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(spec); }), HasSubstr("spectrum (function type 12)"));
  const UffFile s = ReadUffFile(spec);
  EXPECT_EQ(s.records[0].num_points, 6400);
  EXPECT_DOUBLE_EQ(s.records[0].x(0), 1.25);
  EXPECT_NEAR(s.records[0].x(6399), 8000.0, 1e-6);
  // A DAQ waveform written with no field spacing: 66 numbers.
  const UffFile n = ReadUffFile(External("ufffiles_jl/dataset58_nospacing.uff"));
  ASSERT_EQ(n.records.size(), 1u);
  EXPECT_EQ(n.records[0].y.size(), 66);
  EXPECT_NEAR(n.records[0].y(0).real(), -3.09944e-4, 1e-12);
  EXPECT_NEAR(n.records[0].y(2).real(), -0.00115633, 1e-12);
  EXPECT_NEAR(n.records[0].x(1), 4.99942e-4, 1e-12);
}

// The eight format cases: each binary equals its ASCII twin to 1e-6
// relative (acceptance of issue #18; float32 against E13.5 or 13 digits).
TEST(Uff58External, FormatCasesBinaryEqualsAscii) {
  SKIP_WITHOUT_SHARED();
  for (int k = 1; k <= 8; ++k) {
    const std::string a = External("ufffiles_jl/dataset58_case" + std::to_string(k) + "_ascii.unv");
    const std::string b = External("ufffiles_jl/dataset58_case" + std::to_string(k) + "_binary.unv");
    const FrfReadResult ra = ReadFrfFile(a), rb = ReadFrfFile(b);
    const FrfKey key{"", Axis::kX, Axis::kX};
    ASSERT_EQ(ra.frfs.keys(), std::vector<FrfKey>{key}) << k;
    ASSERT_EQ(rb.frfs.keys(), std::vector<FrfKey>{key}) << k;
    EXPECT_EQ(ra.file_quantity, FrfQuantity::kAccelerance) << k;
    const Frf& fa = ra.frfs.at(key);
    const Frf& fb = rb.frfs.at(key);
    ASSERT_EQ(fa.size(), fb.size()) << k;
    // In the stored quantity (accelerance): the largest difference within
    // 1e-6 of the largest value; each value within 6e-6 of itself (E13.5 keeps
    // 6 significant digits, 5e-6, against float32's 6e-8).
    const auto stored = [](const Frf& g, int i) {
      return FromReceptance(FrfQuantity::kAccelerance, g.freq_hz()(i), g.receptance()(i));
    };
    double peak = 0.0, worst = 0.0;
    for (int i = 0; i < fa.size(); ++i) {
      // The abscissa is E13.5 in ASCII and float32 in binary: 6e-6 as above.
      ASSERT_LE(std::abs(fa.freq_hz()(i) - fb.freq_hz()(i)), 6e-6 * fa.freq_hz()(i)) << k << " line " << i;
      const std::complex<double> va = stored(fa, i), vb = stored(fb, i);
      peak = std::max(peak, std::abs(va));
      worst = std::max(worst, std::abs(va - vb));
      ASSERT_LE(std::abs(va - vb), 6e-6 * std::abs(va)) << k << " line " << i;
    }
    EXPECT_LE(worst, 1e-6 * peak) << k;
    const UffFile raw = ReadUffFile(a);
    if (raw.records[0].even) {
      EXPECT_DOUBLE_EQ(raw.records[0].dx, 0.25) << k;
      EXPECT_DOUBLE_EQ(raw.records[0].x(0), 0.0) << k;
    } else {
      EXPECT_NEAR(raw.records[0].x(0), 10.0, 1e-9) << k;
      EXPECT_NEAR(raw.records[0].x(raw.records[0].num_points - 1), 1000.0, 1e-3) << k;
    }
  }
}

TEST(Uff58External, OtherExportsAndParity) {
  SKIP_WITHOUT_SHARED();
  // Two 58b FRFs in one .ufb: rsp 1/+X and 1/+Y, ref 22/+X, 0-200 Hz.
  const FrfReadResult u = ReadFrfFile(External("ufffiles_jl/dataset58_ufb.ufb"));
  const std::vector<FrfKey> keys = {{"", Axis::kX, Axis::kX}, {"", Axis::kY, Axis::kX}};
  ASSERT_EQ(u.frfs.keys(), keys);
  EXPECT_NEAR(u.frfs.at(keys[0]).freq_hz().maxCoeff(), 200.0, 1e-6);
  // pyuff's ASCII/binary pair of a microphone record: 79292 samples, equal
  // within the ASCII rounding (5e-7 Pa, SOURCES.md).
  const UffFile a = ReadUffFile(External("pyuff/Sample_UFF58_ascii.uff"));
  const UffFile b = ReadUffFile(External("pyuff/Sample_UFF58b_bin.uff"));
  ASSERT_EQ(a.records.size(), 1u);
  ASSERT_EQ(b.records.size(), 1u);
  ASSERT_EQ(a.records[0].y.size(), 79292);
  ASSERT_EQ(b.records[0].y.size(), 79292);
  EXPECT_LE((a.records[0].y - b.records[0].y).cwiseAbs().maxCoeff(), 5e-7);
  EXPECT_THAT(CaptureError([&] { ReadFrfFile(External("pyuff/Sample_UFF58b_bin.uff")); }),
              HasSubstr("time response"));
  // 8-byte binary: a 5 Hz sine sampled at 100 Hz: y(t) = A sin(2 pi 5 t),
  // so y(t + 0.1 s) = y(t) and y(0.05 s) is the amplitude.
  const UffFile s = ReadUffFile(External("pyuff/binary8byte.uff"));
  ASSERT_EQ(s.records[0].y.size(), 250);
  const Eigen::VectorXd y = s.records[0].y.real();
  const double amp = y.cwiseAbs().maxCoeff();
  EXPECT_GT(amp, 0.0);
  // The samples are a sine of a single-precision argument: at t = 2.5 s the
  // argument is 78.5 rad, where float32 steps are 7.6e-6, so sin is off by
  // up to 3.8e-6 of the amplitude (1.2e-6 seen): 1e-5 of the amplitude.
  for (int k = 0; k + 20 < 250; ++k) ASSERT_NEAR(y(k + 20), y(k), 1e-5 * amp) << k;
  for (int k = 0; k < 250; ++k) ASSERT_NEAR(y(k), amp * std::sin(2.0 * M_PI * 5.0 * 0.01 * k), 1e-5 * amp) << k;
  // A tiny FRF with a Latin-1 superscript in its unit and no directions.
  const FrfReadResult n = ReadFrfFile(External("pyuff/non_ascii_header.uff"));
  ASSERT_EQ(n.frfs.size(), 1);
  EXPECT_EQ(n.file_quantity, FrfQuantity::kAccelerance);
  const Frf& g = n.frfs.begin()->second;
  EXPECT_EQ(g.size(), 5);  // 6 lines, the 0 Hz one dropped
  EXPECT_NEAR(g.freq_hz()(0), 0.195313, 1e-9);
  ASSERT_FALSE(n.warnings.empty());
  EXPECT_THAT(n.warnings[0], HasSubstr("gives no direction"));
}

// pyuff's measured accelerances (numpy text, one complex value per line,
// 0 Hz upward in 1 Hz steps): written as UFF58 accelerance by robomach's
// writer into a scratch folder (never into the project) and read back; the
// peaks SOURCES.md names (a free beam) are where |A| has its local maxima.
TEST(Uff58External, MeasuredAccelerancesRoundTripThroughUff) {
  SKIP_WITHOUT_SHARED();
  const std::string dir = TempDir("uff58_meas_point");
  for (int point = 1; point <= 3; ++point) {
    std::ifstream in(External("pyuff/meas_point_" + std::to_string(point) + ".txt"));
    std::vector<std::complex<double>> a;
    for (std::string s; std::getline(in, s);) {
      // "(re+imj)": the imaginary part starts at the last sign not after an 'e'.
      s = s.substr(1, s.size() - 3);
      size_t cut = s.size();
      for (size_t k = s.size() - 1; k > 0; --k) {
        if ((s[k] == '+' || s[k] == '-') && s[k - 1] != 'e' && s[k - 1] != 'E') {
          cut = k;
          break;
        }
      }
      a.emplace_back(std::stod(s.substr(0, cut)), std::stod(s.substr(cut)));
    }
    ASSERT_GE(a.size(), 1000u);
    const int n = static_cast<int>(a.size()) - 1;  // without 0 Hz
    Eigen::VectorXd f(n);
    Eigen::VectorXcd h(n);
    for (int k = 0; k < n; ++k) {
      f(k) = k + 1.0;
      h(k) = ToReceptance(FrfQuantity::kAccelerance, f(k), a[k + 1]);
    }
    dynamics::FrfSet set;
    set.Insert({"P" + std::to_string(point), Axis::kZ, Axis::kZ}, Frf::FromSamples(f, h));
    const std::string path = dir + "/p" + std::to_string(point) + ".uff";
    WriteUff58(path, set, FrfQuantity::kAccelerance);
    const FrfReadResult r = ReadFrfFile(path);
    EXPECT_EQ(r.file_quantity, FrfQuantity::kAccelerance);
    const Frf& g = r.frfs.at({"P" + std::to_string(point), Axis::kZ, Axis::kZ});
    ASSERT_EQ(g.size(), n);
    for (int k = 0; k < n; ++k) {
      const std::complex<double> back = FromReceptance(FrfQuantity::kAccelerance, g.freq_hz()(k), g.receptance()(k));
      ASSERT_LE(std::abs(back - a[k + 1]), 1e-11 * std::abs(a[k + 1])) << k;  // E20.12 and two conversions
    }
    for (double fm : {52.0, 142.0, 279.0, 460.0, 687.0, 959.0}) {
      double best = 0.0, arg = 0.0;
      for (int k = 0; k < n; ++k) {
        if (std::abs(g.freq_hz()(k) - fm) > 3.0) continue;
        const double m = std::abs(FromReceptance(FrfQuantity::kAccelerance, g.freq_hz()(k), g.receptance()(k)));
        if (m > best) {
          best = m;
          arg = g.freq_hz()(k);
        }
      }
      EXPECT_NEAR(arg, fm, 1.0 + 1e-9) << "point " << point << " mode " << fm;
    }
  }
}

}  // namespace
}  // namespace robomach::io
