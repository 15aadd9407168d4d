// io::SniffFileKind (issue #35): each kind a user gives a reader by mistake
// is recognised from its first bytes, the shipped inputs are recognised as
// what they are, and the readers name the kind and what they expected.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "robomach/io/csv_table.h"
#include "robomach/io/file_kind.h"
#include "robomach/io/posture_file.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach::io {
namespace {

using robomach::testing::CaptureError;
using robomach::testing::SourcePath;
using robomach::testing::TempDir;
using robomach::testing::WriteText;

TEST(FileKind, RecognisesEachKindFromItsFirstBytes) {
  EXPECT_EQ(SniffText(std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16)).kind, FileKind::kPng);
  EXPECT_EQ(SniffText("%PDF-1.7\n").kind, FileKind::kPdf);
  EXPECT_EQ(SniffText(std::string("PK\x03\x04\x14\0", 6)).kind, FileKind::kZip);
  EXPECT_EQ(SniffText(std::string("\x1f\x8b\x08\0", 4)).kind, FileKind::kGzip);
  EXPECT_EQ(SniffText("\xff\xd8\xff\xe0").kind, FileKind::kJpeg);
  EXPECT_EQ(SniffText(std::string("ab\0cd", 5)).kind, FileKind::kBinary);
  EXPECT_EQ(SniffText("    -1\n    58\n").kind, FileKind::kUff58);
  // Binary records (58b) after a text header are still UFF58.
  EXPECT_EQ(SniffText(std::string("    -1\n    58b     2         2        11        14\n\0\x01\x02", 53)).kind,
            FileKind::kUff58);
  EXPECT_EQ(SniffText("<?xml version=\"1.0\"?>\n<robot name=\"x\"/>").kind, FileKind::kXml);
  EXPECT_EQ(SniffText("ISO-10303-21;\nHEADER;\n").kind, FileKind::kStep);
  EXPECT_EQ(SniffText("# a comment: with a colon\nrobot:\n  urdf: a.urdf\n").kind, FileKind::kYaml);
  EXPECT_EQ(SniffText("- 1\n- 2\n").kind, FileKind::kYaml);
  EXPECT_EQ(SniffText("key: [1, 2, 3]\n").kind, FileKind::kYaml);
  EXPECT_EQ(SniffText("\xEF\xBB\xBF# quantity: receptance\npose_id,q1_deg\nP1,0\n").kind, FileKind::kCsv);
  EXPECT_EQ(SniffText("freq_hz\n1\n2\n").kind, FileKind::kText);  // one column: not refused
  EXPECT_EQ(SniffText("\n  \n").kind, FileKind::kEmpty);
  // Siemens part programs and table archives (formats.md §8.4): the header
  // line, an assignment (also after a block number and ';' comments, some
  // holding commas), CHANDATA.
  EXPECT_EQ(SniffText("%_N_COMP_MPF\n;$PATH=/_N_MPF_DIR\n").kind, FileKind::kMpf);
  EXPECT_EQ(SniffText("; tables, exported\n$AA_ENC_COMP[0,0,AX1]=0.0\n").kind, FileKind::kMpf);
  EXPECT_EQ(SniffText("N10 $AN_CEC[0,0]=0.0\n").kind, FileKind::kMpf);
  EXPECT_EQ(SniffText("CHANDATA(1)\n").kind, FileKind::kMpf);
  EXPECT_EQ(SniffText("%YAML 1.2\n---\na: 1\n").kind, FileKind::kYaml);
  EXPECT_EQ(SniffText("\xff\xfeh\0").kind, FileKind::kUtf16);
}

// A CSV is named by its header when it is one of formats.md's tables, so a
// CSV given to the wrong option says which table it is.
TEST(FileKind, NamesTheTableOfAKnownCsvHeader) {
  const FileSniff t = SniffText("# log\nt_s,axis,K0_mm,tan_beta,P0_mm\n0,X,0,0,0\n");
  EXPECT_EQ(t.kind, FileKind::kCsv);
  EXPECT_EQ(t.description, "a CSV table");
  EXPECT_EQ(t.table, "the temperature log of docs/formats.md §8.4");
  EXPECT_EQ(WrongFileKindMessage(t, "X", "--compensation"),
            "this is a CSV table; --compensation expects X (its columns are those of the temperature log of "
            "docs/formats.md §8.4)");
  EXPECT_EQ(SniffText("t_s,X_count,Y_count\n").table, "the encoder counts of docs/formats.md §8.1");
  EXPECT_EQ(SniffText("pose_id,q1_deg,q2_deg\n").table, "the posture CSV of docs/formats.md §1");
  EXPECT_EQ(SniffText("a,b\n1,2\n").table, "");
  EXPECT_EQ(WrongFileKindMessage(SniffText("a,b\n"), "X"), "this is a CSV table; expected X");
}

