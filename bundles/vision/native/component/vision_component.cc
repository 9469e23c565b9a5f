// RT half of the `vision` component: tool pose from up to four cameras.
//
// Ports: inputs cam0..cam3 (frame, arflex.ImageFrame: GRAY8 or RGB8), joint_state (state,
// arflex.JointState, for the ROI prediction); output tcp_pose (state, arflex.Pose).
// Parameters (all optional in the contract; defaults below when absent): fovy_deg (pinhole
// intrinsics of the cell cameras: fy = fx = (H/2)/tan(fovy/2), principal point at the image
// centre), tcp_x/tcp_y/tcp_z (TCP in the flange/marker frame, m), roi_margin_px, calibrate
// (int64: each change re-runs the extrinsic calibration of every camera from the board),
// tool_id and require_tool_calibration (read at configure): the tool's calibrated TCP from
// $ARFLEX_DATA_DIR/tool-<id>.cal (vision/native/calib, tool_calibration.h) replaces
// tcp_x/y/z; configure says on stderr which TCP it uses (calibrated: method, poses, residual,
// date; or nominal) and refuses (-EINVAL, the reason on stderr) a file that is unreadable,
// malformed or another tool's, and an uncalibrated tool when a calibration is required.
//
// Threads: detection allocates (libapriltag), so it runs on a worker thread created in
// configure. update() (RT thread) never allocates, blocks or prints: when the worker is idle
// it publishes the worker's last result, copies the newest frame of every camera into
// buffers preallocated in configure (frames larger than those buffers are counted and
// skipped), reads the joint state and hands the job over with sem_post. The worker detects
// (full frame for the board calibration, an ROI around the tags predicted from the nominal
// forward kinematics of the joint state, or around the last pose, otherwise the full frame),
// estimates the multi-view pose and leaves the result for the next update.
//
// State block (contract <state type="arflex.VisionState">, docs/DECISIONS.md D58): the cameras'
// extrinsic calibration, the last valid marker pose, the seq of the pose written last and the
// calibrate value served last. The worker leaves a snapshot of its part with each result; the
// RT thread publishes the block every cycle the worker is idle (the snapshot is the worker's
// last, the seqs are the RT thread's). A new version adopts it at its START in a change set
// (the adopt hook, on the RT thread before the first update, while the worker has no job): it
// measures in the old half's camera frames from its first frame set, without calibrating again,
// and its poses continue the old half's seq. A block it cannot take is refused, which refuses
// the START with the reason's errno (rt-core logs it): another type or major version
// -EPROTOTYPE, a block shorter than the type -EMSGSIZE, a value outside the type's bounds or a
// quaternion that is not a unit one -EINVAL.
//
// Validated data (docs/safety.md): a joint state that fails arflex_joint_state_valid (a
// non-finite q, qd or tau) is not used for the ROI prediction (the worker searches around the
// last pose, or the full frame) and is counted (update returns -EINVAL: stats.update_errors)
// until a valid one comes. Frame headers are checked as before (format, size, stride) plus
// the type's generated arflex_image_frame_valid; a malformed frame is skipped.
#include <semaphore.h>

#include <array>
#include <atomic>
#include <sys/resource.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

extern "C" {
#include "arflex/component.h"
}
#include "arflex_cellmodel/kinematics.h"
#include "arflex_types/image_frame.h"
#include "arflex_types/joint_state.h"
#include "arflex_types/pose.h"
#include "arflex_types/vision_state.h"
#include "arflex_vision/cell_layout.h"
#include "arflex_vision/detector.h"
#include "arflex_vision/estimator.h"
#include "arflex_vision_calib/tool_calibration.h"

namespace {

namespace vision = arflex::vision;

constexpr int kCameras = 4;
constexpr int kMaxWidth = 1280;
constexpr int kMaxHeight = 1024;
constexpr size_t kMaxPixels = static_cast<size_t>(kMaxWidth) * kMaxHeight * 3;

struct FrameSlot {
  std::unique_ptr<uint8_t[]> pixels;  // kMaxPixels, allocated in configure
  arflex_image_frame header{};
  bool present = false;
};

struct Vision {
  arflex_input* cam[kCameras] = {};
  arflex_input* joints = nullptr;
  arflex_port* out = nullptr;
  int p_fovy = -1, p_tcp[3] = {-1, -1, -1}, p_margin = -1, p_calibrate = -1;

