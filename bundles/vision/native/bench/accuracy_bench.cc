// arflex-accuracy-bench: the vision-corrected accuracy study of issue 7 on the simulated cell.
//
// For a fixed set of target tool poses across the work space: the NOMINAL model's inverse
// kinematics gives the joint reference; the TRUE arm (geometry errors, compliance) moves
// there under its own servo and settles; the cameras are rendered, the tool tags detected
// (ROI around the prediction from the joint state) and the TCP estimated by the multi-view
// least-squares fit; the outer loop adds gain * J_nominal^+ (desired - measured) to the servo
// reference (size and rate limited, held when vision drops out) until it converges. Reported
// per pose: the static absolute TCP error against the simulator's ground truth with the
// correction off and on, the settling time; per run: mean/max, frames and poses per second,
// frame-to-correction latency. Runs: payload 0/100/210 kg, one and two cameras blocked, and
// the nominal (uncalibrated) tool offset. Prints tables, writes JSON.
//
// Usage: arflex-accuracy-bench [--json FILE] [--width W --height H] [--poses N]
//                              [--noise SIGMA] [--blur SIGMA] [--period-ms P] [--quick]
//                              [--no-refine] [--only INDEX] [--trace] [--outlier-px PX]
//                              [--with-orientation] [--calib-frames N] [--calib-at-home]
//                              [--average K] [--diag] [--no-loop] [--cameras LIST]
//                              [--tool-calibration FILE]
// --quick: only the payload-0 run; --no-refine: AprilTag's corners without the edge re-fit;
// --calib-frames: frames pooled per camera for the board calibration (8); --calib-at-home:
// calibrate with the arm in front of the board (default: parked facing away); --average: frames
// averaged per final update once the loop has converged (4; 1 = off); --diag: per camera / tag
// corner errors against the simulator's projections, calibration errors, static check;
// --no-loop: diagnostics only (no correction); --cameras 2,3: the cameras of the --quick run;
// --tool-calibration FILE: one more run (pivot-tool) with the TCP offset of that tool
// calibration file (arflex-pivot-calibration --out FILE) instead of the TRUE model's; with
// --quick: payload-0 (TRUE offset), pivot-tool and nominal-tool.
// --programs DIR [--first N] [--speed F]: writes the joint targets (the nominal IK of the same
// target set, solved as the runs solve it) as trajectory programs DIR/program-<N+i>.arp (one
// ptp each, at speed fraction F, default 0.1) and exits: the cell benchmark (tests/,
// CellAccuracyBench) drives the running cell through them.
#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "arflex_sim/cell.h"
#include "arflex_sim/render.h"
#include "arflex_tcpcorr/correction.h"
#include "arflex_vision/detector.h"
#include "arflex_vision/estimator.h"
#include "arflex_vision/geometry.h"
#include "arflex_vision_calib/tool_calibration.h"

namespace {

using arflex::sim::Cell;
using arflex::sim::CellConfig;
using arflex::sim::JointVector;
using arflex::sim::Renderer;
using arflex::tcpcorr::CorrectionLaw;
using arflex::tcpcorr::CorrectionOptions;
using arflex::tcpcorr::Matrix6d;
using arflex::tcpcorr::Vector6d;
namespace vision = arflex::vision;
using Clock = std::chrono::steady_clock;

double Ms(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

struct Args {
  std::string json = "arflex-accuracy-bench.json";
  int width = 1280;
  int height = 1024;
  int poses = 24;
  double noise = 2.0;
  double blur = 0.0;
  int period_ms = 100;
  bool quick = false;
  bool refine = true;
  double outlier_px = vision::EstimatorOptions{}.outlier_px;
  // Correct the position only (the law's orientation = false): the tool block's orientation
  // from the cameras is too uncertain (tens of mdeg) to correct with; --with-orientation.
  bool position_only = true;
  int only = -1;       // run only this target (debugging)
  std::vector<int> quick_cameras = {0, 1, 2, 3};  // cameras of the --quick run (--cameras)
  bool trace = false;  // print every measurement of the loop
  int calib_frames = 8;  // frames pooled for each camera's board calibration
  bool calib_home = false;  // calibrate with the arm at home (in front of the board)
  int average = 4;       // frames averaged per final update once the loop has converged (1: off)
  bool diag = false;   // print per camera / per tag corner errors (board and tool)
  bool no_loop = false;  // diagnostics only: no correction loop (error "on" not measured)
  std::string tool_calibration;  // a run with the TCP from this calibration file (pivot-tool)
  std::string programs;  // write the targets as trajectory programs into this directory
  int first_program = 11;
  double program_speed = 0.1;
};

Eigen::Vector3d V(const arflex::sim::Vec3& v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

Eigen::Isometry3d TagPose(const arflex::sim::TagSpec& t) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::Quaterniond(t.quat[0], t.quat[1], t.quat[2], t.quat[3]).toRotationMatrix();
  p.translation() = V(t.pos);
  // The tag is printed on the top face of a 1 mm thick box.
  p.translate(Eigen::Vector3d(0, 0, 0.0005));
  return p;
}

// The fixed target set: a grid over the work space in front of the robot, the tool pitched
// down by 35 or 55 degrees towards the work area, some rolled about the tool axis.
std::vector<Eigen::Isometry3d> Targets(int n) {
  std::vector<Eigen::Vector3d> pts;
  for (double z : {0.5, 1.0}) {
    for (double x : {1.5, 1.9, 2.3}) {
      for (double y : {-0.6, 0.0, 0.6}) pts.emplace_back(x, y, z);
    }
  }
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(1.7, 0.3, 0.75), Eigen::Vector3d(1.7, -0.3, 0.75),
                                   Eigen::Vector3d(2.1, 0.3, 0.75), Eigen::Vector3d(2.1, -0.3, 0.75),
                                   Eigen::Vector3d(1.3, 0.0, 0.8), Eigen::Vector3d(2.3, 0.0, 0.75)}) {
    pts.push_back(p);
  }
  std::vector<Eigen::Isometry3d> out;
  for (int i = 0; i < static_cast<int>(pts.size()) && i < n; ++i) {
    const Eigen::Vector3d& p = pts[i];
    const double yaw = std::atan2(p.y(), p.x());
    const double pitch = (i % 2 == 0 ? 35.0 : 55.0) * M_PI / 180.0;
    const double roll = (i % 3 == 0 ? 0.0 : (i % 3 == 1 ? 0.3 : -0.3));
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    t.translation() = p;
    out.push_back(t);
  }
  return out;
}

