// vision.comp.*: the vision RT half under the rt-core host API. The test is the cell around
// it: it creates a "feeder" instance whose output segments (four frame ports and a joint
// state) it writes itself, with synthetic frames of the board and the tool tags drawn through
// the cell's camera model, spawns the vision component, binds it and reads tcp_pose.
//
//   vision_comp_test <case> <vision exe> <contract>
//   cases: pose, loss, invalid, adopt, tool_uncalibrated, tool_calibrated
//
// tool_uncalibrated / tool_calibrated (the tool calibration, vision/native/calib): with
// require_tool_calibration = 1 and no tool-1.cal in the data directory the half refuses to
// configure, naming the tool and the file; with a tool-1.cal whose TCP is 10 mm off the
// nominal one it says it uses that TCP and its poses are the marker pose times it. Every case
// runs with ARFLEX_DATA_DIR set to a fresh directory of its own (removed at the end).
//
// adopt (docs/DECISIONS.md D58): a second vision half given the first one's state block
// (arflex.VisionState) by ADOPT continues its estimate: its first pose carries the next seq,
// lies where the first half's last one did (the same frames), and its cameras are the first
// half's calibration (to rounding), not a new one. Blocks it cannot take refuse its START with the reason's errno and leave it
// READY: another type or major version (-EPROTOTYPE), a block shorter than the type (-EMSGSIZE),
// a non-finite or out-of-range value and a quaternion that is not a unit one (-EINVAL).
//
// The vision instance's ports, parameters, task type and safe mode come from the bundle's
// contract (arflex_host_load_contract, docs/DECISIONS.md D32/D34). The harness's own choices:
// a 20 ms period (the contract's 200 ms would make the cases ten times slower), SCHED_OTHER,
// no mlock or cpu_dma_latency, no heartbeat watchdog. The feeder plays sim-camera-0..3 and
// sim-robot: it is the test's own provider, not a component, and its segments are declared here.
// Every case ends by checking that no /dev/shm or /dev/mqueue object of its runtime id and no
// child process is left. Waits are on conditions with deadlines; nothing asserts on timing.
#include <dirent.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

extern "C" {
#include "arflex/host.h"
#include "arflex/host_contract.h"
#include "helper.h" /* rt-core test kit: leak checks */
}
#include "arflex_cellmodel/kinematics.h"
#include "arflex_types/image_frame.h"
#include "arflex_types/joint_state.h"
#include "arflex_types/pose.h"
#include "arflex_types/vision_state.h"
#include "arflex_vision/cell_layout.h"
#include "arflex_vision_calib/tool_calibration.h"
#include "synthetic_scene.h"

namespace {

namespace vision = arflex::vision;
constexpr uint64_t kSec = 1000000000ull;
constexpr uint64_t kMs = 1000000ull;
constexpr int kW = 1280, kH = 1024;  // the cell cameras' resolution
constexpr uint32_t kFrameBytes = ARFLEX_TYPE_IMAGE_FRAME_SIZE + kW * kH;
// Frame providers declare the type's largest slot (as sim-camera does).
constexpr uint32_t kFrameElem = ARFLEX_TYPE_IMAGE_FRAME_SIZE + ARFLEX_TYPE_IMAGE_FRAME_MAX_PAYLOAD;

char rid[ARFLEX_ID_MAX + 1];
const char* contract_xml;
int failures = 0;

#define CHECK(cond, ...)                                                        \
  do {                                                                          \
    if (!(cond)) {                                                              \
      std::fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);      \
      std::fprintf(stderr, __VA_ARGS__);                                        \
      std::fputc('\n', stderr);                                                 \
      ++failures;                                                               \
      goto out;                                                                 \
    }                                                                           \
  } while (0)

arflex_ctl_config Config(uint64_t period_ns) {
  arflex_ctl_config c;
  std::memset(&c, 0, sizeof(c));
  c.period_ns = period_ns;
  c.priority = 0;
  c.safe_mode = ARFLEX_SAFE_HOLD;
  c.cfg_flags = ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
  return c;
}

// rt-core's test kit (arflex_testkit): /dev/shm and /dev/mqueue objects of rid, children.
bool Leaked() {
  bool any = th_leftovers(rid) > 0;
  if (!th_no_children()) {
    std::fprintf(stderr, "leak: a child process is left\n");
    any = true;
  }
  return any;
}