  // Job (owned by the RT thread while busy == 0, by the worker while busy == 1).
  FrameSlot frames[kCameras];
  arflex_joint_state joint_state{};
  bool have_joints = false;
  bool joints_invalid = false;  // the newest joint state read was rejected (RT thread only)
  double fovy_deg = 50.0, margin = 30.0;
  Eigen::Vector3d tcp{0.30, 0.0, 0.0};
  bool tcp_calibrated = false;  // the tool's calibration file gave the TCP (configure)
  Eigen::Vector3d tcp_calibration{0.30, 0.0, 0.0};
  bool recalibrate = false;
  int64_t calibrate_seen = 0;

  // Result (written by the worker before it clears busy).
  arflex_pose result{};
  bool result_ready = false;
  uint64_t out_seq = 0;
  int waiting_cycles = 0;  // cycles since the first fresh frame of the pending job

  std::atomic<int> busy{0};
  std::atomic<bool> quit{false};
  sem_t go;
  bool sem_ok = false;
  std::thread worker;

  // Worker-only state.
  std::unique_ptr<vision::TagDetector> detector;
  std::vector<vision::Camera> cameras{kCameras};
  std::vector<vision::TagModel> board = vision::CellBoardTags();
  std::vector<vision::TagModel> tool = vision::CellToolTags();
  arflex::cellmodel::NominalKinematics kinematics{arflex::cellmodel::DefaultArm()};
  bool have_last = false;
  Eigen::Isometry3d last_marker = Eigen::Isometry3d::Identity();
  vision::EstimatorOptions options;
  uint64_t calibrations = 0;

