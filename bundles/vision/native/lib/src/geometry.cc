#include "arflex_vision/geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace arflex {
namespace vision {

std::array<Eigen::Vector3d, 4> TagCornerPoints(const TagModel& tag, double surface) {
  const double h = 0.5 * tag.size;
  const double sx[4] = {-1, 1, 1, -1};
  const double sy[4] = {-1, -1, 1, 1};
  std::array<Eigen::Vector3d, 4> c;
  for (int i = 0; i < 4; ++i) c[i] = tag.pose * Eigen::Vector3d(sx[i] * h, sy[i] * h, surface);
  return c;
}

bool Project(const Camera& camera, const Eigen::Vector3d& p, Eigen::Vector2d* uv) {
  const Eigen::Vector3d c = camera.world_from_camera.inverse() * p;
  if (c.z() <= 1e-6) return false;
  (*uv)(0) = camera.k.cx + camera.k.fx * c.x() / c.z();
  (*uv)(1) = camera.k.cy + camera.k.fy * c.y() / c.z();
  return true;
}

Roi PredictRoi(const Camera& camera, const Eigen::Isometry3d& object_pose,
               const std::vector<TagModel>& tags, double margin_px) {
  double u0 = std::numeric_limits<double>::infinity(), v0 = u0;
  double u1 = -u0, v1 = -u0;
  bool any = false;
  for (const TagModel& tag : tags) {
    for (const Eigen::Vector3d& p : TagCornerPoints(tag)) {
      Eigen::Vector2d uv;
      if (!Project(camera, object_pose * p, &uv)) continue;
      any = true;
      u0 = std::min(u0, uv(0));
      v0 = std::min(v0, uv(1));
      u1 = std::max(u1, uv(0));
      v1 = std::max(v1, uv(1));
    }
  }
  if (!any) return Roi{};
  // Keep the numbers in int range before converting (a point near the camera plane projects
  // far away).
  const double lim = 1e6;
  auto clampd = [lim](double x) { return std::max(-lim, std::min(lim, x)); };
  Roi r{static_cast<int>(std::floor(clampd(u0 - margin_px))),
        static_cast<int>(std::floor(clampd(v0 - margin_px))),
        static_cast<int>(std::ceil(clampd(u1 + margin_px))) + 1,
        static_cast<int>(std::ceil(clampd(v1 + margin_px))) + 1};
  return ClipRoi(r, camera.k.width, camera.k.height);
}

}  // namespace vision
}  // namespace arflex
