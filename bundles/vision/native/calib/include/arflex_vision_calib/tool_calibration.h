// The tool calibration file: where a tool's calibrated TCP (in its marker frame) is kept, and
// which TCP vision uses.
//
// Format (text, one `key value` per line, '#' comments, every key exactly once):
//
//   arflex-tool-calibration 1
//   tool 1                                  # the tool's id (arflex.ToolState tool_id)
//   name tool-gripper                       # the tool component, for people
//   method pivot
//   tcp_in_marker_m 0.3001234 -0.0002345 0.0004567
//   residual_rms_m 0.0000123
//   poses 16
//   rotation_spread_deg 21.3
//   date 2026-12-07T21:00:00Z               # UTC, when it was measured
//
// It lives in the data directory ($ARFLEX_DATA_DIR, else ./data, as the trajectory
// programs) as tool-<id>.cal (ToolCalibrationPath), written atomically (temporary file,
// fsync, rename), so it survives a restart and a crash never leaves half a file.
//
// Allocation: strings and file I/O: not for an RT thread (configure time only).
#ifndef ARFLEX_VISION_CALIB_TOOL_CALIBRATION_H_
#define ARFLEX_VISION_CALIB_TOOL_CALIBRATION_H_

#include <Eigen/Core>
#include <string>

namespace arflex {
namespace vision {
namespace calib {

struct ToolCalibration {
  int tool = 0;                 // tool id (1: the gripper, 2: the spindle)
  std::string name;             // tool component name (no spaces)
  std::string method = "pivot";
  Eigen::Vector3d tcp_in_marker = Eigen::Vector3d::Zero();  // m
  double rms_m = 0.0;           // residual RMS of the calibration (m)
  int poses = 0;
  double spread_deg = 0.0;
  std::string date;             // YYYY-MM-DDTHH:MM:SSZ
};

// The present time as YYYY-MM-DDTHH:MM:SSZ.
std::string UtcNow();

// $dir/tool-<id>.cal, with $dir = $ARFLEX_DATA_DIR, else ./data (absolute).
std::string ToolCalibrationPath(int tool);

// Text of `c` in the format above.
std::string FormatToolCalibration(const ToolCalibration& c);

// Parses `text`; on failure sets `*error` to "<source>:<line>: what is wrong" (or
// "<source>: missing key ..." ) and returns false, leaving `*out` unchanged.
bool ParseToolCalibration(const std::string& text, const std::string& source, ToolCalibration* out,
                          std::string* error);

// Writes `c` to `path` atomically (after checking it as Parse would). False and `*error`.
bool WriteToolCalibration(const std::string& path, const ToolCalibration& c, std::string* error);

// Reads and parses `path`. A missing file sets `*missing` (may be null) and `*error`.
bool ReadToolCalibration(const std::string& path, ToolCalibration* out, bool* missing, std::string* error);

// Which TCP vision measures: the calibrated one from `path` when it is there and belongs to
// `tool`, else the nominal one, unless `require_calibrated`: then an uncalibrated tool is
// refused (ok = false) with the reason. A file that is there but unreadable, malformed or
// another tool's is always refused (fail closed: a wrong TCP moves the arm to the wrong place).
struct TcpChoice {
  bool ok = false;
  bool calibrated = false;
  Eigen::Vector3d tcp_in_marker = Eigen::Vector3d::Zero();
  std::string description;  // which TCP and why, or why refused
};
TcpChoice ChooseTcp(int tool, const Eigen::Vector3d& nominal, const std::string& path,
                    bool require_calibrated);

}  // namespace calib
}  // namespace vision
}  // namespace arflex

#endif  // ARFLEX_VISION_CALIB_TOOL_CALIBRATION_H_