// Damped least-squares inverse kinematics on the NOMINAL model. Returns false if it does not
// converge to 1e-9 m / 1e-9 rad within the iteration budget or leaves the joint limits.
bool NominalIk(const Cell& cell, const Eigen::Isometry3d& target, JointVector* q) {
  const auto& kin = cell.nominal();
  for (int it = 0; it < 500; ++it) {
    const Vector6d e = arflex::tcpcorr::PoseError(target, kin.Tcp(*q));
    if (e.head<3>().norm() < 1e-9 && e.tail<3>().norm() < 1e-9) {
      for (int i = 0; i < 6; ++i) {
        const auto& l = cell.config().arm.links[i];
        if ((*q)[i] < l.lower || (*q)[i] > l.upper) return false;
      }
      return true;
    }
    const Matrix6d j = kin.TcpJacobian(*q);
    const Vector6d dq = arflex::tcpcorr::DampedSolve(j, e, 1e-3);
    const double s = std::min(1.0, 0.2 / std::max(1e-12, dq.cwiseAbs().maxCoeff()));
    for (int i = 0; i < 6; ++i) (*q)[i] += s * dq(i);
  }
  return false;
}

// The joint targets of Targets(n) on the nominal model, solved in order: seeds are the last
// solution (from `start`), then elbow-up guesses facing the target. False (and a message) if
// one does not converge.
bool JointTargets(const Cell& cell, const std::vector<Eigen::Isometry3d>& targets, JointVector start,
                  std::vector<JointVector>* out) {
  JointVector q_cmd = start;
  out->clear();
  for (int i = 0; i < static_cast<int>(targets.size()); ++i) {
    const Eigen::Isometry3d& target = targets[i];
    const double yaw = std::atan2(target.translation().y(), target.translation().x());
    const JointVector seeds[] = {q_cmd, {yaw, 0.3, 0.3, 0.0, 0.6, 0.0}, {yaw, 0.0, 0.6, 0.0, 1.0, 0.0},
                                 {yaw, 0.5, 0.0, 0.0, 0.8, 0.0}, {yaw, -0.2, 0.9, 0.0, 1.2, 0.0}};
    JointVector seed{};
    bool solved = false;
    for (const JointVector& s : seeds) {
      seed = s;
      if ((solved = NominalIk(cell, target, &seed))) break;
    }
    if (!solved) {
      std::fprintf(stderr, "accuracy-bench: target %d: nominal IK did not converge\n", i);
      return false;
    }
    q_cmd = seed;
    out->push_back(seed);
  }
  return true;
}

// --programs: one trajectory program per target (bundles/trajectory/README.md, program files).
int WritePrograms(const Args& a) {
  std::string error;
  const JointVector home = {0.0, 0.3, 0.3, 0.0, 0.6, 0.0};
  const auto cell = Cell::Create(arflex::sim::DefaultCellConfig(), home, &error);
  if (!cell) {
    std::fprintf(stderr, "accuracy-bench: cell: %s\n", error.c_str());
    return 1;
  }
  std::vector<JointVector> q;
  if (!JointTargets(*cell, Targets(a.poses), home, &q)) return 1;
  for (int i = 0; i < static_cast<int>(q.size()); ++i) {
    const std::string path = a.programs + "/program-" + std::to_string(a.first_program + i) + ".arp";
    FILE* f = std::fopen(path.c_str(), "w");
    if (f == nullptr) {
      std::fprintf(stderr, "accuracy-bench: cannot write %s: %s\n", path.c_str(), std::strerror(errno));
      return 1;
    }
    std::fprintf(f, "arflex-program 1\n# accuracy target %d of %d (arflex-accuracy-bench --programs)\nptp", i,
                 static_cast<int>(q.size()));
    for (int j = 0; j < 6; ++j) std::fprintf(f, " %.12f", q[i][j]);
    std::fprintf(f, " speed %.3f\n", a.program_speed);
    if (std::fclose(f) != 0) {
      std::fprintf(stderr, "accuracy-bench: cannot write %s: %s\n", path.c_str(), std::strerror(errno));
      return 1;
    }
  }
  std::printf("%d programs: %s/program-%d.arp .. program-%d.arp\n", static_cast<int>(q.size()), a.programs.c_str(),
              a.first_program, a.first_program + static_cast<int>(q.size()) - 1);
  return 0;
}

struct Stats {
  std::vector<double> v;
  void Add(double x) { v.push_back(x); }
  double Mean() const {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0 : s / v.size();
  }
  double Max() const { return v.empty() ? 0 : *std::max_element(v.begin(), v.end()); }
};

struct PoseRow {
  int index;
  double off_mm, on_mm, off_rot_mdeg, on_rot_mdeg, vision_err_mm, settle_s;
  int iterations, views, holds;
  bool converged;
};

// Where a run's TCP offset in the marker frame comes from: the simulator's TRUE model (the
// ideal calibration), the pivot calibration file (--tool-calibration, camera data alone), or
// the nominal model (uncalibrated).
enum class ToolOffset { kTrue, kFile, kNominal };

const char* ToolOffsetName(ToolOffset t) {
  return t == ToolOffset::kTrue ? "TRUE" : (t == ToolOffset::kFile ? "pivot-calibrated" : "nominal");
}

struct RunResult {
  std::string name;
  double payload;
  std::vector<int> cameras;
  ToolOffset tool;
  std::vector<PoseRow> rows;
  Stats off, on, settle, vision_err;
  // Diagnostics at the uncorrected pose: the same detections with the TRUE camera poses
  // (detection-limited error), ideal corners with the calibrated cameras
  // (calibration-limited error), and the detected corners' distance to the true projections.
  Stats vision_err_true_cams, vision_err_ideal_corners, corner_err_px, board_corner_err_px;
  Stats detect_roi_ms, detect_full_ms, render_ms, estimate_ms, latency_ms, roi_fraction;
  double calib_trans_mm_max = 0, calib_rot_mdeg_max = 0, calib_rms_px_max = 0;
  long frames = 0, estimates = 0, invalid = 0;
};

class Bench {
 public:
  Bench(const Args& args) : args_(args) {}

  bool Run(const std::string& name, double payload, const std::vector<int>& cams,
           ToolOffset tool, RunResult* out);

 private:
  // Renders the active cameras at the current state, detects (ROI around the prediction if
  // `use_roi`) and estimates the TCP. Accumulates timing into `r`.
  vision::PoseEstimate Measure(bool use_roi, RunResult* r, bool diagnose);

