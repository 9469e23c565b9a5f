#include "arflex_vision_calib/tool_calibration.h"

#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

namespace arflex {
namespace vision {
namespace calib {
namespace {

constexpr const char* kMagic = "arflex-tool-calibration";
constexpr int kVersion = 1;
const char* const kKeys[] = {"tool", "name", "method", "tcp_in_marker_m", "residual_rms_m",
                             "poses", "rotation_spread_deg", "date"};

std::string Fixed(double x, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, x);
  return buf;
}

// Reads exactly `n` finite numbers from `in` (nothing after them).
bool Numbers(const std::string& in, int n, double* out) {
  std::istringstream s(in);
  for (int i = 0; i < n; ++i) {
    std::string w;
    if (!(s >> w)) return false;
    char* end = nullptr;
    out[i] = std::strtod(w.c_str(), &end);
    if (end == w.c_str() || *end != '\0' || !std::isfinite(out[i])) return false;
  }
  std::string rest;
  return !(s >> rest);
}

bool IsDate(const std::string& d) {
  // YYYY-MM-DDTHH:MM:SSZ, fields in range.
  struct tm t {};
  if (d.size() != 20) return false;
  const char* end = strptime(d.c_str(), "%Y-%m-%dT%H:%M:%SZ", &t);
  return end != nullptr && *end == '\0';
}

bool IsWord(const std::string& w) {
  if (w.empty() || w.size() > 64) return false;
  for (char c : w) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) return false;
  }
  return true;
}

// Checks the values of one key into `c`; returns the problem or "".
std::string Take(const std::string& key, const std::string& value, ToolCalibration* c) {
  double v[3];
  if (key == "tool") {
    if (!Numbers(value, 1, v) || v[0] < 1 || v[0] > 1000 || v[0] != std::floor(v[0])) {
      return "tool: '" + value + "' is not a tool id (a whole number 1..1000)";
    }
    c->tool = static_cast<int>(v[0]);
  } else if (key == "name" || key == "method") {
    if (!IsWord(value)) return key + ": '" + value + "' is not one word of letters, digits, '-', '_', '.'";
    (key == "name" ? c->name : c->method) = value;
  } else if (key == "tcp_in_marker_m") {
    if (!Numbers(value, 3, v) || Eigen::Vector3d(v[0], v[1], v[2]).norm() > 2.0) {
      return "tcp_in_marker_m: '" + value + "' is not three finite coordinates within 2 m";
    }
    c->tcp_in_marker = Eigen::Vector3d(v[0], v[1], v[2]);
  } else if (key == "residual_rms_m") {
    if (!Numbers(value, 1, v) || v[0] < 0 || v[0] > 0.01) {
      return "residual_rms_m: '" + value + "' is not a residual in 0..0.01 m";
    }
    c->rms_m = v[0];
  } else if (key == "poses") {
    if (!Numbers(value, 1, v) || v[0] < 3 || v[0] > 10000 || v[0] != std::floor(v[0])) {
      return "poses: '" + value + "' is not a pose count of at least 3";
    }
    c->poses = static_cast<int>(v[0]);
  } else if (key == "rotation_spread_deg") {
    if (!Numbers(value, 1, v) || v[0] < 0 || v[0] > 180) {
      return "rotation_spread_deg: '" + value + "' is not an angle in 0..180";
    }
    c->spread_deg = v[0];
  } else if (key == "date") {
    if (!IsDate(value)) return "date: '" + value + "' is not a UTC time YYYY-MM-DDTHH:MM:SSZ";
    c->date = value;
  } else {
    return "unknown key '" + key + "'";
  }
  return "";
}

std::string Trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

}  // namespace

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  struct tm t {};
  gmtime_r(&now, &t);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &t);
  return buf;
}

std::string ToolCalibrationPath(int tool) {
  std::string dir;
  const char* d = std::getenv("ARFLEX_DATA_DIR");
  if (d != nullptr && *d != '\0') {
    dir = d;
  } else {
    char cwd[4096];
    dir = getcwd(cwd, sizeof cwd) != nullptr ? std::string(cwd) + "/data" : "data";
  }
  return dir + "/tool-" + std::to_string(tool) + ".cal";
}

std::string FormatToolCalibration(const ToolCalibration& c) {
  std::string s = std::string(kMagic) + " " + std::to_string(kVersion) + "\n";
  s += "tool " + std::to_string(c.tool) + "\n";
  s += "name " + c.name + "\n";
  s += "method " + c.method + "\n";
  s += "tcp_in_marker_m " + Fixed(c.tcp_in_marker.x(), 10) + " " + Fixed(c.tcp_in_marker.y(), 10) + " " +
       Fixed(c.tcp_in_marker.z(), 10) + "\n";
  s += "residual_rms_m " + Fixed(c.rms_m, 10) + "\n";
  s += "poses " + std::to_string(c.poses) + "\n";
  s += "rotation_spread_deg " + Fixed(c.spread_deg, 3) + "\n";
  s += "date " + c.date + "\n";
  return s;
}

