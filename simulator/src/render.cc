#include "arflex_sim/render.h"

#include <GL/osmesa.h>

#include <cerrno>
#include <cmath>
#include <cstring>

namespace arflex {
namespace sim {

std::unique_ptr<Renderer> Renderer::Create(const mjModel* model, int width, int height,
                                           std::string* error) {
  error->clear();
  if (width < 16 || height < 16 || width > model->vis.global.offwidth ||
      height > model->vis.global.offheight) {
    *error = "render size " + std::to_string(width) + "x" + std::to_string(height) +
             " outside 16x16 .. the model's offscreen buffer " +
             std::to_string(model->vis.global.offwidth) + "x" +
             std::to_string(model->vis.global.offheight);
    return nullptr;
  }
  std::unique_ptr<Renderer> r(new Renderer());
  r->width_ = width;
  r->height_ = height;
  // The OSMesa "window" is only needed to make a context current: MuJoCo renders into its
  // own offscreen framebuffer object, sized by the model.
  OSMesaContext ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (!ctx) {
    *error = "OSMesaCreateContextExt failed (is libOSMesa installed?)";
    return nullptr;
  }
  r->osmesa_ = ctx;
  r->osmesa_buffer_.resize(static_cast<size_t>(64) * 64 * 4);
  if (!OSMesaMakeCurrent(ctx, r->osmesa_buffer_.data(), GL_UNSIGNED_BYTE, 64, 64)) {
    *error = "OSMesaMakeCurrent failed";
    return nullptr;
  }
  r->model_ = mj_copyModel(nullptr, model);
  r->data_ = mj_makeData(r->model_);
  mjv_defaultScene(&r->scene_);
  mjv_defaultCamera(&r->camera_);
  mjv_defaultOption(&r->option_);
  mjr_defaultContext(&r->context_);
  mjv_makeScene(r->model_, &r->scene_, 2000);
  r->have_scene_ = true;
  mjr_makeContext(r->model_, &r->context_, mjFONTSCALE_100);
  r->have_context_ = true;
  mjr_setBuffer(mjFB_OFFSCREEN, &r->context_);
  if (r->context_.currentBuffer != mjFB_OFFSCREEN || r->context_.offWidth < width ||
      r->context_.offHeight < height) {
    *error = "MuJoCo offscreen buffer unavailable on the OSMesa context";
    return nullptr;
  }
  r->raw_.resize(static_cast<size_t>(width) * height * 3);
  r->camera_.type = mjCAMERA_FIXED;
  r->SetState(r->model_->qpos0);
  return r;
}

bool Renderer::MakeCurrent() {
  if (!osmesa_) return false;
  return OSMesaMakeCurrent(static_cast<OSMesaContext>(osmesa_), osmesa_buffer_.data(),
                           GL_UNSIGNED_BYTE, 64, 64);
}

void Renderer::ReleaseCurrent() {
  if (osmesa_ && OSMesaGetCurrentContext() == static_cast<OSMesaContext>(osmesa_)) {
    OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
  }
}

Renderer::~Renderer() {
  // MuJoCo frees GL objects: the context must be current on this thread.
  if (osmesa_) MakeCurrent();
  if (have_context_) mjr_freeContext(&context_);
  if (have_scene_) mjv_freeScene(&scene_);
  if (data_) mj_deleteData(data_);
  if (model_) mj_deleteModel(model_);
  if (osmesa_) OSMesaDestroyContext(static_cast<OSMesaContext>(osmesa_));
}

int Renderer::FindCamera(const std::string& name) const {
  return mj_name2id(model_, mjOBJ_CAMERA, name.c_str());
}

void Renderer::SetState(const double* qpos) {
  mju_copy(data_->qpos, qpos, model_->nq);
  mj_kinematics(model_, data_);
  mj_comPos(model_, data_);
  mj_camlight(model_, data_);
}

int Renderer::Render(int camera, uint8_t* rgb, SensorEffects* effects) {
  if (camera < 0 || camera >= model_->ncam) return -EINVAL;
  camera_.fixedcamid = camera;
  mjv_updateScene(model_, data_, &option_, nullptr, &camera_, mjCAT_ALL, &scene_);
  const mjrRect viewport = {0, 0, width_, height_};
  mjr_render(viewport, &scene_, &context_);
  mjr_readPixels(raw_.data(), nullptr, viewport, &context_);
  // OpenGL rows start at the bottom.
  const size_t row = static_cast<size_t>(width_) * 3;
  for (int y = 0; y < height_; ++y) {
    std::memcpy(rgb + y * row, raw_.data() + (height_ - 1 - y) * row, row);
  }
  if (effects) ApplySensorEffects(rgb, width_, height_, effects, &work_);
  return 0;
}

CameraIntrinsics Renderer::Intrinsics(int camera) const {
  CameraIntrinsics k;
  k.width = width_;
  k.height = height_;
  const double fovy = model_->cam_fovy[camera] * 3.14159265358979323846 / 180.0;
  k.fy = 0.5 * height_ / std::tan(0.5 * fovy);
  k.fx = k.fy;
  k.cx = 0.5 * (width_ - 1);
  k.cy = 0.5 * (height_ - 1);
  return k;
}

Eigen::Isometry3d Renderer::CameraPose(int camera) const {
  // MuJoCo's camera frame: x right, y up, looking along -z. OpenCV's: x right, y down,
  // looking along +z; flip y and z.
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  const double* p = data_->cam_xpos + 3 * camera;
  const double* r = data_->cam_xmat + 9 * camera;
  Eigen::Matrix3d rot;
  for (int a = 0; a < 3; ++a) {
    rot(a, 0) = r[3 * a + 0];
    rot(a, 1) = -r[3 * a + 1];
    rot(a, 2) = -r[3 * a + 2];
  }
  t.linear() = rot;
  t.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  return t;
}

bool Renderer::Project(int camera, const Eigen::Vector3d& p, double* u, double* v) const {
  const Eigen::Vector3d c = CameraPose(camera).inverse() * p;
  if (c.z() <= 1e-9) return false;
  const CameraIntrinsics k = Intrinsics(camera);
  *u = k.cx + k.fx * c.x() / c.z();
  *v = k.cy + k.fy * c.y() / c.z();
  return true;
}

bool Renderer::TagCorners(int tag_id, std::array<Eigen::Vector3d, 4>* corners) const {
  const std::string name = "tag" + std::to_string(tag_id);
  const int g = mj_name2id(model_, mjOBJ_GEOM, name.c_str());
  if (g < 0) return false;
  const double half = model_->geom_size[3 * g] * 8.0 / 10.0;  // black border of the tag
  const double top = model_->geom_size[3 * g + 2];
  const double* p = data_->geom_xpos + 3 * g;
  const double* r = data_->geom_xmat + 9 * g;
  Eigen::Matrix3d rot;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) rot(a, b) = r[3 * a + b];
  }
  const double sx[4] = {-1, 1, 1, -1};
  const double sy[4] = {-1, -1, 1, 1};
  for (int i = 0; i < 4; ++i) {
    (*corners)[i] = Eigen::Vector3d(p[0], p[1], p[2]) +
                    rot * Eigen::Vector3d(sx[i] * half, sy[i] * half, top);
  }
  return true;
}

}  // namespace sim
}  // namespace arflex