TEST(FileKind, ShippedInputsAreWhatTheirReadersExpect) {
  EXPECT_EQ(SniffFileKind(SourcePath("config/kr210.yaml")).kind, FileKind::kYaml);
  EXPECT_EQ(SniffFileKind(SourcePath("config/cut_demo.yaml")).kind, FileKind::kYaml);
  EXPECT_EQ(SniffFileKind(SourcePath("config/postures_demo.csv")).kind, FileKind::kCsv);
  EXPECT_EQ(SniffFileKind(SourcePath("tests/data/tracker_campaign.csv")).kind, FileKind::kCsv);
  EXPECT_EQ(SniffFileKind(SourcePath("tests/data/kr210_P1_receptance.csv")).kind, FileKind::kCsv);
  EXPECT_EQ(SniffFileKind(SourcePath("tests/data/kr210_P1_receptance.uff")).kind, FileKind::kUff58);
  EXPECT_EQ(SniffFileKind(SourcePath("config/kr210_r2700_2.urdf")).kind, FileKind::kXml);
  EXPECT_EQ(SniffFileKind(SourcePath("config/no_such_file.csv")).kind, FileKind::kMissing);
}

// Every shipped and test input is sniffed as the kind its extension says
// (or as plain text, which no reader refuses), so the check never refuses a
// good file.
TEST(FileKind, EveryShippedFileIsSniffedAsItsExtensionSays) {
  namespace fs = std::filesystem;
  int checked = 0;
  for (const char* root : {"config", "tests/data"}) {
    for (const auto& e : fs::recursive_directory_iterator(SourcePath(root))) {
      if (!e.is_regular_file()) continue;
      const std::string ext = e.path().extension().string();
      const FileSniff s = SniffFileKind(e.path().string());
      const bool text = s.kind == FileKind::kText || s.kind == FileKind::kEmpty;
      if (ext == ".csv") {
        EXPECT_TRUE(s.kind == FileKind::kCsv || text) << e.path() << ": " << s.description;
      } else if (ext == ".yaml" || ext == ".yml") {
        EXPECT_TRUE(s.kind == FileKind::kYaml || text) << e.path() << ": " << s.description;
      } else if (ext == ".uff" || ext == ".unv") {
        EXPECT_EQ(s.kind, FileKind::kUff58) << e.path();
      } else if (ext == ".mpf") {
        EXPECT_EQ(s.kind, FileKind::kMpf) << e.path() << ": " << s.description;
      } else {
        continue;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 50);
}

TEST(FileKind, ReadersNameWhatTheyWereGivenAndWhatTheyExpect) {
  EXPECT_EQ(CaptureError([] { ReadPostureFile(SourcePath("config/kr210.yaml"), 6); }),
            SourcePath("config/kr210.yaml") + ": this is a YAML file; expected the posture CSV of docs/formats.md §1");
  const std::string png = WriteText(TempDir("file_kind") + "/robot.yaml", std::string("\x89PNG\r\n\x1a\n\0\0", 10));
  EXPECT_EQ(CaptureError([&] { LoadRobotConfig(png); }),
            png + ": this is a PNG image; expected a robot config YAML (as config/kr210.yaml)");
  EXPECT_EQ(WrongFileKindMessage({FileKind::kUff58, "a UFF58 file"}, kTrackerCsvFormat, "--tracker"),
            "this is a UFF58 file; --tracker expects the laser-tracker CSV of docs/formats.md §2");
  // A missing file is its own error type (the tools exit 66 for it).
  EXPECT_THROW(CsvTable::ReadFile(SourcePath("config/no_such_file.csv")), MissingFileError);
}

// Posture units (issue #35): radians under _deg headers and degrees under
// _rad headers are named; an angle no joint can have is refused.
TEST(PostureUnits, RadiansUnderDegreesAndDegreesUnderRadiansAreNamed) {
  const std::string dir = TempDir("posture_units");
  std::vector<std::string> w;
  ReadPostureFile(WriteText(dir + "/r.csv", "pose_id,q1_deg,q2_deg\nA,0,-1.57\nB,0.5,1.2\n"), 2, &w);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("these look like radians"), std::string::npos) << w[0];
  ReadPostureFile(WriteText(dir + "/d.csv", "pose_id,q1_rad,q2_rad\nA,0,-90\n"), 2, &w);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("an angle of 90 under a _rad header is 5157 deg"), std::string::npos) << w[0];
  // Degrees that happen to be small and whole, and real radians: no finding.
  ReadPostureFile(WriteText(dir + "/ok1.csv", "pose_id,q1_deg,q2_deg\nA,0,-5\nB,3,2\n"), 2, &w);
  EXPECT_TRUE(w.empty());
  ReadPostureFile(WriteText(dir + "/ok2.csv", "pose_id,q1_rad,q2_rad\nA,0,-1.57\n"), 2, &w);
  EXPECT_TRUE(w.empty());
  ReadPostureFile(SourcePath("config/postures_demo.csv"), 6, &w);
  EXPECT_TRUE(w.empty());
  const std::string huge = WriteText(dir + "/h.csv", "pose_id,q1_deg,q2_deg\nA,1e308,0\n");
  EXPECT_NE(CaptureError([&] { ReadPostureFile(huge, 2); }).find(huge + ":2: column q1_deg: 1e308 deg is not a joint angle"),
            std::string::npos);
}

}  // namespace
}  // namespace robomach::io