const arflex::cellmodel::JointVector kQ = {0.1, 0.45, 0.35, 0.2, 0.7, 0.3};

// The expected TCP: nominal flange at kQ and the TCP 0.3 m along the flange x axis.
Eigen::Isometry3d TrueTcp() {
  arflex::cellmodel::NominalKinematics kin(arflex::cellmodel::DefaultArm());
  Eigen::Isometry3d t = kin.Flange(kQ);
  t.translate(Eigen::Vector3d(0.3, 0, 0));
  return t;
}

class Feeder {
 public:
  int Create() {
    const char* names[] = {"cam0", "cam1", "cam2", "cam3", "joint_state"};
    struct arflex_host_output outs[5];
    std::memset(outs, 0, sizeof(outs));
    for (int i = 0; i < 4; ++i) {
      outs[i].port = names[i];
      outs[i].spec.method = ARFLEX_PORT_FRAME;
      outs[i].spec.type = {ARFLEX_TYPE_IMAGE_FRAME_NAME, 1, 0, kFrameElem};
      outs[i].spec.depth = 2;
    }
    outs[4].port = names[4];
    outs[4].spec.method = ARFLEX_PORT_STATE;
    outs[4].spec.type = {ARFLEX_TYPE_JOINT_STATE_NAME, 1, 0, ARFLEX_TYPE_JOINT_STATE_SIZE};
    outs[4].spec.depth = 1;
    arflex_host_opts o;
    std::memset(&o, 0, sizeof(o));
    o.runtime = rid;
    o.instance = "feeder";
    o.config = Config(10 * kMs);
    o.outputs = outs;
    o.noutputs = 5;
    const int r = arflex_host_create(&host_, &o);
    created_ = r == 0;
    return r;
  }
  ~Feeder() {
    if (created_) arflex_host_destroy(&host_);
  }
  arflex_host* host() { return &host_; }
  bool bad_joints = false;  // publish a NaN joint state with the frames

  // Draws the frames of the scene once (it is static): with and without the tags.
  void Draw() {
    const auto cams = vision::testing::CellCameras(kW, kH);
    arflex::cellmodel::NominalKinematics kin(arflex::cellmodel::DefaultArm());
    const Eigen::Isometry3d flange = kin.Flange(kQ);
    for (int c = 0; c < 4; ++c) {
      blank_[c] = cv::Mat(kH, kW, CV_8UC1, cv::Scalar(140));
      tagged_[c] = blank_[c].clone();
      for (const auto& t : vision::CellBoardTags()) drawer_.Draw(cams[c], t, Eigen::Isometry3d::Identity(), &tagged_[c]);
      for (const auto& t : vision::CellToolTags()) drawer_.Draw(cams[c], t, flange, &tagged_[c]);
    }
  }

  // Publishes one frame per camera (a synchronised set) and the joint state; with `tags`
  // false the frames show no tag (vision loss).
  void Publish(bool tags, uint64_t seq) {
    static const char* const names[] = {"cam0", "cam1", "cam2", "cam3"};
    for (int c = 0; c < 4; ++c) {
      const cv::Mat& img = tags ? tagged_[c] : blank_[c];
      arflex_port* p = arflex_host_output(&host_, names[c]);
      auto* slot = static_cast<uint8_t*>(arflex_frame_begin(p));
      arflex_image_frame h;
      std::memset(&h, 0, sizeof(h));
      h.t_ns = static_cast<int64_t>(arflex_sys_now_ns());
      h.seq = seq;
      h.camera = c;
      h.width = kW;
      h.height = kH;
      h.stride = kW;
      h.format = ARFLEX_IMAGE_FRAME_FORMAT_GRAY8;
      h.bytes = kW * kH;
      std::memcpy(slot, &h, sizeof(h));
      std::memcpy(slot + ARFLEX_TYPE_IMAGE_FRAME_SIZE, img.data, kW * kH);
      arflex_frame_commit(p, kFrameBytes);
    }
    arflex_joint_state js;
    std::memset(&js, 0, sizeof(js));
    js.t_ns = static_cast<int64_t>(arflex_sys_now_ns());
    js.seq = seq;
    for (int i = 0; i < 6; ++i) js.q[i] = kQ[i];
    if (bad_joints) js.q[3] = std::nan("");
    arflex_state_write(arflex_host_output(&host_, "joint_state"), &js, sizeof(js));
  }

