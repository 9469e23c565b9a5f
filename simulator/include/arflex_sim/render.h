// Offscreen rendering of the cell's fixed cameras with MuJoCo's renderer on an OSMesa
// context (headless, software), plus the camera model (intrinsics, pose, projection) and the
// sensor effects (Gaussian noise, optional Gaussian blur).
//
// Threading: a Renderer owns an OSMesa context that is current on the thread that created
// it; create and use it on one thread (a render thread). It owns a copy of the model and its
// own mjData, and renders from a qpos vector the caller copied from the physics thread, so
// rendering never touches the Cell's data and never stalls physics.
#ifndef ARFLEX_SIM_RENDER_H_
#define ARFLEX_SIM_RENDER_H_

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace arflex {
namespace sim {

// Pinhole intrinsics in pixels, OpenCV convention: pixel (0, 0) is the centre of the top-left
// pixel, u to the right, v down. fx = fy = (height / 2) / tan(fovy / 2),
// cx = (width - 1) / 2, cy = (height - 1) / 2.
struct CameraIntrinsics {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
};

struct SensorEffects {
  double noise_sigma = 0.0;  // Gaussian noise, grey levels (0..255) per channel
  double blur_sigma = 0.0;   // Gaussian blur, pixels (0 = off); applied before the noise
  uint64_t seed = 1;         // noise generator seed (advances with every frame)
};

class Renderer {
 public:
  // Creates an OSMesa context current on this thread and MuJoCo's render context for a copy
  // of `model` (the Cell's TRUE model, textures included). `width` x `height` must not exceed
  // the model's offscreen buffer (visual/global offwidth, offheight). Returns nullptr and sets
  // `*error` on failure.
  static std::unique_ptr<Renderer> Create(const mjModel* model, int width, int height,
                                          std::string* error);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Makes the OSMesa context current on the calling thread / releases it from the calling
  // thread. A Renderer created on one thread (e.g. an RT half's configure hook) can be handed
  // to another (its RT thread): ReleaseCurrent() on the first, MakeCurrent() on the second.
  // The destructor makes the context current on the destroying thread itself.
  bool MakeCurrent();
  void ReleaseCurrent();

  int width() const { return width_; }
  int height() const { return height_; }
  int camera_count() const { return model_->ncam; }
  // Camera index by name, -1 if unknown.
  int FindCamera(const std::string& name) const;

  // Sets the arm state to render: copies model->nq values from `qpos` (the caller copied them
  // from the physics thread) and computes the kinematics.
  void SetState(const double* qpos);

  // Renders camera `camera` at the state given by SetState() into `rgb` (width*height*3
  // bytes, caller-owned, row 0 at the top), applying `effects`. Returns 0, or -EINVAL for a
  // bad camera index.
  int Render(int camera, uint8_t* rgb, SensorEffects* effects);

  CameraIntrinsics Intrinsics(int camera) const;
  // Pose of the camera in the world, OpenCV convention (x right, y down, z forward).
  Eigen::Isometry3d CameraPose(int camera) const;
  // Projects world point `p` into camera `camera`; false if behind the camera.
  bool Project(int camera, const Eigen::Vector3d& p, double* u, double* v) const;
  // World coordinates of the four corners of the black border of tag `tag_id` at the current
  // state (on the tag's visible face), in the order (-,-), (+,-), (+,+), (-,+) of the tag
  // geom's x and y axes. False if the tag is not in the model.
  bool TagCorners(int tag_id, std::array<Eigen::Vector3d, 4>* corners) const;

 private:
  Renderer() = default;
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  void* osmesa_ = nullptr;
  std::vector<uint8_t> osmesa_buffer_;
  mjvScene scene_;
  mjvCamera camera_;
  mjvOption option_;
  mjrContext context_;
  bool have_scene_ = false;
  bool have_context_ = false;
  int width_ = 0;
  int height_ = 0;
  std::vector<uint8_t> raw_;
  std::vector<float> work_;
};

// Applies `effects` to an RGB image in place (blur, then noise). Exposed for tests.
void ApplySensorEffects(uint8_t* rgb, int width, int height, SensorEffects* effects,
                        std::vector<float>* work);

// Converts RGB (row-major, 3 bytes per pixel) to 8-bit luma (ITU-R BT.601 weights).
void RgbToGray(const uint8_t* rgb, int width, int height, uint8_t* gray);

// Writes an 8-bit image (channels 1 or 3) as an uncompressed PNG. Returns false on I/O error.
bool WritePng(const std::string& path, const uint8_t* pixels, int width, int height,
              int channels);

}  // namespace sim
}  // namespace arflex

#endif  // ARFLEX_SIM_RENDER_H_