  const Args& args_;
  std::unique_ptr<Cell> cell_;
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<vision::TagDetector> detector_;
  std::vector<vision::Camera> cameras_;
  std::vector<vision::Camera> true_cameras_;  // diagnostics only
  std::vector<int> active_;
  std::vector<vision::TagModel> board_, tool_;
  Eigen::Isometry3d tcp_in_marker_ = Eigen::Isometry3d::Identity();
  std::vector<uint8_t> rgb_;
  vision::EstimatorOptions est_options_;
};

vision::PoseEstimate Bench::Measure(bool use_roi, RunResult* r, bool diagnose) {
  std::array<vision::Observation, vision::kMaxObservations> obs, ideal;
  int nobs = 0, nideal = 0;
  std::array<vision::TagDetection, 16> dets;
  JointVector q = cell_->ReadJointState().q;
  const Eigen::Isometry3d predicted_marker = cell_->nominal().Flange(q);
  renderer_->SetState(cell_->qpos());
  double latency = 0;
  for (int c : active_) {
    arflex::sim::SensorEffects fx;
    fx.noise_sigma = args_.noise;
    fx.blur_sigma = args_.blur;
    fx.seed = 1000003ull * (r->frames + 1) + c;
    auto t0 = Clock::now();
    renderer_->Render(c, rgb_.data(), &fx);
    auto t1 = Clock::now();
    r->render_ms.Add(Ms(t0, t1));
    ++r->frames;
    vision::FrameView frame{rgb_.data(), args_.width, args_.height, 3 * args_.width,
                            vision::PixelFormat::kRgb8};
    vision::Roi roi = vision::PredictRoi(cameras_[c], predicted_marker, tool_, 30.0);
    int n;
    if (use_roi) {
      n = roi.empty() ? 0 : detector_->Detect(frame, &roi, 1, dets.data(), 16, nullptr);
    } else {
      n = detector_->Detect(frame, nullptr, 0, dets.data(), 16, nullptr);
    }
    auto t2 = Clock::now();
    (use_roi ? r->detect_roi_ms : r->detect_full_ms).Add(Ms(t1, t2));
    if (use_roi) r->roi_fraction.Add(static_cast<double>(roi.area()) / (args_.width * args_.height));
    latency += Ms(t1, t2);
    if (n > 0) {
      const int first = nobs;
      vision::CollectObservations(c, dets.data(), n, tool_, obs.data(), &nobs);
      for (int i = first; diagnose && i < nobs; ++i) {
        std::array<Eigen::Vector3d, 4> truth;
        if (!renderer_->TagCorners(tool_[obs[i].tag].id, &truth)) continue;
        vision::Observation& o = ideal[nideal++];
        o = obs[i];
        double e2 = 0, emax = 0;
        for (int k = 0; k < 4; ++k) {
          double u, v;
          renderer_->Project(c, truth[k], &u, &v);
          o.px[k] = Eigen::Vector2d(u, v);
          const double e = (obs[i].px[k] - o.px[k]).norm();
          r->corner_err_px.Add(e);
          e2 += e * e;
          emax = std::max(emax, e);
        }
        if (args_.diag) {
          const Eigen::Vector3d centre = 0.25 * (truth[0] + truth[1] + truth[2] + truth[3]);
          const Eigen::Vector3d normal = (truth[1] - truth[0]).cross(truth[3] - truth[0]).normalized();
          const Eigen::Vector3d eye = renderer_->CameraPose(c).translation();
          const double angle = std::acos(std::abs(normal.dot((eye - centre).normalized()))) * 180 / M_PI;
          double side = 0;
          for (int k = 0; k < 4; ++k) side += 0.25 * (o.px[(k + 1) % 4] - o.px[k]).norm();
          std::printf("    cam %d tag %2d: side %5.1f px, view %4.1f deg, corner error rms %.3f px, max %.3f px, edge scatter %.3f px\n",
                      c, tool_[obs[i].tag].id, side, angle, std::sqrt(e2 / 4), emax, obs[i].edge_scatter_px);
        }
      }
    }
  }
  auto t3 = Clock::now();
  vision::PoseEstimate est =
      vision::EstimateObjectPose(cameras_, tool_, obs.data(), nobs, &predicted_marker, est_options_);
  est = vision::TransformEstimate(est, tcp_in_marker_);
  auto t4 = Clock::now();
  r->estimate_ms.Add(Ms(t3, t4));
  if (use_roi) r->latency_ms.Add(latency + Ms(t3, t4));
  if (diagnose && est.valid) {
    const Eigen::Vector3d truth = cell_->TrueTcp().translation();
    auto err = [&](const std::vector<vision::Camera>& cams, const vision::Observation* o, int n) {
      const vision::PoseEstimate e = vision::TransformEstimate(
          vision::EstimateObjectPose(cams, tool_, o, n, &predicted_marker, est_options_), tcp_in_marker_);
      return e.valid ? 1e3 * (e.pose.translation() - truth).norm() : -1.0;
    };
    r->vision_err_true_cams.Add(err(true_cameras_, obs.data(), nobs));
    r->vision_err_ideal_corners.Add(err(cameras_, ideal.data(), nideal));
    if (args_.diag) {
      const Eigen::Vector3d t = est.pose.translation() - truth;
      std::printf("    estimate: error %.4f mm (x %.4f y %.4f z %.4f), reported sigma %.4f mm, rms %.3f px, "
                  "%d tags %d views; true cameras %.4f mm; ideal corners %.4f mm; ideal corners + true "
                  "cameras %.4f mm\n",
                  1e3 * t.norm(), 1e3 * t.x(), 1e3 * t.y(), 1e3 * t.z(),
                  1e3 * std::sqrt(est.covariance.topLeftCorner<3, 3>().trace()), est.rms_px, est.n_tags,
                  est.n_views, err(true_cameras_, obs.data(), nobs), err(cameras_, ideal.data(), nideal),
                  err(true_cameras_, ideal.data(), nideal));
    }
  }
  ++r->estimates;
  if (!est.valid) ++r->invalid;
  return est;
}

