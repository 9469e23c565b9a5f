// sim-camera: the RT half of one simulated fixed camera (simulator/README.md, "As
// components"). One instance per camera (parameter `camera`, 0..3).
//
// Every period it takes the newest `joint_state` (arflex.JointState) of sim-robot, poses the
// arm in its own private copy of the TRUE cell model (motor angles from the joint state, the
// series compliance at its static deflection for those angles and the configured payload),
// renders the camera offscreen with MuJoCo on OSMesa, applies blur and noise, and publishes
// the image in the `frames` frame port (arflex.ImageFrame header + pixels, 8-bit grey or RGB).
// A frame carries the t_ns of the joint state it shows. Rendering happens only in this
// process: sim-robot's physics never waits for it.
//
// The OSMesa context is created in configure (main thread) and handed to the RT thread in
// start; everything is allocated in configure. Note: llvmpipe itself runs worker threads and
// may allocate inside Mesa while rendering; this RT half is a soft real-time task.
#include <arflex/component.h>
#include <arflex_types/image_frame.h>
#include <arflex_types/joint_state.h>

#include <sys/resource.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "arflex_sim/cell.h"
#include "arflex_sim/params.h"
#include "arflex_sim/render.h"

namespace {

using arflex::sim::Cell;
using arflex::sim::CellConfig;
using arflex::sim::JointVector;
using arflex::sim::kNumJoints;
using arflex::sim::Renderer;

constexpr JointVector kHome = {0.0, 0.5, 0.3, 0.0, 0.8, 0.0};
constexpr uint32_t kFrameElem =
    ARFLEX_TYPE_IMAGE_FRAME_SIZE + ARFLEX_TYPE_IMAGE_FRAME_MAX_PAYLOAD;

const arflex_port_type kFrameType = {ARFLEX_TYPE_IMAGE_FRAME_NAME,
                                     ARFLEX_TYPE_IMAGE_FRAME_VERSION_MAJOR,
                                     ARFLEX_TYPE_IMAGE_FRAME_VERSION_MINOR, kFrameElem};
const arflex_port_type kJointStateType = {ARFLEX_TYPE_JOINT_STATE_NAME,
                                          ARFLEX_TYPE_JOINT_STATE_VERSION_MAJOR,
                                          ARFLEX_TYPE_JOINT_STATE_VERSION_MINOR,
                                          ARFLEX_TYPE_JOINT_STATE_SIZE};

struct Camera {
  std::unique_ptr<Cell> cell;  // private pose copy (never stepped)
  std::unique_ptr<Renderer> renderer;
  arflex_port* frames = nullptr;
  arflex_input* joint_state = nullptr;
  int camera = 0;
  bool color = false;
  int p_noise = -1, p_blur = -1;
  arflex::sim::SensorEffects effects;
  std::vector<uint8_t> rgb;
  arflex_joint_state js{};
  bool have_state = false;
  uint64_t seq = 0;
};

Camera g_cam;

int64_t ParamI(const arflex_component* c, const char* name, int64_t def) {
  const int i = arflex_component_param(c, name);
  return i < 0 ? def : arflex_param_i64(c, i);
}
double ParamD(const arflex_component* c, const char* name, double def) {
  const int i = arflex_component_param(c, name);
  return i < 0 ? def : arflex_param_f64(c, i);
}
bool ParamB(const arflex_component* c, const char* name, bool def) {
  const int i = arflex_component_param(c, name);
  return i < 0 ? def : arflex_param_bool(c, i);
}

int Configure(arflex_component* c, void* user) {
  Camera& k = *static_cast<Camera*>(user);
  int ret = arflex_component_output(c, "frames", ARFLEX_PORT_FRAME, &kFrameType, &k.frames);
  if (ret == 0) {
    ret = arflex_component_input(c, "joint_state", ARFLEX_PORT_STATE, &kJointStateType,
                                 &k.joint_state);
  }
  if (ret < 0) return ret;

  const int64_t camera = ParamI(c, "camera", 0);
  const int64_t width = ParamI(c, "width", 640);
  const int64_t height = ParamI(c, "height", 480);
  const int64_t seed = ParamI(c, "seed", 1);
  k.color = ParamB(c, "color", false);
  k.p_noise = arflex_component_param(c, "noise_sigma");
  k.p_blur = arflex_component_param(c, "blur_sigma");
  const int64_t channels = k.color ? 3 : 1;
  if (camera < 0 || camera > 3) {
    std::fprintf(stderr, "sim-camera: parameter camera = %lld outside 0..3\n",
                 static_cast<long long>(camera));
    return -ERANGE;
  }
  if (width < 16 || height < 16 || width > 1280 || height > 1024) {
    std::fprintf(stderr, "sim-camera: parameters width x height = %lld x %lld outside "
                 "16x16 .. 1280x1024\n", static_cast<long long>(width),
                 static_cast<long long>(height));
    return -ERANGE;
  }
  if (static_cast<uint64_t>(width * height * channels) > ARFLEX_TYPE_IMAGE_FRAME_MAX_PAYLOAD) {
    std::fprintf(stderr, "sim-camera: a %lldx%lld frame exceeds arflex.ImageFrame's payload\n",
                 static_cast<long long>(width), static_cast<long long>(height));
    return -EMSGSIZE;
  }
  if (seed < 0) {
    std::fprintf(stderr, "sim-camera: parameter seed = %lld must be >= 0\n",
                 static_cast<long long>(seed));
    return -ERANGE;
  }
  CellConfig config = arflex::sim::DefaultCellConfig();
  config.error_seed = static_cast<uint64_t>(seed);
  config.payload_mass = ParamD(c, "payload_kg", 0.0);
  config.nominal_payload_mass = config.payload_mass;
  std::string error;
  k.cell = Cell::Create(config, kHome, &error);
  if (!k.cell) {
    std::fprintf(stderr, "sim-camera: cannot build the cell model: %s\n", error.c_str());
    return -EINVAL;
  }
  k.renderer = Renderer::Create(k.cell->model(), static_cast<int>(width),
                                static_cast<int>(height), &error);
  if (!k.renderer) {
    std::fprintf(stderr, "sim-camera: cannot create the renderer: %s\n", error.c_str());
    k.cell.reset();
    return -EIO;
  }
  k.renderer->ReleaseCurrent();  // the RT thread takes the context in start
  k.camera = static_cast<int>(camera);
  k.effects.seed = static_cast<uint64_t>(seed) * 1000003u + static_cast<uint64_t>(camera) + 1;
  k.rgb.assign(static_cast<size_t>(width) * height * 3, 0);
  k.have_state = false;
  return 0;
}

int Start(arflex_component*, void* user) {
  Camera& k = *static_cast<Camera*>(user);
  return k.renderer->MakeCurrent() ? 0 : -EIO;
}

void Stop(arflex_component*, void* user) {
  static_cast<Camera*>(user)->renderer->ReleaseCurrent();
}

int Update(arflex_component* c, void* user, uint64_t /*release_ns*/) {
  Camera& k = *static_cast<Camera*>(user);
  arflex_joint_state js;
  if (arflex_input_state_read(k.joint_state, &js, sizeof(js), nullptr) == 1) {
    k.js = js;
    k.have_state = true;
  }
  if (!k.have_state) return 0;  // nothing to show yet: no frame without a joint state

  JointVector q;
  for (int i = 0; i < kNumJoints; ++i) q[i] = k.js.q[i];
  k.cell->ResetTo(q);  // motor angles + static compliance deflection, no stepping
  k.renderer->SetState(k.cell->qpos());
  k.effects.noise_sigma = k.p_noise >= 0 ? arflex_param_f64(c, k.p_noise) : 0.0;
  k.effects.blur_sigma = k.p_blur >= 0 ? arflex_param_f64(c, k.p_blur) : 0.0;

  const int w = k.renderer->width();
  const int h = k.renderer->height();
  const int channels = k.color ? 3 : 1;
  uint8_t* slot = static_cast<uint8_t*>(arflex_frame_begin(k.frames));
  uint8_t* pixels = slot + ARFLEX_TYPE_IMAGE_FRAME_SIZE;
  int ret = k.renderer->Render(k.camera, k.color ? pixels : k.rgb.data(), &k.effects);
  if (ret == 0 && !k.color) arflex::sim::RgbToGray(k.rgb.data(), w, h, pixels);

  arflex_image_frame hdr;
  std::memset(&hdr, 0, sizeof(hdr));
  hdr.t_ns = k.js.t_ns;  // the time of the joint state this frame shows
  hdr.seq = ++k.seq;
  hdr.camera = static_cast<uint32_t>(k.camera);
  hdr.width = static_cast<uint32_t>(w);
  hdr.height = static_cast<uint32_t>(h);
  hdr.stride = static_cast<uint32_t>(w * channels);
  hdr.format = k.color ? ARFLEX_IMAGE_FRAME_FORMAT_RGB8 : ARFLEX_IMAGE_FRAME_FORMAT_GRAY8;
  hdr.bytes = hdr.stride * hdr.height;
  std::memcpy(slot, &hdr, sizeof(hdr));
  const int commit = arflex_frame_commit(k.frames, ARFLEX_TYPE_IMAGE_FRAME_SIZE + hdr.bytes);
  return ret < 0 ? ret : commit;
}

void Cleanup(arflex_component*, void* user) {
  Camera& k = *static_cast<Camera*>(user);
  k.renderer.reset();  // makes the context current on this (main) thread to free it
  k.cell.reset();
}

}  // namespace

int main(int argc, char** argv) {
  // Best-effort work yields to everything else: rendering (llvmpipe, several threads)
  // runs at nice 19. Every thread of this process (rt-core's loop and mailbox threads, and threads libraries create later)
  // inherits it from the main thread. Without it a cell's SCHED_OTHER work starves the
  // runtime's heartbeat thread on a small machine, and the 1 ms components go to safe mode.
  if (setpriority(PRIO_PROCESS, 0, 19) != 0) {
    std::fprintf(stderr, "sim-camera: warning: setpriority(nice 19) failed: %s\n", std::strerror(errno));
  }
  arflex_component_ops ops{};
  ops.name = "sim-camera";
  ops.user = &g_cam;
  ops.configure = Configure;
  ops.start = Start;
  ops.stop = Stop;
  ops.update = Update;
  ops.cleanup = Cleanup;
  return arflex_component_main(argc, argv, &ops);
}