 private:
  arflex_host host_{};
  bool created_ = false;
  vision::testing::SceneDrawer drawer_;
  cv::Mat blank_[4], tagged_[4];
};

// The vision instance as its contract declares it, with the harness's period and flags.
// `instance` names its objects ("vision"; the half that replaces it in the adopt case: "2-vision").
// `param` (may be null) gets the initial value `bits`; `spawn_flags` go to arflex_host_spawn_ex.
int MakeVision(arflex_host* h, const char* exe, const char* instance = "vision", const char* param = nullptr,
               uint64_t bits = 0, unsigned spawn_flags = 0) {
  static const arflex_host_type types[] = {ARFLEX_HOST_FRAME_TYPE(IMAGE_FRAME), ARFLEX_HOST_TYPE(JOINT_STATE),
                                           ARFLEX_HOST_TYPE(POSE), ARFLEX_HOST_TYPE(VISION_STATE)};
  static arflex_host_contract c;
  char err[512];
  int r = arflex_host_load_contract(&c, contract_xml, types, 4, err, sizeof(err));
  if (r < 0) {
    std::fprintf(stderr, "%s\n", err);
    return r;
  }
  for (unsigned i = 0; param != nullptr && i < c.nparams; ++i) {
    if (std::strcmp(c.params[i].name, param) == 0) c.params[i].default_bits = bits;
  }
  arflex_host_opts o;
  arflex_host_contract_opts(&c, rid, instance, &o);
  o.config.period_ns = 20 * kMs;
  o.config.deadline_ns = 20 * kMs;
  o.config.priority = 0;
  o.config.hb_timeout_ns = 0;
  o.config.cfg_flags |= ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
  r = arflex_host_create(h, &o);
  if (r < 0) return r;
  return arflex_host_spawn_ex(h, exe, nullptr, nullptr, spawn_flags);
}

// The vision half of a case and its tcp_pose reader: closed and destroyed (child reaped, objects
// unlinked) when the case returns.
struct HalfUnderTest {
  arflex_host vis{};
  arflex_port reader{};
  bool reader_open = false;
  HalfUnderTest() = default;
  HalfUnderTest(const HalfUnderTest&) = delete;
  HalfUnderTest& operator=(const HalfUnderTest&) = delete;
  ~HalfUnderTest() {
    if (reader_open) arflex_port_close(&reader);
    arflex_host_destroy(&vis);
  }
};

// Waits for `vis` READY, binds its inputs to the feeder's outputs, opens `reader` on its
// tcp_pose (setting *reader_open) and STARTs it. Returns "" or the step that failed.
std::string ReadyBindStart(Feeder* feeder, arflex_host* vis, arflex_port* reader, bool* reader_open) {
  static const char* const ports[] = {"cam0", "cam1", "cam2", "cam3", "joint_state"};
  if (arflex_host_wait_state(vis, ARFLEX_STATE_READY, 20 * kSec) != 0) return "vision READY";
  for (const char* port : ports) {
    if (arflex_host_bind(vis, port, arflex_host_output_name(feeder->host(), port), 2 * kSec) != 0) {
      return std::string("BIND ") + port;
    }
  }
  const arflex_port_type t = {ARFLEX_TYPE_POSE_NAME, 1, 0, ARFLEX_TYPE_POSE_SIZE};
  if (arflex_port_open(reader, arflex_host_output_name(vis, "tcp_pose"), false, false, ARFLEX_PORT_STATE, &t) != 0) {
    return "open tcp_pose";
  }
  *reader_open = true;
  if (arflex_host_start(vis, 2 * kSec) != 0) return "START";
  return "";
}

// Reads the child's output pipe until it holds `needle`, it ends (EOF) or `timeout_ns` passes.
// Returns everything read.
std::string ReadOutputUntil(arflex_host* h, const char* needle, uint64_t timeout_ns) {
  std::string text;
  const int fd = arflex_host_output_fd(h);
  const uint64_t deadline = arflex_sys_now_ns() + timeout_ns;
  while (fd >= 0 && text.find(needle) == std::string::npos && arflex_sys_now_ns() < deadline) {
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, 100) <= 0) continue;
    char buf[512];
    const ssize_t n = read(fd, buf, sizeof buf);
    if (n == 0) break;
    if (n > 0) text.append(buf, static_cast<size_t>(n));
  }
  return text;
}

