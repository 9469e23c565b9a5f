// arflex-pivot-calibration: the tool (TCP) calibration of the simulated cell from camera
// images alone, as it is done on a real cell with a pivot.
//
// The simulated tool tip rests in one fixed point (a divot) while the arm turns the tool
// into N orientations. The simulator holds the tip there as the divot would: the arm is put
// where the TRUE model's tip is on the pivot (that is the only use of the TRUE model in the
// measurement; the orientations are chosen on the nominal model). For each orientation the
// four cameras are rendered, the tool tags detected and the marker (flange) pose estimated
// by vision's multi-view fit, with the cameras calibrated from the reference board as
// vision does. The pivot solver (arflex_vision_calib) gets these marker poses and nothing
// else. The TRUE TCP offset is read only afterwards, to score the result.
//
// Usage: arflex-pivot-calibration [--poses N] [--frames K] [--width W --height H]
//                                 [--noise SIGMA] [--tilt-deg D] [--pivot X,Y,Z] [--tool ID]
//                                 [--tool-name NAME]
//                                 [--out FILE] [--check TOL_MM] [--unweighted]
// --frames: frames per orientation pooled into one estimate (1); --tilt-deg: the tool's
// tilt about the pivot's vertical and horizontal axes (35); --pivot X,Y,Z: the divot (1.9,0,0.6); --out: writes the tool
// calibration file (tool_calibration.h); --check: exit status 1 when the recovered offset is
// further than TOL_MM from the TRUE one; --unweighted: every pose weighs the same (default:
// 1 / the pose estimate's reprojection RMS^2) (the ctest vision.calib.sim_pivot), 2 on bad
// arguments, 3 when the set is refused or vision fails.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "arflex_sim/cell.h"
#include "arflex_sim/render.h"
#include "arflex_tcpcorr/correction.h"
#include "arflex_vision/detector.h"
#include "arflex_vision/estimator.h"
#include "arflex_vision/geometry.h"
#include "arflex_vision_calib/pivot.h"
#include "arflex_vision_calib/tool_calibration.h"

namespace {

using arflex::sim::Cell;
using arflex::sim::JointVector;
using arflex::sim::Renderer;
namespace vision = arflex::vision;
namespace calib = arflex::vision::calib;

struct Options {
  int poses = 24;
  int frames = 1;
  int width = 1280;
  int height = 1024;
  double noise = 2.0;
  double tilt_deg = 35.0;
  Eigen::Vector3d pivot{1.9, 0.0, 0.6};  // the divot (m, cell frame)
  int tool = 1;                    // tool id: the gripper
  std::string tool_name = "tool-gripper";
  std::string out;
  double check_mm = -1;  // < 0: no check
  bool weighted = true;  // weigh each pose by 1 / its reprojection RMS^2 (--unweighted: all 1)
};

// The tag's printed face in its parent frame (the simulator's tag is a 1 mm box).
vision::TagModel ToVision(const arflex::sim::TagSpec& t) {
  vision::TagModel m;
  m.id = t.id;
  m.size = t.size;
  m.pose.linear() = Eigen::Quaterniond(t.quat[0], t.quat[1], t.quat[2], t.quat[3]).toRotationMatrix();
  m.pose.translation() = Eigen::Vector3d(t.pos[0], t.pos[1], t.pos[2]) +
                         m.pose.linear() * Eigen::Vector3d(0, 0, 0.0005);
  return m;
}

// The simulated cell seen through vision: renders, detects, calibrates the cameras from the
// board and measures the marker pose.
class SimVision {
 public:
  bool Init(const Options& o, std::string* error) {
    o_ = o;
    auto config = arflex::sim::DefaultCellConfig();
    config.max_render_width = std::max(o.width, 640);
    config.max_render_height = std::max(o.height, 480);
    // Parked facing away from the board, so that every camera sees the whole board.
    cell_ = Cell::Create(config, {M_PI, 0.3, 0.3, 0.0, 0.6, 0.0}, error);
    if (!cell_) return false;
    renderer_ = Renderer::Create(cell_->model(), o.width, o.height, error);
    if (!renderer_) return false;
    vision::DetectorOptions d;
    d.max_width = o.width;
    d.max_height = o.height;
    detector_ = vision::TagDetector::Create(d, error);
    if (!detector_) return false;
    for (const auto& t : config.tags) (t.body == "world" ? board_ : tool_).push_back(ToVision(t));
    rgb_.assign(static_cast<size_t>(o.width) * o.height * 3, 0);
    cameras_.resize(renderer_->camera_count());
    return true;
  }