bool Bench::Run(const std::string& name, double payload, const std::vector<int>& cams,
                ToolOffset tool, RunResult* r) {
  r->name = name;
  r->payload = payload;
  r->cameras = cams;
  r->tool = tool;
  CellConfig config = arflex::sim::DefaultCellConfig();
  config.payload_mass = payload;
  config.nominal_payload_mass = payload;  // the controller is told the payload
  config.max_render_width = std::max(args_.width, 640);
  config.max_render_height = std::max(args_.height, 480);
  std::string error;
  const JointVector home = {0.0, 0.3, 0.3, 0.0, 0.6, 0.0};
  // The cell starts (and the cameras calibrate) with the arm parked facing away from the
  // reference board, so that it hides no board tag from any camera: with the arm at `home`
  // cameras 0 and 1 see only three of the four tags and calibrate several times worse.
  const JointVector park = {M_PI, 0.3, 0.3, 0.0, 0.6, 0.0};
  cell_ = Cell::Create(config, args_.calib_home ? home : park, &error);
  if (!cell_) {
    std::fprintf(stderr, "accuracy-bench: cell: %s\n", error.c_str());
    return false;
  }
  renderer_ = Renderer::Create(cell_->model(), args_.width, args_.height, &error);
  if (!renderer_) {
    std::fprintf(stderr, "accuracy-bench: renderer: %s\n", error.c_str());
    return false;
  }
  vision::DetectorOptions dopt;
  dopt.max_width = args_.width;
  dopt.max_height = args_.height;
  dopt.refine_corners = args_.refine;
  est_options_.outlier_px = args_.outlier_px;
  detector_ = vision::TagDetector::Create(dopt, &error);
  if (!detector_) {
    std::fprintf(stderr, "accuracy-bench: %s\n", error.c_str());
    return false;
  }
  rgb_.assign(static_cast<size_t>(args_.width) * args_.height * 3, 0);
  active_ = cams;
  board_.clear();
  tool_.clear();
  for (const auto& t : config.tags) {
    vision::TagModel m{t.id, t.size, TagPose(t)};
    (t.body == "world" ? board_ : tool_).push_back(m);
  }
  // TCP in the marker (flange) frame: nominal, the TRUE model's (an ideal tool calibration),
  // or the one the pivot calibration measured from the cameras (arflex-pivot-calibration).
  Eigen::Vector3d tcp = V(config.arm.tcp_offset);
  if (tool == ToolOffset::kTrue) tcp += V(cell_->errors().offset_error[arflex::sim::kNumJoints]);
  if (tool == ToolOffset::kFile) {
    arflex::vision::calib::ToolCalibration cal;
    if (!arflex::vision::calib::ReadToolCalibration(args_.tool_calibration, &cal, nullptr, &error)) {
      std::fprintf(stderr, "accuracy-bench: %s\n", error.c_str());
      return false;
    }
    tcp = cal.tcp_in_marker;
    std::printf("%s: TCP from %s (%s, %d poses, residual RMS %.4f mm, %s): %.4f mm from the TRUE one\n",
                name.c_str(), args_.tool_calibration.c_str(), cal.method.c_str(), cal.poses, 1e3 * cal.rms_m,
                cal.date.c_str(),
                1e3 * (tcp - V(config.arm.tcp_offset) - V(cell_->errors().offset_error[arflex::sim::kNumJoints])).norm());
  }
  tcp_in_marker_ = Eigen::Isometry3d::Identity();
  tcp_in_marker_.translation() = tcp;

  // Extrinsic calibration of every camera from the reference board (full frame), at start.
  cameras_.assign(renderer_->camera_count(), vision::Camera{});
  renderer_->SetState(cell_->qpos());
  for (int c = 0; c < renderer_->camera_count(); ++c) {
    const auto k = renderer_->Intrinsics(c);
    cameras_[c].k = vision::Intrinsics{k.width, k.height, k.fx, k.fy, k.cx, k.cy};
    if (std::find(cams.begin(), cams.end(), c) == cams.end()) continue;  // blocked
    // The cell is static while it calibrates: pool the board detections of several frames
    // (independent sensor noise) into one fit.
    std::vector<vision::TagDetection> dets(16 * static_cast<size_t>(args_.calib_frames));
    int n = 0;
    for (int f = 0; f < args_.calib_frames; ++f) {
      arflex::sim::SensorEffects fx;
      fx.noise_sigma = args_.noise;
      fx.blur_sigma = args_.blur;
      fx.seed = 77 + c + 1009ull * f;
      renderer_->Render(c, rgb_.data(), &fx);
      vision::FrameView frame{rgb_.data(), args_.width, args_.height, 3 * args_.width,
                              vision::PixelFormat::kRgb8};
      // Keep only board tags: the pooled list must fit the estimator's observation limit.
      std::array<vision::TagDetection, 16> one;
      const int m = detector_->Detect(frame, nullptr, 0, one.data(), 16, nullptr);
      for (int i = 0; i < m; ++i) {
        for (const vision::TagModel& b : board_) {
          if (b.id == one[i].id && n < vision::kMaxObservations) dets[n++] = one[i];
        }
      }
    }
    vision::PoseEstimate est;
    if (!vision::CalibrateCamera(&cameras_[c], board_, dets.data(), std::max(n, 0), est_options_,
                                 &est, &error)) {
      std::fprintf(stderr, "accuracy-bench: camera %d: %s\n", c, error.c_str());
      return false;
    }
    const Eigen::Isometry3d truth = renderer_->CameraPose(c);
    const Eigen::Isometry3d d = truth.inverse() * cameras_[c].world_from_camera;
    for (int i = 0; i < n; ++i) {
      std::array<Eigen::Vector3d, 4> corners;
      if (!renderer_->TagCorners(dets[i].id, &corners)) continue;
      double e2 = 0, emax = 0;
      for (int k = 0; k < 4; ++k) {
        double u, v;
        renderer_->Project(c, corners[k], &u, &v);
        const double e = std::hypot(dets[i].corners[k][0] - u, dets[i].corners[k][1] - v);
        r->board_corner_err_px.Add(e);
        e2 += e * e;
        emax = std::max(emax, e);
      }
      if (args_.diag && i < static_cast<int>(board_.size())) {
        std::printf("  calib cam %d board tag %d: corner error rms %.3f px, max %.3f px (first frame)\n", c,
                    dets[i].id, std::sqrt(e2 / 4), emax);
      }
    }
    if (args_.diag) {
      std::printf("  calib cam %d: %d board tag sightings in %d frames, rms %.3f px, translation error %.3f mm, "
                  "rotation error %.2f mdeg\n",
                  c, n, args_.calib_frames, cameras_[c].calibration_rms_px,
                  1e3 * (truth.translation() - cameras_[c].world_from_camera.translation()).norm(),
                  1e3 * Eigen::AngleAxisd(d.linear()).angle() * 180 / M_PI);
    }
    r->calib_trans_mm_max = std::max(r->calib_trans_mm_max,
                                     1e3 * (truth.translation() - cameras_[c].world_from_camera.translation()).norm());
    r->calib_rot_mdeg_max = std::max(r->calib_rot_mdeg_max,
                                     1e3 * Eigen::AngleAxisd(d.linear()).angle() * 180 / M_PI);
    r->calib_rms_px_max = std::max(r->calib_rms_px_max, cameras_[c].calibration_rms_px);
  }
  true_cameras_ = cameras_;
  for (int c = 0; c < renderer_->camera_count(); ++c) {
    true_cameras_[c].world_from_camera = renderer_->CameraPose(c);
    true_cameras_[c].calibrated = cameras_[c].calibrated;
  }

  // The law's defaults, but a faster ramp (0.05 rad/s): at the component default of
  // 0.01 rad/s the wrist corrections take most of a second.
  CorrectionOptions copt;
  copt.max_rate = 0.05;
  copt.orientation = !args_.position_only;
  const double dt = cell_->timestep();
  const int period_steps = std::max(1, static_cast<int>(std::lround(args_.period_ms * 1e-3 / dt)));
  const std::vector<Eigen::Isometry3d> targets = Targets(args_.poses);
  std::vector<JointVector> joint_targets;
  if (!JointTargets(*cell_, targets, home, &joint_targets)) return false;
  JointVector q_cmd = home;
  JointVector start = args_.calib_home ? home : park;
  for (int i = 0; i < static_cast<int>(targets.size()); ++i) {
    if (args_.only >= 0 && i != args_.only) continue;
    const Eigen::Isometry3d& target = targets[i];
    q_cmd = joint_targets[i];
    // Move: a smooth joint-space ramp from where the reference was (incl. the last
    // correction) to the new reference, correction off.
    const int ramp = 1500;
    cell_->SetCorrection(JointVector{});
    for (int k = 1; k <= ramp; ++k) {
      const double s = static_cast<double>(k) / ramp;
      const double w = s * s * (3 - 2 * s);
      JointVector ref;
      for (int j = 0; j < 6; ++j) ref[j] = start[j] + w * (q_cmd[j] - start[j]);
      cell_->SetJointReference(ref);
      cell_->Step(1);
    }
    auto settle = [this, i]() {
      int k = 0;
      double v = 0;
      for (; k < 20000; k += 10) {
        cell_->Step(10);
        const auto js = cell_->ReadJointState();
        v = 0;
        for (double x : js.dq) v = std::max(v, std::abs(x));
        if (k >= 300 && v < 1e-6) break;
      }
      if (args_.diag) std::printf("  pose %d: settle %d steps, max |dq| %.2e\n", i, k, v);
    };
    settle();
    if (args_.diag) {
      // Is the arm static? TCP motion over one and over ten servo steps after settling.
      const Eigen::Vector3d a = cell_->TrueTcp().translation();
      cell_->Step(1);
      const Eigen::Vector3d b = cell_->TrueTcp().translation();
      cell_->Step(10);
      const Eigen::Vector3d c = cell_->TrueTcp().translation();
      double v = 0;
      for (double x : cell_->ReadJointState().dq) v = std::max(v, std::abs(x));
      std::printf("  pose %d settled: TCP moved %.4f mm in 1 step, %.4f mm in 10 steps; max |dq| %.2e rad/s\n",
                  i, 1e3 * (b - a).norm(), 1e3 * (c - b).norm(), v);
      const auto js = cell_->ReadJointState();
      std::printf("    q_cmd");
      for (int j = 0; j < 6; ++j) std::printf(" %+.4f", q_cmd[j]);
      std::printf("\n    q    ");
      for (int j = 0; j < 6; ++j) std::printf(" %+.4f", js.q[j]);
      std::printf("\n    dq   ");
      for (int j = 0; j < 6; ++j) std::printf(" %+.4f", js.dq[j]);
      std::printf("\n    tau  ");
      for (int j = 0; j < 6; ++j) std::printf(" %+.1f", js.tau[j]);
      std::printf("\n    limits");
      for (int j = 0; j < 6; ++j) std::printf(" [%+.2f %+.2f]", cell_->config().arm.links[j].lower, cell_->config().arm.links[j].upper);
      std::printf("\n");
    }
    const Eigen::Isometry3d true_off = cell_->TrueTcp();
    PoseRow row{};
    row.index = i;
    row.off_mm = 1e3 * (true_off.translation() - target.translation()).norm();
    row.off_rot_mdeg = 1e3 * arflex::tcpcorr::PoseError(target, true_off).tail<3>().norm() * 180 / M_PI;
    // Cold start measurement: full-frame detection (also the vision error at this pose).
    const vision::PoseEstimate cold = Measure(false, r, true);
    row.vision_err_mm = cold.valid ? 1e3 * (cold.pose.translation() - true_off.translation()).norm() : -1;
    if (cold.valid) r->vision_err.Add(row.vision_err_mm);

    // Correction on: the outer loop at the vision period, the applied correction ticked at
    // the servo rate.
    CorrectionLaw law(copt);
    const Matrix6d jac = cell_->nominal().TcpJacobian(q_cmd);
    const double e0 = row.off_mm;
    std::vector<double> trace;  // true error (mm) at every servo step
    int quiet = 0;
    const int max_iterations = 30;
    int it = 0;
    if (args_.diag) {
      std::printf("  pose %d: cold estimate %s, vision error %.4f mm\n", i, cold.reason, row.vision_err_mm);
    }
    for (; it < (args_.no_loop ? 0 : max_iterations); ++it) {
      const vision::PoseEstimate est = Measure(true, r, false);
      if (args_.trace) {
        const Eigen::Vector3d t = cell_->TrueTcp().translation();
        std::printf("  it %2d valid %d views %d tags %d rej %d obl %d rms %.3f px | vision err %.4f mm | true err %.4f mm\n",
                    it, est.valid, est.n_views, est.n_tags, est.n_rejected, est.n_oblique, est.rms_px,
                    1e3 * (est.pose.translation() - t).norm(), 1e3 * (t - target.translation()).norm());
      }
      if (est.valid) row.views = std::max(row.views, est.n_views);
      const Vector6d before = law.target();
      law.Update(jac, target, est.pose, est.valid);
      const double moved = (law.target() - before).cwiseAbs().maxCoeff();
      for (int k = 0; k < period_steps; ++k) {
        const Vector6d& a = law.Tick(dt);
        JointVector corr;
        for (int j = 0; j < 6; ++j) corr[j] = a(j);
        cell_->SetCorrection(corr);
        cell_->Step(1);
        trace.push_back(1e3 * (cell_->TrueTcp().translation() - target.translation()).norm());
      }
      // Converged: two valid measurements in a row within 20 um of the target (as the loop
      // sees it; the vision noise keeps moving the correction by a few urad).
      (void)moved;
      quiet = (est.valid && (est.pose.translation() - target.translation()).norm() < 20e-6) ? quiet + 1 : 0;
      if (quiet >= 2) {
        row.converged = true;
        ++it;
        break;
      }
    }
    // Static refinement: once converged, what the loop still sees is mostly frame noise
    // (a few hundredths of a mm). Average `average` frames of the static arm and make one
    // update from the mean; twice (each update corrects the law's gain of the mean error).
    for (int round = 0; row.converged && args_.average > 1 && round < 2; ++round) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      vision::PoseEstimate last;
      int used = 0;
      for (int f = 0; f < args_.average; ++f) {
        const vision::PoseEstimate est = Measure(true, r, false);
        ++it;
        if (est.valid) {
          sum += est.pose.translation();
          last = est;
          ++used;
        }
        for (int k = 0; k < period_steps; ++k) {
          const Vector6d& a = law.Tick(dt);
          JointVector corr;
          for (int j = 0; j < 6; ++j) corr[j] = a(j);
          cell_->SetCorrection(corr);
          cell_->Step(1);
          trace.push_back(1e3 * (cell_->TrueTcp().translation() - target.translation()).norm());
        }
      }
      if (used == 0) break;
      last.pose.translation() = sum / used;
      if (args_.trace) {
        std::printf("  mean of %d frames: vision err %.4f mm | true err %.4f mm\n", used,
                    1e3 * (last.pose.translation() - cell_->TrueTcp().translation()).norm(),
                    1e3 * (cell_->TrueTcp().translation() - target.translation()).norm());
      }
      law.Update(jac, target, last.pose, true);
      for (int k = 0; k < period_steps; ++k) {
        const Vector6d& a = law.Tick(dt);
        JointVector corr;
        for (int j = 0; j < 6; ++j) corr[j] = a(j);
        cell_->SetCorrection(corr);
        cell_->Step(1);
        trace.push_back(1e3 * (cell_->TrueTcp().translation() - target.translation()).norm());
      }
    }
    row.iterations = it;
    row.holds = static_cast<int>(law.holds());
    settle();
    const Eigen::Isometry3d true_on = cell_->TrueTcp();
    row.on_mm = 1e3 * (true_on.translation() - target.translation()).norm();
    row.on_rot_mdeg = 1e3 * arflex::tcpcorr::PoseError(target, true_on).tail<3>().norm() * 180 / M_PI;
    // Settling time: after this time the true error stays within 10 % of the way from the
    // uncorrected to the final error.
    const double band = row.on_mm + 0.1 * std::max(0.0, e0 - row.on_mm);
    int last_out = -1;
    for (int k = 0; k < static_cast<int>(trace.size()); ++k) {
      if (trace[k] > band) last_out = k;
    }
    row.settle_s = (last_out + 1) * dt;
    r->off.Add(row.off_mm);
    r->on.Add(row.on_mm);
    r->settle.Add(row.settle_s);
    r->rows.push_back(row);
    for (int j = 0; j < 6; ++j) start[j] = q_cmd[j] + law.applied()(j);
  }
  renderer_.reset();
  detector_.reset();
  cell_.reset();
  return true;
}