// Publishes frames (with or without tags) until a tcp_pose with `want_valid` arrives or the
// deadline passes. Returns true and the pose in *got.
bool WaitPose(Feeder* feeder, arflex_port* reader, bool tags, bool want_valid, arflex_pose* got) {
  const uint64_t deadline = arflex_sys_now_ns() + 30 * kSec;
  uint64_t seq = 1;
  uint64_t last_publish = 0;
  while (arflex_sys_now_ns() < deadline) {
    // A new frame set every 100 ms (the test's camera rate).
    if (arflex_sys_now_ns() - last_publish > 100 * kMs) {
      feeder->Publish(tags, seq++);
      last_publish = arflex_sys_now_ns();
    }
    arflex_pose p;
    if (arflex_state_read(reader, &p, sizeof(p), nullptr) == 1) {
      *got = p;
      // A valid pose counts once it uses at least three of the four views.
      if (want_valid ? (p.valid != 0 && p.n_views >= 3) : p.valid == 0) return true;
    }
    usleep(1000);  // polling interval of the reader, not a wait for a condition
  }
  return false;
}

// Reads the newest value of a state segment; false when there is none.
bool ReadState(arflex_port* p, arflex_vision_state* st) {
  return p != nullptr && arflex_state_read(p, st, sizeof(*st), nullptr) == 1;
}