  // The worker's part of the state block, written with each result (D58); read by the RT
  // thread while busy == 0.
  arflex_vision_state snapshot{};
  arflex_vision_state state{};  // RT thread: the block published
};

Vision g;

double ParamF64(arflex_component* c, int idx, double def) {
  return idx >= 0 ? arflex_param_f64(c, idx) : def;
}

// The type's largest slot (header + MAX_PAYLOAD), as every arflex.ImageFrame provider
// declares it; frames above 1280x1024 RGB are counted out by the size check in update().
const arflex_port_type kFrameType = {ARFLEX_TYPE_IMAGE_FRAME_NAME, 1, 0,
                                     ARFLEX_TYPE_IMAGE_FRAME_SIZE + ARFLEX_TYPE_IMAGE_FRAME_MAX_PAYLOAD};
const arflex_port_type kJointType = {ARFLEX_TYPE_JOINT_STATE_NAME, 1, 0, ARFLEX_TYPE_JOINT_STATE_SIZE};
const arflex_port_type kPoseType = {ARFLEX_TYPE_POSE_NAME, 1, 0, ARFLEX_TYPE_POSE_SIZE};

// Quaternion w, x, y, z of a rotation, to 4 doubles.
void PutQuat(const Eigen::Matrix3d& r, double* q) {
  const Eigen::Quaterniond e(r);
  q[0] = e.w();
  q[1] = e.x();
  q[2] = e.y();
  q[3] = e.z();
}

// A unit quaternion (w, x, y, z) as a rotation; false when it is not one (to 1e-6).
bool GetQuat(const double* q, Eigen::Matrix3d* r) {
  const Eigen::Quaterniond e(q[0], q[1], q[2], q[3]);
  if (!(std::abs(e.norm() - 1.0) <= 1e-6)) return false;
  *r = e.normalized().toRotationMatrix();
  return true;
}

// The worker's part of the state block (worker thread, at the end of a job).
void Snapshot() {
  Vision& v = g;
  arflex_vision_state& s = v.snapshot;
  s.calibrations = v.calibrations;
  s.flags = v.have_last ? ARFLEX_VISION_STATE_FLAG_HAVE_LAST : 0u;
  const Eigen::Vector3d lp = v.last_marker.translation();
  for (int i = 0; i < 3; ++i) s.last_p[i] = lp(i);
  PutQuat(v.last_marker.linear(), s.last_quat);
  s.calibrated = 0;
  for (int c = 0; c < kCameras; ++c) {
    const vision::Camera& cam = v.cameras[c];
    if (cam.calibrated) s.calibrated |= 1u << c;
    const Eigen::Vector3d p = cam.world_from_camera.translation();
    for (int i = 0; i < 3; ++i) s.cam_p[3 * c + i] = p(i);
    PutQuat(cam.world_from_camera.linear(), &s.cam_quat[4 * c]);
    s.cam_rms[c] = cam.calibration_rms_px;
  }
  s.fovy_deg = v.fovy_deg;
}

void Process() {
  Vision& v = g;
  std::array<vision::Observation, vision::kMaxObservations> obs;
  std::array<vision::TagDetection, 16> dets;
  int nobs = 0;
  int64_t t_ns = 0;
  Eigen::Isometry3d predicted;
  bool have_prediction = false;
  if (v.have_joints) {
    arflex::cellmodel::JointVector q;
    for (int i = 0; i < 6; ++i) q[i] = v.joint_state.q[i];
    predicted = v.kinematics.Flange(q);
    have_prediction = true;
  } else if (v.have_last) {
    predicted = v.last_marker;
    have_prediction = true;
  }
  for (int c = 0; c < kCameras; ++c) {
    FrameSlot& f = v.frames[c];
    if (!f.present) continue;
    const arflex_image_frame& h = f.header;
    vision::FrameView frame{f.pixels.get(), static_cast<int>(h.width), static_cast<int>(h.height),
                            static_cast<int>(h.stride),
                            h.format == ARFLEX_IMAGE_FRAME_FORMAT_RGB8 ? vision::PixelFormat::kRgb8
                                                                       : vision::PixelFormat::kGray8};
    vision::Camera& cam = v.cameras[c];
    cam.k.width = frame.width;
    cam.k.height = frame.height;
    cam.k.fy = cam.k.fx = 0.5 * frame.height / std::tan(0.5 * v.fovy_deg * M_PI / 180.0);
    cam.k.cx = 0.5 * (frame.width - 1);
    cam.k.cy = 0.5 * (frame.height - 1);
    if (!cam.calibrated || v.recalibrate) {
      const int n = v.detector->Detect(frame, nullptr, 0, dets.data(), 16, nullptr);
      std::string error;
      vision::Camera fresh = cam;
      fresh.calibrated = false;
      if (n > 0 && vision::CalibrateCamera(&fresh, v.board, dets.data(), n, v.options, nullptr, &error)) {
        cam = fresh;
        ++v.calibrations;
      }
      if (!cam.calibrated) continue;
      vision::CollectObservations(c, dets.data(), n, v.tool, obs.data(), &nobs);
    } else {
      vision::Roi roi;
      if (have_prediction) roi = vision::PredictRoi(cam, predicted, v.tool, v.margin);
      const int n = roi.empty() ? v.detector->Detect(frame, nullptr, 0, dets.data(), 16, nullptr)
                                : v.detector->Detect(frame, &roi, 1, dets.data(), 16, nullptr);
      if (n > 0) vision::CollectObservations(c, dets.data(), n, v.tool, obs.data(), &nobs);
    }
    if (t_ns == 0 || h.t_ns < t_ns) t_ns = h.t_ns;
  }
  v.recalibrate = false;
  for (FrameSlot& f : v.frames) f.present = false;
  vision::PoseEstimate est = vision::EstimateObjectPose(
      v.cameras, v.tool, obs.data(), nobs, have_prediction ? &predicted : nullptr, v.options);
  if (est.valid) {
    v.last_marker = est.pose;
    v.have_last = true;
  }
  Eigen::Isometry3d tcp = Eigen::Isometry3d::Identity();
  tcp.translation() = v.tcp;
  est = vision::TransformEstimate(est, tcp);
  arflex_pose& r = v.result;
  r.t_ns = t_ns;
  const Eigen::Vector3d p = est.pose.translation();
  const Eigen::Quaterniond q(est.pose.linear());
  for (int i = 0; i < 3; ++i) r.p[i] = p(i);
  r.quat[0] = q.w();
  r.quat[1] = q.x();
  r.quat[2] = q.y();
  r.quat[3] = q.z();
  for (int i = 0; i < 6; ++i) r.cov[i] = est.covariance(i, i);
  r.valid = est.valid ? 1u : 0u;
  r.n_views = static_cast<uint32_t>(est.valid ? est.n_views : 0);
  Snapshot();
  v.result_ready = true;
}

void WorkerLoop() {
  for (;;) {
    while (sem_wait(&g.go) != 0 && errno == EINTR) {
    }
    if (g.quit.load(std::memory_order_acquire)) return;
    Process();
    g.busy.store(0, std::memory_order_release);
  }
}

// Which TCP the half measures (configure): the tool's calibration file, or the nominal
// tcp_x/y/z unless a calibration is required. Says which on stderr; -EINVAL when refused.
int ChooseTcp(arflex_component* c) {
  const int p_tool = arflex_component_param(c, "tool_id");
  const int p_require = arflex_component_param(c, "require_tool_calibration");
  const int tool = p_tool >= 0 ? static_cast<int>(arflex_param_i64(c, p_tool)) : 1;
  const bool require = p_require >= 0 && arflex_param_i64(c, p_require) != 0;
  const Eigen::Vector3d nominal(ParamF64(c, g.p_tcp[0], 0.30), ParamF64(c, g.p_tcp[1], 0.0),
                                ParamF64(c, g.p_tcp[2], 0.0));
  const arflex::vision::calib::TcpChoice choice =
      arflex::vision::calib::ChooseTcp(tool, nominal, arflex::vision::calib::ToolCalibrationPath(tool), require);
  std::fprintf(stderr, "vision: %s\n", choice.description.c_str());
  if (!choice.ok) return -EINVAL;
  g.tcp_calibrated = choice.calibrated;
  g.tcp_calibration = choice.tcp_in_marker;
  return 0;
}

int Configure(arflex_component* c, void*) {
  static const char* const names[kCameras] = {"cam0", "cam1", "cam2", "cam3"};
  for (int i = 0; i < kCameras; ++i) {
    int r = arflex_component_input(c, names[i], ARFLEX_PORT_FRAME, &kFrameType, &g.cam[i]);
    if (r < 0) return r;
  }
  int r = arflex_component_input(c, "joint_state", ARFLEX_PORT_STATE, &kJointType, &g.joints);
  if (r < 0) return r;
  r = arflex_component_output(c, "tcp_pose", ARFLEX_PORT_STATE, &kPoseType, &g.out);
  if (r < 0) return r;
  // The state block (D58): without a state segment (a contract without <state>, a host test
  // without one) publishing is a no-op.
  static const arflex_port_type kStateType = {ARFLEX_TYPE_VISION_STATE_NAME, ARFLEX_TYPE_VISION_STATE_VERSION_MAJOR,
                                              ARFLEX_TYPE_VISION_STATE_VERSION_MINOR, ARFLEX_TYPE_VISION_STATE_SIZE};
  if ((r = arflex_component_state(c, &kStateType, nullptr)) < 0 && r != -ENOENT) return r;
  g.p_fovy = arflex_component_param(c, "fovy_deg");
  g.p_tcp[0] = arflex_component_param(c, "tcp_x");
  g.p_tcp[1] = arflex_component_param(c, "tcp_y");
  g.p_tcp[2] = arflex_component_param(c, "tcp_z");
  g.p_margin = arflex_component_param(c, "roi_margin_px");
  g.p_calibrate = arflex_component_param(c, "calibrate");
  if ((r = ChooseTcp(c)) < 0) return r;
  vision::DetectorOptions o;
  o.max_width = kMaxWidth;
  o.max_height = kMaxHeight;
  std::string error;
  g.detector = vision::TagDetector::Create(o, &error);
  if (!g.detector) {
    std::fprintf(stderr, "vision: %s\n", error.c_str());
    return -EINVAL;
  }
  for (FrameSlot& f : g.frames) f.pixels.reset(new uint8_t[kMaxPixels]);
  g.fovy_deg = ParamF64(c, g.p_fovy, 50.0);
  Snapshot();  // what a block published before the first job says (identity poses, nothing calibrated)
  if (sem_init(&g.go, 0, 0) != 0) return -errno;
  g.sem_ok = true;
  try {
    g.worker = std::thread(WorkerLoop);
  } catch (const std::system_error& e) {
    sem_destroy(&g.go);
    g.sem_ok = false;
    return -EAGAIN;
  }
  return 0;
}

// The state block (D58), RT thread, while the worker is idle: its last snapshot and the RT
// thread's own seqs.
void PublishState(arflex_component* c, uint64_t release_ns) {
  if (!arflex_component_state_open(c)) return;
  arflex_vision_state& st = g.state;
  const uint64_t seq = st.seq;
  st = g.snapshot;
  st.t_ns = static_cast<int64_t>(release_ns);
  st.seq = seq + 1;
  st.out_seq = g.out_seq;
  st.calibrate_seen = g.calibrate_seen;
  arflex_component_state_publish(c, &st, sizeof(st), release_ns);
}

// The adopt hook (D58): the state block of the version this half replaces, at its START (RT
// thread, right after the start hook, before the first update; no job was handed to the
// worker yet, so its state is this thread's to write).
int Adopt(arflex_component* c, void*, const arflex_adopted_state* a) {
  if (std::strcmp(a->type_name, ARFLEX_TYPE_VISION_STATE_NAME) != 0 || a->major != ARFLEX_TYPE_VISION_STATE_VERSION_MAJOR)
    return -EPROTOTYPE;
  arflex_vision_state st;
  if (a->length < sizeof(st)) return -EMSGSIZE;
  if (g.busy.load(std::memory_order_acquire) != 0) return -EBUSY;  // a half that ran: never adopts
  std::memcpy(&st, a->data, sizeof(st));
  if (!arflex_vision_state_valid(&st) || (st.calibrated & ~((1u << kCameras) - 1u)) != 0 ||
      (st.flags & ~ARFLEX_VISION_STATE_FLAG_HAVE_LAST) != 0)
    return -EINVAL;
  Eigen::Matrix3d last, cams[kCameras];
  if (!GetQuat(st.last_quat, &last)) return -EINVAL;
  for (int k = 0; k < kCameras; ++k)
    if (!GetQuat(&st.cam_quat[4 * k], &cams[k])) return -EINVAL;
  // taken whole, or not at all (above); calibrations made with another field of view than
  // this half's are not used (it calibrates again from the board)
  const bool same_optics = std::abs(st.fovy_deg - ParamF64(c, g.p_fovy, 50.0)) < 1e-9;
  for (int k = 0; k < kCameras; ++k) {
    vision::Camera& cam = g.cameras[k];
    cam.calibrated = same_optics && ((st.calibrated >> k) & 1u) != 0;
    cam.world_from_camera = Eigen::Isometry3d::Identity();
    cam.world_from_camera.linear() = cams[k];
    cam.world_from_camera.translation() = Eigen::Vector3d(st.cam_p[3 * k], st.cam_p[3 * k + 1], st.cam_p[3 * k + 2]);
    cam.calibration_rms_px = st.cam_rms[k];
  }
  g.have_last = (st.flags & ARFLEX_VISION_STATE_FLAG_HAVE_LAST) != 0;
  g.last_marker = Eigen::Isometry3d::Identity();
  g.last_marker.linear() = last;
  g.last_marker.translation() = Eigen::Vector3d(st.last_p[0], st.last_p[1], st.last_p[2]);
  g.calibrations = st.calibrations;
  g.out_seq = st.out_seq;
  g.calibrate_seen = st.calibrate_seen;
  g.state.seq = st.seq;
  Snapshot();
  return 0;
}

int Update(arflex_component* c, void*, uint64_t release_ns) {
  if (g.busy.load(std::memory_order_acquire) != 0) return 0;  // worker still on the last job
  if (g.result_ready) {
    g.result.seq = ++g.out_seq;
    arflex_state_write(g.out, &g.result, sizeof(g.result));
    g.result_ready = false;
  }
  PublishState(c, release_ns);
  // Collect the newest frame of every camera; the job goes when every bound camera has a
  // fresh frame (one set of views), or three cycles after the first one arrived.
  bool all = true, any = false;
  for (int i = 0; i < kCameras; ++i) {
    FrameSlot& f = g.frames[i];
    arflex_frame_view view;
    if (arflex_input_frame_acquire(g.cam[i], &view) == 1 && view.length >= ARFLEX_TYPE_IMAGE_FRAME_SIZE) {
      arflex_image_frame h;
      std::memcpy(&h, view.data, sizeof(h));
      const uint32_t bpp = h.format == ARFLEX_IMAGE_FRAME_FORMAT_RGB8 ? 3u : 1u;
      const bool format_ok =
          h.format == ARFLEX_IMAGE_FRAME_FORMAT_RGB8 || h.format == ARFLEX_IMAGE_FRAME_FORMAT_GRAY8;
      const uint64_t bytes = static_cast<uint64_t>(h.stride) * h.height;
      // A malformed frame is ignored (the estimate uses the other cameras).
      if (arflex_image_frame_valid(&h) && format_ok && h.width > 0 && h.height > 0 && h.width <= kMaxWidth && h.height <= kMaxHeight &&
          h.stride >= h.width * bpp && bytes <= kMaxPixels && bytes + ARFLEX_TYPE_IMAGE_FRAME_SIZE <= view.length) {
        f.present = false;  // the pixels of a pending frame are being replaced
        std::memcpy(f.pixels.get(), static_cast<const uint8_t*>(view.data) + ARFLEX_TYPE_IMAGE_FRAME_SIZE,
                    bytes);
        if (arflex_frame_valid(&view)) {  // not overwritten while copying
          f.header = h;
          f.present = true;
        }
      } else {
        arflex_input_reject(g.cam[i]);
      }
    }
    any = any || f.present;
    if (arflex_input_bound(g.cam[i]) && !f.present) all = false;
  }
  if (!any) return 0;
  if (!all && ++g.waiting_cycles < 3) return 0;
  g.waiting_cycles = 0;
  // The joint state for the ROI prediction: the newest valid one; none while the newest value
  // read is invalid (each invalid value read is counted).
  int err = 0;
  arflex_joint_state js;
  const int got = arflex_input_state_read(g.joints, &js, sizeof(js), nullptr);
  if (got == 1) {
    g.joints_invalid = !arflex_joint_state_valid(&js);
    if (g.joints_invalid) {
      arflex_input_reject(g.joints);
      err = -EINVAL;
    } else {
      g.joint_state = js;
    }
  }
  g.have_joints = got >= 0 && !g.joints_invalid && g.joint_state.seq != 0;
  g.fovy_deg = ParamF64(c, g.p_fovy, 50.0);
  g.margin = ParamF64(c, g.p_margin, 30.0);
  g.tcp = g.tcp_calibrated ? g.tcp_calibration
                           : Eigen::Vector3d(ParamF64(c, g.p_tcp[0], 0.30), ParamF64(c, g.p_tcp[1], 0.0),
                                             ParamF64(c, g.p_tcp[2], 0.0));
  if (g.p_calibrate >= 0) {
    const int64_t want = arflex_param_i64(c, g.p_calibrate);
    if (want != g.calibrate_seen) {
      g.calibrate_seen = want;
      g.recalibrate = true;
    }
  }
  g.busy.store(1, std::memory_order_release);
  sem_post(&g.go);
  return err;
}

void Cleanup(arflex_component*, void*) {
  if (g.worker.joinable()) {
    g.quit.store(true, std::memory_order_release);
    sem_post(&g.go);
    g.worker.join();
  }
  if (g.sem_ok) sem_destroy(&g.go);
  g.detector.reset();
  for (FrameSlot& f : g.frames) f.pixels.reset();
}

}  // namespace

int main(int argc, char** argv) {
  // Best-effort work yields to everything else: detection (worker thread) runs at
  // nice 19. Every thread of this process (rt-core's loop and mailbox threads, and threads libraries create later)
  // inherits it from the main thread. Without it a cell's SCHED_OTHER work starves the
  // runtime's heartbeat thread on a small machine, and the 1 ms components go to safe mode.
  if (setpriority(PRIO_PROCESS, 0, 19) != 0) {
    std::fprintf(stderr, "vision: warning: setpriority(nice 19) failed: %s\n", std::strerror(errno));
  }
  arflex_component_ops ops{};
  ops.name = "vision";
  ops.configure = Configure;
  ops.update = Update;
  ops.cleanup = Cleanup;
  ops.adopt = Adopt;
  return arflex_component_main(argc, argv, &ops);
}