bool ParseToolCalibration(const std::string& text, const std::string& source, ToolCalibration* out,
                          std::string* error) {
  std::istringstream in(text);
  std::string line;
  int n = 0;
  bool header = false;
  std::map<std::string, int> seen;
  ToolCalibration c;
  while (std::getline(in, line)) {
    ++n;
    const size_t hash = line.find('#');
    line = Trim(hash == std::string::npos ? line : line.substr(0, hash));
    if (line.empty()) continue;
    const size_t sp = line.find_first_of(" \t");
    const std::string key = line.substr(0, sp);
    const std::string value = sp == std::string::npos ? "" : Trim(line.substr(sp));
    const std::string where = source + ":" + std::to_string(n) + ": ";
    if (!header) {
      if (key != kMagic) {
        *error = where + "not a tool calibration file (the first line must be '" + kMagic + " " +
                 std::to_string(kVersion) + "')";
        return false;
      }
      if (value != std::to_string(kVersion)) {
        *error = where + "unsupported version '" + value + "' (this reader knows " + std::to_string(kVersion) + ")";
        return false;
      }
      header = true;
      continue;
    }
    if (seen.count(key) != 0) {
      *error = where + "key '" + key + "' given twice (first on line " + std::to_string(seen[key]) + ")";
      return false;
    }
    const std::string bad = Take(key, value, &c);
    if (!bad.empty()) {
      *error = where + bad;
      return false;
    }
    seen[key] = n;
  }
  if (!header) {
    *error = source + ": empty: not a tool calibration file";
    return false;
  }
  for (const char* k : kKeys) {
    if (seen.count(k) == 0) {
      *error = source + ": missing key '" + k + "'";
      return false;
    }
  }
  *out = c;
  return true;
}

bool WriteToolCalibration(const std::string& path, const ToolCalibration& c, std::string* error) {
  const std::string text = FormatToolCalibration(c);
  ToolCalibration check;
  if (!ParseToolCalibration(text, path + " (to be written)", &check, error)) return false;
  // Non-finite values print as "nan": the parse above refuses them; also check the precision
  // did not change the offset.
  if ((check.tcp_in_marker - c.tcp_in_marker).norm() > 1e-9) {
    *error = path + ": tcp_in_marker_m does not survive formatting";
    return false;
  }
  // Atomic: the whole text into path.tmp, flushed to the disk, then renamed over the file.
  const std::string tmp = path + ".tmp";
  FILE* f = std::fopen(tmp.c_str(), "we");
  if (f == nullptr) {
    *error = tmp + ": cannot create: " + std::strerror(errno);
    return false;
  }
  bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size() && std::fflush(f) == 0 &&
            fsync(fileno(f)) == 0;
  int e = errno;
  if (std::fclose(f) != 0 && ok) {
    ok = false;
    e = errno;
  }
  if (ok && rename(tmp.c_str(), path.c_str()) != 0) {
    ok = false;
    e = errno;
  }
  if (!ok) {
    *error = path + ": cannot write: " + std::strerror(e);
    unlink(tmp.c_str());
  }
  return ok;
}

bool ReadToolCalibration(const std::string& path, ToolCalibration* out, bool* missing, std::string* error) {
  if (missing != nullptr) *missing = false;
  std::ifstream f(path);
  if (!f) {
    const int e = errno;
    if (missing != nullptr) *missing = (e == ENOENT);
    *error = path + ": cannot read: " + std::strerror(e);
    return false;
  }
  std::stringstream text;
  text << f.rdbuf();
  if (text.str().size() > 4096) {
    *error = path + ": too large for a tool calibration file (" + std::to_string(text.str().size()) + " bytes)";
    return false;
  }
  return ParseToolCalibration(text.str(), path, out, error);
}

TcpChoice ChooseTcp(int tool, const Eigen::Vector3d& nominal, const std::string& path, bool require_calibrated) {
  TcpChoice t;
  ToolCalibration c;
  bool missing = false;
  std::string error;
  if (!ReadToolCalibration(path, &c, &missing, &error)) {
    if (!missing) {
      t.description = "tool " + std::to_string(tool) + ": calibration refused: " + error;
      return t;
    }
    if (require_calibrated) {
      t.description = "tool " + std::to_string(tool) + " is not calibrated (no " + path +
                      ") and a calibration is required: correction refused; run a pivot calibration";
      return t;
    }
    t.ok = true;
    t.tcp_in_marker = nominal;
    t.description = "nominal TCP (" + Fixed(nominal.x(), 4) + ", " + Fixed(nominal.y(), 4) + ", " +
                    Fixed(nominal.z(), 4) + ") m: tool " + std::to_string(tool) + " is not calibrated (no " +
                    path + ")";
    return t;
  }
  if (c.tool != tool) {
    t.description = "tool " + std::to_string(tool) + ": calibration refused: " + path + " is for tool " +
                    std::to_string(c.tool) + " (" + c.name + ")";
    return t;
  }
  t.ok = true;
  t.calibrated = true;
  t.tcp_in_marker = c.tcp_in_marker;
  t.description = "calibrated TCP (" + Fixed(c.tcp_in_marker.x(), 6) + ", " + Fixed(c.tcp_in_marker.y(), 6) +
                  ", " + Fixed(c.tcp_in_marker.z(), 6) + ") m of tool " + std::to_string(tool) + " (" + c.name +
                  "): " + c.method + ", " + std::to_string(c.poses) + " poses, residual RMS " +
                  Fixed(1e3 * c.rms_m, 4) + " mm, " + c.date + ", " + path;
  return t;
}

}  // namespace calib
}  // namespace vision
}  // namespace arflex
