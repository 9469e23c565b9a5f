// vision.calib.ToolCalibration*: the calibration file (format, atomic write, every kind of
// bad content named with its line) and the TCP choice (calibrated, nominal, refused).
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "arflex_vision_calib/tool_calibration.h"

namespace arflex {
namespace vision {
namespace calib {
namespace {

ToolCalibration Sample() {
  ToolCalibration c;
  c.tool = 1;
  c.name = "tool-gripper";
  c.method = "pivot";
  c.tcp_in_marker = Eigen::Vector3d(0.3004123456, -0.0007123456, 0.0005123456);
  c.rms_m = 12.5e-6;
  c.poses = 16;
  c.spread_deg = 21.25;
  c.date = "2026-12-07T21:00:00Z";
  return c;
}

// A scratch directory removed with everything in it at the end of the test.
class TempDir {
 public:
  TempDir() {
    char t[] = "/tmp/arflex-toolcal-XXXXXX";
    path_ = mkdtemp(t);
  }
  ~TempDir() { std::system(("rm -rf '" + path_ + "'").c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(ToolCalibrationTest, FormatThenParseGivesTheSameCalibration) {
  const ToolCalibration c = Sample();
  ToolCalibration back;
  std::string error;
  ASSERT_TRUE(ParseToolCalibration(FormatToolCalibration(c), "x.cal", &back, &error)) << error;
  EXPECT_EQ(back.tool, 1);
  EXPECT_EQ(back.name, "tool-gripper");
  EXPECT_EQ(back.method, "pivot");
  EXPECT_LT((back.tcp_in_marker - c.tcp_in_marker).norm(), 1e-10);
  EXPECT_NEAR(back.rms_m, c.rms_m, 1e-10);
  EXPECT_EQ(back.poses, 16);
  EXPECT_NEAR(back.spread_deg, 21.25, 1e-6);
  EXPECT_EQ(back.date, c.date);
}

TEST(ToolCalibrationTest, WriteIsReadBackAndLeavesNoTemporaryFile) {
  TempDir dir;
  const std::string path = dir.path() + "/tool-1.cal";
  std::string error;
  ASSERT_TRUE(WriteToolCalibration(path, Sample(), &error)) << error;
  ToolCalibration back;
  bool missing = true;
  ASSERT_TRUE(ReadToolCalibration(path, &back, &missing, &error)) << error;
  EXPECT_FALSE(missing);
  EXPECT_LT((back.tcp_in_marker - Sample().tcp_in_marker).norm(), 1e-10);
  EXPECT_NE(access((path + ".tmp").c_str(), F_OK), 0);
  // A bad calibration is not written (and the good one stays).
  ToolCalibration bad = Sample();
  bad.tcp_in_marker.x() = std::nan("");
  EXPECT_FALSE(WriteToolCalibration(path, bad, &error));
  EXPECT_NE(error.find("tcp_in_marker_m"), std::string::npos) << error;
  ASSERT_TRUE(ReadToolCalibration(path, &back, &missing, &error)) << error;
}

TEST(ToolCalibrationTest, MissingFileIsReportedAsMissing) {
  TempDir dir;
  ToolCalibration back;
  bool missing = false;
  std::string error;
  EXPECT_FALSE(ReadToolCalibration(dir.path() + "/tool-9.cal", &back, &missing, &error));
  EXPECT_TRUE(missing);
  EXPECT_NE(error.find("tool-9.cal"), std::string::npos) << error;
}

TEST(ToolCalibrationTest, BadContentIsRefusedNamingTheLine) {
  const std::string good = FormatToolCalibration(Sample());
  struct Case {
    std::string from, to, expect;
  };
  const Case cases[] = {
      {"arflex-tool-calibration 1", "arflex-tool-calibration 2", ":1: unsupported version"},
      {"arflex-tool-calibration 1", "something else", ":1: not a tool calibration file"},
      {"poses 16", "poses 16\ncolour blue", ":8: unknown key 'colour'"},
      {"poses 16", "poses 16\nposes 17", ":8: key 'poses' given twice"},
      {"tcp_in_marker_m ", "tcp_in_marker_m x ", ":5: tcp_in_marker_m"},
      {"residual_rms_m ", "residual_rms_m -", ":6: residual_rms_m"},
      {"poses 16", "poses 2", ":7: poses"},
      {"2026-12-07T21:00:00Z", "yesterday", ":9: date"},
      {"tool 1", "tool 0", ":2: tool"},
      {"method pivot\n", "", "missing key 'method'"},
  };
  for (const Case& c : cases) {
    std::string text = good;
    const size_t at = text.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    text.replace(at, c.from.size(), c.to);
    ToolCalibration out = Sample();
    out.poses = 99;
    std::string error;
    EXPECT_FALSE(ParseToolCalibration(text, "f.cal", &out, &error)) << text;
    EXPECT_NE(error.find("f.cal"), std::string::npos) << error;
    EXPECT_NE(error.find(c.expect), std::string::npos) << "expected '" << c.expect << "' in: " << error;
    EXPECT_EQ(out.poses, 99) << "the output is left unchanged";
  }
}

TEST(ToolCalibrationTest, CalibratedToolIsUsedAndSaidSo) {
  TempDir dir;
  const std::string path = dir.path() + "/tool-1.cal";
  std::string error;
  ASSERT_TRUE(WriteToolCalibration(path, Sample(), &error)) << error;
  const TcpChoice t = ChooseTcp(1, Eigen::Vector3d(0.3, 0, 0), path, true);
  ASSERT_TRUE(t.ok) << t.description;
  EXPECT_TRUE(t.calibrated);
  EXPECT_LT((t.tcp_in_marker - Sample().tcp_in_marker).norm(), 1e-10);
  for (const char* part : {"calibrated", "pivot", "16 poses", "0.0125 mm", "2026-12-07T21:00:00Z", "tool-1.cal"}) {
    EXPECT_NE(t.description.find(part), std::string::npos) << part << " in: " << t.description;
  }
}

TEST(ToolCalibrationTest, UncalibratedToolUsesTheNominalTcpOrIsRefusedWhenRequired) {
  TempDir dir;
  const std::string path = dir.path() + "/tool-1.cal";
  TcpChoice t = ChooseTcp(1, Eigen::Vector3d(0.3, 0, 0), path, false);
  ASSERT_TRUE(t.ok) << t.description;
  EXPECT_FALSE(t.calibrated);
  EXPECT_EQ(t.tcp_in_marker, Eigen::Vector3d(0.3, 0, 0));
  EXPECT_NE(t.description.find("nominal"), std::string::npos) << t.description;

  t = ChooseTcp(1, Eigen::Vector3d(0.3, 0, 0), path, true);
  EXPECT_FALSE(t.ok);
  EXPECT_NE(t.description.find("tool 1 is not calibrated"), std::string::npos) << t.description;
  EXPECT_NE(t.description.find(path), std::string::npos) << t.description;
}

TEST(ToolCalibrationTest, AnotherToolsOrABrokenFileIsAlwaysRefused) {
  TempDir dir;
  const std::string path = dir.path() + "/tool-2.cal";
  std::string error;
  ASSERT_TRUE(WriteToolCalibration(path, Sample(), &error)) << error;  // says tool 1
  TcpChoice t = ChooseTcp(2, Eigen::Vector3d(0.3, 0, 0), path, false);
  EXPECT_FALSE(t.ok);
  EXPECT_NE(t.description.find("is for tool 1"), std::string::npos) << t.description;

  WriteText(path, "arflex-tool-calibration 1\ntool 2\n");
  t = ChooseTcp(2, Eigen::Vector3d(0.3, 0, 0), path, false);
  EXPECT_FALSE(t.ok);
  EXPECT_NE(t.description.find("missing key"), std::string::npos) << t.description;
}

TEST(ToolCalibrationTest, PathIsInTheDataDirectory) {
  setenv("ARFLEX_DATA_DIR", "/srv/cell-data", 1);
  EXPECT_EQ(ToolCalibrationPath(2), "/srv/cell-data/tool-2.cal");
  unsetenv("ARFLEX_DATA_DIR");
  const std::string p = ToolCalibrationPath(1);
  EXPECT_EQ(p.front(), '/');
  EXPECT_NE(p.find("/data/tool-1.cal"), std::string::npos) << p;
}

}  // namespace
}  // namespace calib
}  // namespace vision
}  // namespace arflex