// The adopt case (D58), after `first` gave a valid pose (`pose`) and was stopped.
void AdoptCase(Feeder* feeder, arflex_host* first, const arflex_pose& last_pose, const char* exe) {
  static const char* const ports[] = {"cam0", "cam1", "cam2", "cam3", "joint_state"};
  arflex_vision_state old{};
  arflex_host bad;
  bool bad_created = false;
  std::memset(&bad, 0, sizeof(bad));
  CHECK(ReadState(arflex_host_state(first), &old), "the first half published no state block");
  CHECK(old.calibrated == 0xfu, "calibrated cameras 0x%x", old.calibrated);
  CHECK(old.calibrations >= 4, "%llu calibrations", static_cast<unsigned long long>(old.calibrations));
  CHECK(old.out_seq == last_pose.seq, "the block's out_seq %llu, the last pose's seq %llu",
        static_cast<unsigned long long>(old.out_seq), static_cast<unsigned long long>(last_pose.seq));
  CHECK(old.flags & ARFLEX_VISION_STATE_FLAG_HAVE_LAST, "no last estimate in the block");
  {
    // Blocks the new half must refuse, each in a state segment of the test's own instance.
    struct Bad {
      const char* port;
      arflex_port_type type;
      int want;
    };
    const Bad cases[] = {
        {"other", {ARFLEX_TYPE_POSE_NAME, 1, 0, ARFLEX_TYPE_POSE_SIZE}, -EPROTOTYPE},
        {"major2", {ARFLEX_TYPE_VISION_STATE_NAME, 2, 0, ARFLEX_TYPE_VISION_STATE_SIZE}, -EPROTOTYPE},
        {"short", {ARFLEX_TYPE_VISION_STATE_NAME, 1, 0, 128}, -EMSGSIZE},
        {"nan", {ARFLEX_TYPE_VISION_STATE_NAME, 1, 0, ARFLEX_TYPE_VISION_STATE_SIZE}, -EINVAL},
        {"notunit", {ARFLEX_TYPE_VISION_STATE_NAME, 1, 0, ARFLEX_TYPE_VISION_STATE_SIZE}, -EINVAL},
    };
    constexpr int kBad = sizeof(cases) / sizeof(cases[0]);
    struct arflex_host_output outs[kBad];
    std::memset(outs, 0, sizeof(outs));
    for (int i = 0; i < kBad; ++i) {
      outs[i].port = cases[i].port;
      outs[i].spec.method = ARFLEX_PORT_STATE;
      outs[i].spec.type = cases[i].type;
      outs[i].spec.depth = 1;
    }
    arflex_host_opts o;
    std::memset(&o, 0, sizeof(o));
    o.runtime = rid;
    o.instance = "bad";
    o.config = Config(10 * kMs);
    o.outputs = outs;
    o.noutputs = kBad;
    CHECK(arflex_host_create(&bad, &o) == 0, "the bad blocks' instance");
    bad_created = true;
    arflex_pose other{};
    other.seq = 1;
    other.quat[0] = 1;
    CHECK(arflex_state_write(arflex_host_output(&bad, "other"), &other, sizeof(other)) == 0, "write other");
    CHECK(arflex_state_write(arflex_host_output(&bad, "major2"), &old, sizeof(old)) == 0, "write major2");
    CHECK(arflex_state_write(arflex_host_output(&bad, "short"), &old, 128) == 0, "write short");
    arflex_vision_state v = old;
    v.cam_p[4] = std::nan("");
    CHECK(arflex_state_write(arflex_host_output(&bad, "nan"), &v, sizeof(v)) == 0, "write nan");
    v = old;
    v.cam_quat[4] = 0.5;  // camera 1: (0.5, x, y, z) is no unit quaternion, every number in bounds
    v.cam_quat[5] = v.cam_quat[6] = v.cam_quat[7] = 0.0;
    CHECK(arflex_state_write(arflex_host_output(&bad, "notunit"), &v, sizeof(v)) == 0, "write notunit");
    for (const Bad& b : cases) {
      arflex_host h;
      std::memset(&h, 0, sizeof(h));
      bool ok = MakeVision(&h, exe, "2-vision") == 0 && arflex_host_wait_state(&h, ARFLEX_STATE_READY, 20 * kSec) == 0;
      int st = ok ? arflex_host_adopt(&h, arflex_host_output_name(&bad, b.port), 2 * kSec) : -1;
      int started = st == 0 ? arflex_host_start(&h, 2 * kSec) : 1;
      const bool ready = arflex_ctl_state(h.ctl) == ARFLEX_STATE_READY;
      std::printf("adopt: a block '%s' (%s %u.%u, %u B): START %d (%s)\n", b.port, b.type.name, b.type.major,
                  b.type.minor, b.type.elem_size, started, started < 0 ? std::strerror(-started) : "-");
      const bool down = arflex_host_shutdown(&h, 5 * kSec) == 0 && arflex_host_wait_exit(&h, 10 * kSec) == 0;
      arflex_host_destroy(&h);
      CHECK(ok && st == 0, "the refusing half came up and took the ADOPT (%d)", st);
      CHECK(started == b.want, "block '%s': START %d, expected %d", b.port, started, b.want);
      CHECK(ready, "block '%s': the refusing half is not READY", b.port);
      CHECK(down, "block '%s': the refusing half did not shut down", b.port);
    }
  }
  {
    // The good block: the first half's.
    arflex_host next;
    std::memset(&next, 0, sizeof(next));
    arflex_port reader;
    bool reader_open = false;
    arflex_pose p{};
    arflex_vision_state now{};
    bool ok = MakeVision(&next, exe, "2-vision") == 0 && arflex_host_wait_state(&next, ARFLEX_STATE_READY, 20 * kSec) == 0;
    if (ok) ok = arflex_host_adopt(&next, arflex_host_state(first)->name, 2 * kSec) == 0;
    for (const char* port : ports)
      if (ok) ok = arflex_host_bind(&next, port, arflex_host_output_name(feeder->host(), port), 2 * kSec) == 0;
    if (ok) {
      const arflex_port_type t = {ARFLEX_TYPE_POSE_NAME, 1, 0, ARFLEX_TYPE_POSE_SIZE};
      ok = arflex_port_open(&reader, arflex_host_output_name(&next, "tcp_pose"), false, false, ARFLEX_PORT_STATE, &t) == 0;
      reader_open = ok;
    }
    if (ok) ok = arflex_host_start(&next, 2 * kSec) == 0;
    // its first pose: WaitPose returns the first value it reads that is valid with 3 views
    const bool got = ok && WaitPose(feeder, &reader, true, true, &p);
    const bool have_state = got && ReadState(arflex_host_state(&next), &now);
    double dp = 0, dcam = 0;
    for (int i = 0; i < 3; ++i) dp = std::max(dp, std::abs(p.p[i] - last_pose.p[i]));
    for (int i = 0; i < 12; ++i) dcam = std::max(dcam, std::abs(now.cam_p[i] - old.cam_p[i]));
    for (int i = 0; i < 16; ++i) dcam = std::max(dcam, std::abs(now.cam_quat[i] - old.cam_quat[i]));
    std::printf("adopt: the adopting half's first pose seq %llu (the first half's last %llu), %.3g m from the "
                "first half's last pose; its cameras %.3g from the adopted calibration, %llu calibrations "
                "(adopted %llu)\n", static_cast<unsigned long long>(p.seq),
                static_cast<unsigned long long>(last_pose.seq), dp, dcam,
                static_cast<unsigned long long>(now.calibrations), static_cast<unsigned long long>(old.calibrations));
    const bool down = arflex_host_shutdown(&next, 5 * kSec) == 0 && arflex_host_wait_exit(&next, 10 * kSec) == 0;
    if (reader_open) arflex_port_close(&reader);
    arflex_host_destroy(&next);
    CHECK(ok, "the adopting half: ADOPT, BIND, START");
    CHECK(got, "no valid tcp_pose from the adopting half");
    CHECK(have_state, "no state block from the adopting half");
    CHECK(p.seq == last_pose.seq + 1, "its first pose has seq %llu, not %llu", static_cast<unsigned long long>(p.seq),
          static_cast<unsigned long long>(last_pose.seq + 1));
    CHECK(dp < 1e-6, "its first pose is %.3g m from the first half's last one", dp);
    CHECK(now.calibrations == old.calibrations, "it calibrated again (%llu, adopted %llu)",
          static_cast<unsigned long long>(now.calibrations), static_cast<unsigned long long>(old.calibrations));
    // the camera poses go through a quaternion and back: the same to rounding (a calibration
    // of its own would move them by 1e-5 and more)
    CHECK(dcam < 1e-12, "its cameras are %.3g from the adopted calibration", dcam);
    CHECK(down, "the adopting half did not shut down");
  }
out:
  if (bad_created) arflex_host_destroy(&bad);
}