void PrintRun(const RunResult& r, bool per_pose) {
  std::printf("\n== %s: payload %.0f kg, cameras", r.name.c_str(), r.payload);
  for (int c : r.cameras) std::printf(" %d", c);
  std::printf(", tool offset %s ==\n", ToolOffsetName(r.tool));
  std::printf("camera calibration (board): max translation error %.2f mm, max rotation error "
              "%.1f mdeg, max rms %.3f px\n",
              r.calib_trans_mm_max, r.calib_rot_mdeg_max, r.calib_rms_px_max);
  if (per_pose) {
    std::printf("%4s %10s %10s %12s %12s %10s %9s %5s %5s %5s\n", "pose", "off (mm)", "on (mm)",
                "off (mdeg)", "on (mdeg)", "vis (mm)", "settle(s)", "iter", "views", "conv");
    for (const PoseRow& p : r.rows) {
      std::printf("%4d %10.4f %10.4f %12.1f %12.1f %10.4f %9.2f %5d %5d %5s\n", p.index, p.off_mm,
                  p.on_mm, p.off_rot_mdeg, p.on_rot_mdeg, p.vision_err_mm, p.settle_s,
                  p.iterations, p.views, p.converged ? "yes" : "no");
    }
  }
  const double ratio = r.on.Mean() > 0 ? r.off.Mean() / r.on.Mean() : 0;
  std::printf("error off: mean %.4f mm, max %.4f mm | on: mean %.4f mm, max %.4f mm | "
              "reduction %.1fx | settle mean %.2f s, max %.2f s\n",
              r.off.Mean(), r.off.Max(), r.on.Mean(), r.on.Max(), ratio, r.settle.Mean(),
              r.settle.Max());
  const double n_cam = r.cameras.empty() ? 1 : r.cameras.size();
  std::printf("vision error (uncorrected pose, full frame): mean %.4f mm, max %.4f mm; "
              "estimates %ld, invalid %ld\n",
              r.vision_err.Mean(), r.vision_err.Max(), r.estimates, r.invalid);
  std::printf("diagnosis at the uncorrected poses: vision error with the TRUE camera poses %.4f mm "
              "(max %.4f); with ideal corners and the calibrated cameras %.4f mm (max %.4f); "
              "detected corner to true projection %.3f px mean, %.3f px max (board at calibration: "
              "%.3f px mean, %.3f px max)\n",
              r.vision_err_true_cams.Mean(), r.vision_err_true_cams.Max(),
              r.vision_err_ideal_corners.Mean(), r.vision_err_ideal_corners.Max(),
              r.corner_err_px.Mean(), r.corner_err_px.Max(), r.board_corner_err_px.Mean(),
              r.board_corner_err_px.Max());
  std::printf("per camera: render %.1f ms (%.1f fps), detect full frame %.1f ms (%.1f fps), "
              "detect ROI %.1f ms (%.1f fps, ROI %.1f %% of the frame)\n",
              r.render_ms.Mean(), 1e3 / r.render_ms.Mean(), r.detect_full_ms.Mean(),
              1e3 / r.detect_full_ms.Mean(), r.detect_roi_ms.Mean(), 1e3 / r.detect_roi_ms.Mean(),
              100 * r.roi_fraction.Mean());
  std::printf("estimate %.2f ms; frame-to-correction latency (detect %zu views in sequence + "
              "estimate + law) mean %.1f ms, max %.1f ms; poses/s (vision only) %.1f\n",
              r.estimate_ms.Mean(), static_cast<size_t>(n_cam), r.latency_ms.Mean(),
              r.latency_ms.Max(), 1e3 / r.latency_ms.Mean());
}