  // Board calibration of every camera, `frames` frames pooled per camera.
  bool CalibrateCameras(int frames, std::string* error) {
    renderer_->SetState(cell_->qpos());
    for (int c = 0; c < static_cast<int>(cameras_.size()); ++c) {
      const auto k = renderer_->Intrinsics(c);
      cameras_[c].k = vision::Intrinsics{k.width, k.height, k.fx, k.fy, k.cx, k.cy};
      std::vector<vision::TagDetection> pooled;
      for (int f = 0; f < frames; ++f) {
        std::array<vision::TagDetection, 16> dets;
        const int n = DetectIn(c, 500 + 97 * c + f, nullptr, dets.data());
        for (int i = 0; i < n; ++i) {
          const bool on_board = std::any_of(board_.begin(), board_.end(),
                                            [&](const vision::TagModel& b) { return b.id == dets[i].id; });
          if (on_board && pooled.size() < vision::kMaxObservations) pooled.push_back(dets[i]);
        }
      }
      if (!vision::CalibrateCamera(&cameras_[c], board_, pooled.data(), static_cast<int>(pooled.size()),
                                   vision::EstimatorOptions(), nullptr, error)) {
        *error = "camera " + std::to_string(c) + ": " + *error;
        return false;
      }
    }
    return true;
  }

  // The marker pose at the arm's present state from `frames` frames of every camera pooled
  // into one multi-view estimate (ROI around the nominal prediction from the joint state).
  vision::PoseEstimate MeasureMarker(int frames, uint64_t seed) {
    const JointVector q = cell_->ReadJointState().q;
    const Eigen::Isometry3d predicted = cell_->nominal().Flange(q);
    renderer_->SetState(cell_->qpos());
    std::array<vision::Observation, vision::kMaxObservations> obs;
    int nobs = 0;
    for (int f = 0; f < frames; ++f) {
      for (int c = 0; c < static_cast<int>(cameras_.size()); ++c) {
        const vision::Roi roi = vision::PredictRoi(cameras_[c], predicted, tool_, 30.0);
        if (roi.empty()) continue;
        std::array<vision::TagDetection, 16> dets;
        const int n = DetectIn(c, seed * 1009 + 31 * f + c, &roi, dets.data());
        vision::CollectObservations(c, dets.data(), n, tool_, obs.data(), &nobs);
      }
    }
    return vision::EstimateObjectPose(cameras_, tool_, obs.data(), nobs, &predicted, vision::EstimatorOptions());
  }

  Cell& cell() { return *cell_; }

 private:
  int DetectIn(int camera, uint64_t seed, const vision::Roi* roi, vision::TagDetection* dets) {
    arflex::sim::SensorEffects fx;
    fx.noise_sigma = o_.noise;
    fx.seed = seed;
    renderer_->Render(camera, rgb_.data(), &fx);
    const vision::FrameView frame{rgb_.data(), o_.width, o_.height, 3 * o_.width, vision::PixelFormat::kRgb8};
    return detector_->Detect(frame, roi, roi ? 1 : 0, dets, 16, nullptr);
  }