// tool_uncalibrated and tool_calibrated (see the top).
void ToolCase(const std::string& name, const char* exe, const std::string& data_dir) {
  arflex_pose pose;
  std::string out;  // what the half wrote on stdout/stderr
  Feeder feeder;
  HalfUnderTest half;
  arflex_host& vis = half.vis;
  arflex_port& reader = half.reader;
  bool& reader_open = half.reader_open;
  const std::string file = data_dir + "/tool-1.cal";
  arflex::vision::calib::ToolCalibration cal;
  cal.tool = 1;
  cal.name = "tool-gripper";
  cal.tcp_in_marker = Eigen::Vector3d(0.31, 0.004, -0.002);
  cal.rms_m = 20e-6;
  cal.poses = 16;
  cal.spread_deg = 20;
  cal.date = "2026-12-07T21:00:00Z";
  CHECK(feeder.Create() == 0, "feeder create");
  feeder.Draw();
  if (name == "tool_uncalibrated") {
    CHECK(MakeVision(&vis, exe, "vision", "require_tool_calibration", 1, ARFLEX_HOST_OUTPUT_PIPE) == 0,
          "vision create/spawn");
    CHECK(arflex_host_wait_state(&vis, ARFLEX_STATE_READY, 20 * kSec) != 0, "an uncalibrated tool got READY");
    out = ReadOutputUntil(&vis, "\n", 10 * kSec);
    CHECK(out.find("tool 1 is not calibrated") != std::string::npos && out.find(file) != std::string::npos,
          "the refusal does not name the tool and %s: '%s'", file.c_str(), out.c_str());
    std::printf("refused: %s", out.c_str());
    goto out;
  }
  {
    std::string error;
    CHECK(arflex::vision::calib::WriteToolCalibration(file, cal, &error), "%s", error.c_str());
  }
  CHECK(MakeVision(&vis, exe, "vision", "require_tool_calibration", 1, ARFLEX_HOST_OUTPUT_PIPE) == 0,
        "vision create/spawn");
  out = ReadOutputUntil(&vis, "\n", 20 * kSec);
  CHECK(out.find("calibrated TCP (0.310000, 0.004000, -0.002000)") != std::string::npos &&
            out.find(file) != std::string::npos && out.find("2026-12-07T21:00:00Z") != std::string::npos,
        "the half does not say it uses the calibrated TCP: '%s'", out.c_str());
  std::printf("uses: %s", out.c_str());
  arflex_host_close_output(&vis);  // nothing more is read: the child's later writes fail, as a closed log would
  {
    const std::string failed = ReadyBindStart(&feeder, &vis, &reader, &reader_open);
    CHECK(failed.empty(), "%s", failed.c_str());
  }
  std::memset(&pose, 0, sizeof(pose));
  CHECK(WaitPose(&feeder, &reader, true, true, &pose), "no valid tcp_pose");
  {
    arflex::cellmodel::NominalKinematics kin(arflex::cellmodel::DefaultArm());
    const Eigen::Vector3d want = kin.Flange(kQ) * cal.tcp_in_marker;
    const Eigen::Vector3d p(pose.p[0], pose.p[1], pose.p[2]);
    CHECK((p - want).norm() < 1e-3, "tcp_pose is %.3f mm from the marker pose times the calibrated TCP",
          1e3 * (p - want).norm());
    CHECK((p - TrueTcp().translation()).norm() > 5e-3, "tcp_pose is at the nominal TCP (%.3f mm)",
          1e3 * (p - TrueTcp().translation()).norm());
  }
  CHECK(arflex_host_shutdown(&vis, 5 * kSec) == 0, "SHUTDOWN");
  CHECK(arflex_host_wait_exit(&vis, 10 * kSec) == 0, "exit");
out:
  unlink(file.c_str());
}