void WriteJson(FILE* f, const Args& a, const std::vector<RunResult>& runs) {
  std::fprintf(f, "{\n  \"benchmark\": \"arflex-accuracy-bench\",\n");
  std::fprintf(f, "  \"config\": {\"width\": %d, \"height\": %d, \"poses\": %d, \"noise_sigma\": %g, "
                  "\"blur_sigma\": %g, \"vision_period_ms\": %d, \"corner_refit\": %s, \"outlier_px\": %g, \"position_only\": %s, "
                  "\"calibration_frames\": %d, \"calibration_pose\": \"%s\", \"static_average_frames\": %d},\n",
               a.width, a.height, a.poses, a.noise, a.blur, a.period_ms, a.refine ? "true" : "false",
               a.outlier_px, a.position_only ? "true" : "false", a.calib_frames, a.calib_home ? "home" : "parked",
               a.average);
  std::fprintf(f, "  \"runs\": [\n");
  for (size_t i = 0; i < runs.size(); ++i) {
    const RunResult& r = runs[i];
    std::fprintf(f, "    {\"name\": \"%s\", \"payload_kg\": %g, \"tool_offset\": \"%s\", \"cameras\": [",
                 r.name.c_str(), r.payload, ToolOffsetName(r.tool));
    for (size_t c = 0; c < r.cameras.size(); ++c) std::fprintf(f, "%s%d", c ? ", " : "", r.cameras[c]);
    std::fprintf(f, "],\n     \"error_off_mm\": {\"mean\": %.6f, \"max\": %.6f}, \"error_on_mm\": "
                    "{\"mean\": %.6f, \"max\": %.6f}, \"reduction\": %.3f,\n",
                 r.off.Mean(), r.off.Max(), r.on.Mean(), r.on.Max(),
                 r.on.Mean() > 0 ? r.off.Mean() / r.on.Mean() : 0.0);
    std::fprintf(f, "     \"settle_s\": {\"mean\": %.4f, \"max\": %.4f}, \"vision_error_mm\": {\"mean\": "
                    "%.6f, \"max\": %.6f},\n",
                 r.settle.Mean(), r.settle.Max(), r.vision_err.Mean(), r.vision_err.Max());
    std::fprintf(f, "     \"diagnosis\": {\"vision_error_true_cameras_mm\": %.6f, "
                    "\"vision_error_ideal_corners_mm\": %.6f, \"corner_error_px\": {\"mean\": %.4f, "
                    "\"max\": %.4f}},\n",
                 r.vision_err_true_cams.Mean(), r.vision_err_ideal_corners.Mean(),
                 r.corner_err_px.Mean(), r.corner_err_px.Max());
    std::fprintf(f, "     \"calibration\": {\"max_translation_mm\": %.4f, \"max_rotation_mdeg\": %.3f, "
                    "\"max_rms_px\": %.4f},\n",
                 r.calib_trans_mm_max, r.calib_rot_mdeg_max, r.calib_rms_px_max);
    std::fprintf(f, "     \"per_camera_ms\": {\"render\": %.3f, \"detect_full\": %.3f, \"detect_roi\": %.3f, "
                    "\"roi_fraction\": %.4f}, \"estimate_ms\": %.4f, \"latency_ms\": {\"mean\": %.3f, "
                    "\"max\": %.3f}, \"frames\": %ld, \"estimates\": %ld, \"invalid\": %ld,\n",
                 r.render_ms.Mean(), r.detect_full_ms.Mean(), r.detect_roi_ms.Mean(),
                 r.roi_fraction.Mean(), r.estimate_ms.Mean(), r.latency_ms.Mean(), r.latency_ms.Max(),
                 r.frames, r.estimates, r.invalid);
    std::fprintf(f, "     \"poses\": [\n");
    for (size_t p = 0; p < r.rows.size(); ++p) {
      const PoseRow& w = r.rows[p];
      std::fprintf(f, "       {\"pose\": %d, \"off_mm\": %.6f, \"on_mm\": %.6f, \"off_rot_mdeg\": %.3f, "
                      "\"on_rot_mdeg\": %.3f, \"vision_error_mm\": %.6f, \"settle_s\": %.3f, "
                      "\"iterations\": %d, \"views\": %d, \"converged\": %s}%s\n",
                   w.index, w.off_mm, w.on_mm, w.off_rot_mdeg, w.on_rot_mdeg, w.vision_err_mm,
                   w.settle_s, w.iterations, w.views, w.converged ? "true" : "false",
                   p + 1 < r.rows.size() ? "," : "");
    }
    std::fprintf(f, "     ]}%s\n", i + 1 < runs.size() ? "," : "");
  }
  std::fprintf(f, "  ]\n}\n");
}