  Options o_;
  std::unique_ptr<Cell> cell_;
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<vision::TagDetector> detector_;
  std::vector<vision::Camera> cameras_;
  std::vector<vision::TagModel> board_, tool_;
  std::vector<uint8_t> rgb_;
};

// The divot holds the tip: moves the simulated arm (at rest, static compliance) so that the
// TRUE tip is at `pivot` with the tool orientation `r` (q from the nominal Jacobian, the
// TRUE tip as the physical constraint). False if it does not get within 1e-9 m.
bool HoldTipAt(Cell* cell, const Eigen::Vector3d& pivot, const Eigen::Matrix3d& r, JointVector* q) {
  Eigen::Isometry3d want = Eigen::Isometry3d::Identity();
  want.linear() = r;
  want.translation() = pivot;
  for (int it = 0; it < 100; ++it) {
    cell->ResetTo(*q);
    const auto e = arflex::tcpcorr::PoseError(want, cell->TrueTcp());
    if (e.head<3>().norm() < 1e-10 && e.tail<3>().norm() < 1e-9) return true;
    const auto dq = arflex::tcpcorr::DampedSolve(cell->nominal().TcpJacobian(*q), e, 1e-4);
    for (int j = 0; j < 6; ++j) (*q)[j] += dq(j);
  }
  return false;
}

// N tool orientations about the pivot: the tool pitched down 45 deg facing away from the
// base, turned about the vertical by up to +-tilt, pitched by up to +-0.8 tilt and rolled
// about its own axis by up to +-1.2 tilt (a Lissajous pattern, so every axis is exercised).
std::vector<Eigen::Matrix3d> Orientations(const Eigen::Vector3d& pivot, int n, double tilt_deg) {
  const double yaw0 = std::atan2(pivot.y(), pivot.x()), t = tilt_deg * M_PI / 180.0;
  std::vector<Eigen::Matrix3d> out;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    out.push_back((Eigen::AngleAxisd(yaw0 + t * std::cos(a), Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(M_PI / 4 + 0.8 * t * std::sin(a), Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(1.2 * t * std::sin(2 * a + 0.3), Eigen::Vector3d::UnitX()))
                      .toRotationMatrix());
  }
  return out;
}

bool ParseArgs(int argc, char** argv, Options* o) {
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (k == "--unweighted") {
      o->weighted = false;
      continue;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "pivot-calibration: %s needs a value (or is unknown)\n", k.c_str());
      return false;
    }
    const std::string v = argv[++i];
    if (k == "--tool-name") {
      o->tool_name = v;
      continue;
    }
    if (k == "--out") {
      o->out = v;
      continue;
    }
    if (k == "--pivot") {
      double x, y, z;
      char extra;
      if (std::sscanf(v.c_str(), "%lf,%lf,%lf%c", &x, &y, &z, &extra) != 3 || !std::isfinite(x + y + z)) {
        std::fprintf(stderr, "pivot-calibration: --pivot: '%s' is not x,y,z (m)\n", v.c_str());
        return false;
      }
      o->pivot = Eigen::Vector3d(x, y, z);
      continue;
    }
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (end == v.c_str() || *end != '\0' || !std::isfinite(x) || x < 0) {
      std::fprintf(stderr, "pivot-calibration: %s: '%s' is not a non-negative number\n", k.c_str(), v.c_str());
      return false;
    }
    if (k == "--poses") o->poses = static_cast<int>(x);
    else if (k == "--frames") o->frames = static_cast<int>(x);
    else if (k == "--width") o->width = static_cast<int>(x);
    else if (k == "--height") o->height = static_cast<int>(x);
    else if (k == "--noise") o->noise = x;
    else if (k == "--tilt-deg") o->tilt_deg = x;
    else if (k == "--check") o->check_mm = x;
    else if (k == "--tool") o->tool = static_cast<int>(x);
    else {
      std::fprintf(stderr, "pivot-calibration: unknown argument '%s'\n", k.c_str());
      return false;
    }
  }
  if (o->poses < 3 || o->poses > 64 || o->frames < 1 || o->frames > 4) {
    std::fprintf(stderr, "pivot-calibration: --poses must be in 3..64 and --frames in 1..4\n");
    return false;
  }
  if (o->width < 320 || o->width > 1280 || o->height < 240 || o->height > 1024) {
    std::fprintf(stderr, "pivot-calibration: --width/--height must be within 320x240..1280x1024\n");
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!ParseArgs(argc, argv, &o)) return 2;
  const auto t0 = std::chrono::steady_clock::now();
  SimVision sim;
  std::string error;
  if (!sim.Init(o, &error) || !sim.CalibrateCameras(8, &error)) {
    std::fprintf(stderr, "pivot-calibration: %s\n", error.c_str());
    return 3;
  }
  const Eigen::Vector3d pivot = o.pivot;
  const double calib_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("arflex-pivot-calibration: %d orientations about (%.2f, %.2f, %.2f) m, tilt %.0f deg, "
              "%dx%d, noise %.1f DN, %d frame(s) x 4 cameras per orientation\n",
              o.poses, pivot.x(), pivot.y(), pivot.z(), o.tilt_deg, o.width, o.height, o.noise, o.frames);
  // Scoring only: the TRUE and nominal offsets (diagnostics per pose and the final score).
  const auto& cfg = sim.cell().config();
  const Eigen::Vector3d nominal(cfg.arm.tcp_offset[0], cfg.arm.tcp_offset[1], cfg.arm.tcp_offset[2]);
  const auto& d = sim.cell().errors().offset_error[arflex::sim::kNumJoints];
  const Eigen::Vector3d truth = nominal + Eigen::Vector3d(d[0], d[1], d[2]);
  std::printf("%4s %6s %5s %6s %14s %16s %9s\n", "pose", "views", "tags", "rms px", "tip err (mm)",
              "tip sigma (mm)", "valid");
  std::vector<Eigen::Isometry3d> measured;
  std::vector<double> weights;
  JointVector q = {0.0, 0.3, 0.3, 0.0, 0.6, 0.0};
  const std::vector<Eigen::Matrix3d> orientations = Orientations(pivot, o.poses, o.tilt_deg);
  for (int i = 0; i < o.poses; ++i) {
    if (!HoldTipAt(&sim.cell(), pivot, orientations[i], &q)) {
      std::fprintf(stderr, "pivot-calibration: orientation %d cannot be reached with the tip on the pivot\n", i);
      return 3;
    }
    const vision::PoseEstimate e = sim.MeasureMarker(o.frames, 1 + i);
    // Diagnostics (TRUE used to score only): where this measured marker pose puts the TRUE
    // tip against the pivot, and the estimate's own sigma at the tip.
    Eigen::Isometry3d tip = Eigen::Isometry3d::Identity();
    tip.translation() = nominal;
    const double sigma = std::sqrt(vision::TransformEstimate(e, tip).covariance.topLeftCorner<3, 3>().trace());
    std::printf("%4d %6d %5d %6.3f %14.4f %16.4f %9s\n", i, e.n_views, e.n_tags, e.rms_px,
                1e3 * (e.pose * truth - pivot).norm(), 1e3 * sigma, e.valid ? "yes" : e.reason);
    if (e.valid) {
      measured.push_back(e.pose);
      // Each pose weighs by its reprojection residual (1 / rms^2, floored at 0.01 px): a pose
      // whose corners fit worse (tags seen obliquely) puts the tip worse.
      weights.push_back(1.0 / std::pow(std::max(e.rms_px, 0.01), 2));
    }
  }
  const calib::PivotResult r = calib::SolvePivot(measured, calib::PivotOptions(), o.weighted ? &weights : nullptr);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!r.ok) {
    std::fprintf(stderr, "pivot-calibration: refused: %s\n", r.reason.c_str());
    return 3;
  }
  for (int i = 0; i < r.poses; ++i) std::printf("  residual %2d: %.4f mm\n", i, 1e3 * r.residual_m[i]);
  const double err_mm = 1e3 * (r.tip_in_marker - truth).norm();
  std::printf("TCP in the marker frame (mm):   x          y          z\n");
  std::printf("  calibrated            %10.4f %10.4f %10.4f  (sigma %.4f %.4f %.4f)\n", 1e3 * r.tip_in_marker.x(),
              1e3 * r.tip_in_marker.y(), 1e3 * r.tip_in_marker.z(), 1e3 * r.tip_sigma_m.x(),
              1e3 * r.tip_sigma_m.y(), 1e3 * r.tip_sigma_m.z());
  std::printf("  TRUE (scoring only)   %10.4f %10.4f %10.4f\n", 1e3 * truth.x(), 1e3 * truth.y(), 1e3 * truth.z());
  std::printf("  nominal               %10.4f %10.4f %10.4f\n", 1e3 * nominal.x(), 1e3 * nominal.y(), 1e3 * nominal.z());
  std::printf("calibrated - TRUE: %.4f mm; nominal - TRUE: %.4f mm; pivot residual RMS %.4f mm, max %.4f mm "
              "(pose %d); rotation spread %.1f deg; %d poses; %.1f s (cameras calibrated after %.1f s)\n",
              err_mm, 1e3 * (nominal - truth).norm(), 1e3 * r.rms_m, 1e3 * r.max_residual_m, r.worst_pose,
              r.spread_deg, r.poses, wall, calib_s);
  if (!o.out.empty()) {
    calib::ToolCalibration tc;
    tc.tool = o.tool;
    tc.name = o.tool_name;
    tc.method = "pivot";
    tc.tcp_in_marker = r.tip_in_marker;
    tc.rms_m = r.rms_m;
    tc.poses = r.poses;
    tc.spread_deg = r.spread_deg;
    tc.date = calib::UtcNow();
    if (!calib::WriteToolCalibration(o.out, tc, &error)) {
      std::fprintf(stderr, "pivot-calibration: %s\n", error.c_str());
      return 3;
    }
    std::printf("calibration file: %s\n", o.out.c_str());
  }
  if (o.check_mm >= 0 && !(err_mm <= o.check_mm)) {
    std::fprintf(stderr, "pivot-calibration: FAILED: the calibrated TCP is %.4f mm from the TRUE one (limit %.4f mm)\n",
                 err_mm, o.check_mm);
    return 1;
  }
  return 0;
}