int RunCase(const std::string& name, const char* exe) {
  Feeder feeder;
  HalfUnderTest half;
  arflex_host& vis = half.vis;
  arflex_port& reader = half.reader;
  bool& reader_open = half.reader_open;
  arflex_pose pose;
  const Eigen::Isometry3d truth = TrueTcp();
  CHECK(feeder.Create() == 0, "feeder create");
  feeder.Draw();
  CHECK(MakeVision(&vis, exe) == 0, "vision create/spawn");
  {
    const std::string failed = ReadyBindStart(&feeder, &vis, &reader, &reader_open);
    CHECK(failed.empty(), "%s", failed.c_str());
  }
  // Calibration from the board, then the tool pose from all four views.
  std::memset(&pose, 0, sizeof(pose));
  CHECK(WaitPose(&feeder, &reader, true, true, &pose), "no valid tcp_pose (last: seq %llu valid %u views %u)",
        static_cast<unsigned long long>(pose.seq), pose.valid, pose.n_views);
  {
    const Eigen::Vector3d p(pose.p[0], pose.p[1], pose.p[2]);
    const double err = (p - truth.translation()).norm();
    // Synthetic 1280x1024 frames, the cell cameras' resolution.
    const double sigma = std::sqrt(pose.cov[0] + pose.cov[1] + pose.cov[2]);
    CHECK(err < 1.0e-3 && err < 4 * sigma + 0.2e-3, "tcp_pose %.6f %.6f %.6f is %.3f mm from the truth", p.x(), p.y(), p.z(), 1e3 * err);
    CHECK(pose.n_views >= 3, "only %u views", pose.n_views);
    CHECK(pose.cov[0] > 0 && pose.cov[0] < 25e-6, "variance x %g", pose.cov[0]);
    const Eigen::Quaterniond q(pose.quat[0], pose.quat[1], pose.quat[2], pose.quat[3]);
    CHECK(q.angularDistance(Eigen::Quaterniond(truth.linear())) < 5e-3, "orientation off");
  }
  if (name == "invalid") {
    // Validated data (docs/safety.md): a NaN joint state is not used for the ROI prediction
    // (counted as update errors); the pose stays valid (searched around the last pose); a
    // valid joint state afterwards is used again (no more errors).
    arflex_stats st;
    CHECK(arflex_ctl_stats_read(vis.ctl, &st) == 0, "stats");
    const uint64_t e0 = st.update_errors;
    feeder.bad_joints = true;
    for (int k = 0; k < 3; ++k)
      CHECK(WaitPose(&feeder, &reader, true, true, &pose), "no valid tcp_pose with a NaN joint state");
    CHECK(arflex_ctl_stats_read(vis.ctl, &st) == 0 && st.update_errors > e0, "the NaN joint state was not counted");
    {
      const Eigen::Vector3d p(pose.p[0], pose.p[1], pose.p[2]);
      CHECK((p - truth.translation()).norm() < 1.0e-3, "tcp_pose %.3f mm off with a NaN joint state",
            1e3 * (p - truth.translation()).norm());
    }
    feeder.bad_joints = false;
    CHECK(WaitPose(&feeder, &reader, true, true, &pose), "no valid tcp_pose after a valid joint state");
    CHECK(arflex_ctl_stats_read(vis.ctl, &st) == 0, "stats");
    const uint64_t e1 = st.update_errors;
    for (int k = 0; k < 3; ++k) CHECK(WaitPose(&feeder, &reader, true, true, &pose), "valid pose %d", k);
    CHECK(arflex_ctl_stats_read(vis.ctl, &st) == 0 && st.update_errors == e1,
          "errors counted with a valid joint state (%llu)", static_cast<unsigned long long>(st.update_errors - e1));
  }
  if (name == "adopt") {
    CHECK(arflex_host_stop(&vis, 5 * kSec) == 0, "STOP the first half");  // its block holds still
    // the last pose it wrote (a job in flight at the STOP is not published): a newer one than
    // WaitPose read (1), or that one (0)
    CHECK(arflex_state_read(&reader, &pose, sizeof(pose), nullptr) >= 0, "the first half's last pose");
    AdoptCase(&feeder, &vis, pose, exe);
  }
  if (name == "loss") {
    // Vision drops out (the tags are covered): the pose turns invalid, it never keeps
    // reporting the stale one as valid; then it recovers.
    CHECK(WaitPose(&feeder, &reader, false, false, &pose), "no invalid tcp_pose after the loss");
    CHECK(pose.n_views == 0, "n_views %u while invalid", pose.n_views);
    CHECK(WaitPose(&feeder, &reader, true, true, &pose), "no recovery");
    // Recalibration on request keeps it valid.
    CHECK(arflex_host_set_param(&vis, "calibrate", 1, nullptr, 2 * kSec) == 0, "SET_PARAM calibrate");
    CHECK(WaitPose(&feeder, &reader, true, true, &pose), "not valid after recalibration");
  }
  CHECK(arflex_host_shutdown(&vis, 5 * kSec) == 0, "SHUTDOWN");
  CHECK(arflex_host_wait_exit(&vis, 10 * kSec) == 0, "exit");
  CHECK(WIFEXITED(arflex_host_exit_status(&vis)) && WEXITSTATUS(arflex_host_exit_status(&vis)) == 0,
        "exit status %d", arflex_host_exit_status(&vis));
out:
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: vision_comp_test <pose|loss|invalid|adopt|tool_uncalibrated|tool_calibrated> "
                         "<vision exe> <contract>\n");
    return 2;
  }
  contract_xml = argv[3];
  std::snprintf(rid, sizeof(rid), "vct%d", static_cast<int>(getpid()));
  const std::string name = argv[1];
  const bool tool_case = name == "tool_uncalibrated" || name == "tool_calibrated";
  if (name != "pose" && name != "loss" && name != "invalid" && name != "adopt" && !tool_case) {
    std::fprintf(stderr, "vision_comp_test: unknown case '%s'\n", argv[1]);
    return 2;
  }
  // A data directory of the case's own: no tool calibration file unless the case writes one.
  char data_dir[] = "/tmp/vct-data-XXXXXX";
  if (mkdtemp(data_dir) == nullptr || setenv("ARFLEX_DATA_DIR", data_dir, 1) != 0) {
    std::fprintf(stderr, "vision_comp_test: cannot make a data directory: %s\n", std::strerror(errno));
    return 1;
  }
  if (tool_case) {
    ToolCase(name, argv[2], data_dir);
  } else {
    RunCase(name, argv[2]);
  }
  if (rmdir(data_dir) != 0) {
    std::fprintf(stderr, "leak: %s is left (%s)\n", data_dir, std::strerror(errno));
    ++failures;
  }
  if (Leaked()) ++failures;
  std::printf("vision.comp.%s: %s\n", name.c_str(), failures ? "FAIL" : "ok");
  return failures ? 1 : 0;
}