bool ParseArgs(int argc, char** argv, Args* a) {
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto value = [&](const char* name) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "accuracy-bench: %s needs a value\n", name);
        return nullptr;
      }
      return argv[++i];
    };
    const char* v = nullptr;
    if (k == "--quick") {
      a->quick = true;
      continue;
    }
    if (k == "--no-refine") {
      a->refine = false;
      continue;
    }
    if (k == "--with-orientation") {
      a->position_only = false;
      continue;
    }
    if (k == "--trace") {
      a->trace = true;
      continue;
    }
    if (k == "--diag") {
      a->diag = true;
      continue;
    }
    if (k == "--calib-at-home") {
      a->calib_home = true;
      continue;
    }
    if (k == "--no-loop") {
      a->no_loop = true;
      continue;
    }
    if (k == "--programs" || k == "--first" || k == "--speed") {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "accuracy-bench: %s needs a value\n", k.c_str());
        return false;
      }
      const std::string v = argv[++i];
      if (k == "--programs") {
        a->programs = v;
        continue;
      }
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0' || !std::isfinite(x)) {
        std::fprintf(stderr, "accuracy-bench: %s: '%s' is not a number\n", k.c_str(), v.c_str());
        return false;
      }
      if (k == "--first") {
        if (x < 1 || x > 76 || x != std::floor(x)) {
          std::fprintf(stderr, "accuracy-bench: --first must be a whole number in 1..76 (programs 1..99)\n");
          return false;
        }
        a->first_program = static_cast<int>(x);
      } else {
        if (!(x > 0 && x <= 1)) {
          std::fprintf(stderr, "accuracy-bench: --speed must be in (0, 1]\n");
          return false;
        }
        a->program_speed = x;
      }
      continue;
    }
    if (k == "--json" || k == "--width" || k == "--height" || k == "--poses" || k == "--noise" ||
        k == "--blur" || k == "--period-ms" || k == "--only" || k == "--outlier-px" ||
        k == "--calib-frames" || k == "--average" || k == "--cameras" || k == "--tool-calibration") {
      if (!(v = value(k.c_str()))) return false;
    } else {
      std::fprintf(stderr, "accuracy-bench: unknown argument '%s'\n", k.c_str());
      return false;
    }
    char* end = nullptr;
    if (k == "--json") {
      a->json = v;
      continue;
    }
    if (k == "--tool-calibration") {
      a->tool_calibration = v;
      continue;
    }
    if (k == "--cameras") {
      a->quick_cameras.clear();
      for (const char* c = v; *c; ++c) {
        if (*c == ',') continue;
        if (*c < '0' || *c > '3') {
          std::fprintf(stderr, "accuracy-bench: --cameras: '%s' is not a list of cameras 0-3 (e.g. 2,3)\n", v);
          return false;
        }
        a->quick_cameras.push_back(*c - '0');
      }
      if (a->quick_cameras.empty()) {
        std::fprintf(stderr, "accuracy-bench: --cameras needs at least one camera\n");
        return false;
      }
      continue;
    }
    const double x = std::strtod(v, &end);
    if (end == v || *end != '\0' || !std::isfinite(x) || x < 0) {
      std::fprintf(stderr, "accuracy-bench: %s: '%s' is not a non-negative number\n", k.c_str(), v);
      return false;
    }
    if (k == "--width") a->width = static_cast<int>(x);
    if (k == "--height") a->height = static_cast<int>(x);
    if (k == "--poses") a->poses = static_cast<int>(x);
    if (k == "--noise") a->noise = x;
    if (k == "--blur") a->blur = x;
    if (k == "--period-ms") a->period_ms = static_cast<int>(x);
    if (k == "--only") a->only = static_cast<int>(x);
    if (k == "--outlier-px") a->outlier_px = x;
    if (k == "--calib-frames") a->calib_frames = static_cast<int>(x);
    if (k == "--average") a->average = static_cast<int>(x);
  }
  if (a->width < 64 || a->width > 1280 || a->height < 64 || a->height > 1024) {
    std::fprintf(stderr, "accuracy-bench: --width/--height must be within 64x64..1280x1024\n");
    return false;
  }
  if (a->poses < 1 || a->poses > 24) {
    std::fprintf(stderr, "accuracy-bench: --poses must be in 1..24\n");
    return false;
  }
  if (a->calib_frames < 1 || a->calib_frames > 16) {
    std::fprintf(stderr, "accuracy-bench: --calib-frames must be in 1..16\n");
    return false;
  }
  if (a->average < 1 || a->average > 50) {
    std::fprintf(stderr, "accuracy-bench: --average must be in 1..50\n");
    return false;
  }
  if (a->period_ms < 1) {
    std::fprintf(stderr, "accuracy-bench: --period-ms must be >= 1\n");
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (!ParseArgs(argc, argv, &args)) return 2;
  if (!args.programs.empty()) return WritePrograms(args);
  struct Spec {
    const char* name;
    double payload;
    std::vector<int> cams;
    ToolOffset tool;
    bool per_pose;
  };
  std::vector<Spec> specs = {
      {"payload-0", 0, {0, 1, 2, 3}, ToolOffset::kTrue, true},
      {"payload-100", 100, {0, 1, 2, 3}, ToolOffset::kTrue, false},
      {"payload-210", 210, {0, 1, 2, 3}, ToolOffset::kTrue, false},
      {"blocked-1", 0, {1, 2, 3}, ToolOffset::kTrue, false},
      {"blocked-2", 0, {2, 3}, ToolOffset::kTrue, false},
      {"nominal-tool", 0, {0, 1, 2, 3}, ToolOffset::kNominal, false},
  };
  if (args.quick) {
    specs.resize(1);
    specs[0].cams = args.quick_cameras;
  }
  if (!args.tool_calibration.empty()) {
    // --tool-calibration: the pivot-calibrated TCP next to the TRUE (payload-0) and the
    // nominal one; with --quick these three runs only.
    specs.push_back({"pivot-tool", 0, {0, 1, 2, 3}, ToolOffset::kFile, false});
    if (args.quick) specs.push_back({"nominal-tool", 0, {0, 1, 2, 3}, ToolOffset::kNominal, false});
  }
  std::printf("arflex-accuracy-bench: %d poses, %dx%d, noise %.1f DN, blur %.1f px, vision "
              "period %d ms (simulated time), corner re-fit %s, outlier threshold %.2f px, "
              "correcting %s; calibration: %d frames per camera, arm %s; static average %d frames\n",
              args.poses, args.width, args.height, args.noise, args.blur, args.period_ms,
              args.refine ? "on" : "off", args.outlier_px,
              args.position_only ? "the position" : "position and orientation", args.calib_frames,
              args.calib_home ? "at home" : "parked away from the board", args.average);
  std::vector<RunResult> runs;
  Bench bench(args);
  for (const Spec& s : specs) {
    RunResult r;
    if (!bench.Run(s.name, s.payload, s.cams, s.tool, &r)) return 1;
    PrintRun(r, s.per_pose);
    std::fflush(stdout);
    runs.push_back(std::move(r));
  }
  FILE* f = std::fopen(args.json.c_str(), "w");
  if (f == nullptr) {
    std::fprintf(stderr, "accuracy-bench: cannot write %s\n", args.json.c_str());
    return 1;
  }
  WriteJson(f, args, runs);
  std::fclose(f);
  std::printf("\nJSON: %s\n", args.json.c_str());
  return 0;
}
