#include "arflex_cellmodel/layout.h"

namespace arflex {
namespace cellmodel {

std::vector<CameraSpec> DefaultCameras() {
  const Vec3 target = {1.8, 0.0, 0.5};
  return {
      {"cam_front_left", {3.6, 1.6, 2.6}, target, {0, 0, 1}, 50.0},
      {"cam_front_right", {3.6, -1.6, 2.6}, target, {0, 0, 1}, 50.0},
      {"cam_back_left", {0.6, 2.2, 2.6}, target, {0, 0, 1}, 50.0},
      {"cam_back_right", {0.6, -2.2, 2.6}, target, {0, 0, 1}, 50.0},
  };
}

std::vector<TagSpec> DefaultTags() {
  // Quaternions turn the tag's +z normal to the block's +z, +y, -y and -z faces.
  const double s = 0.7071067811865476;
  return {
      {0, 0.24, "world", {1.40, 0.70, 0.002}},
      {1, 0.24, "world", {2.30, 0.70, 0.002}},
      {2, 0.24, "world", {1.40, -0.70, 0.002}},
      {3, 0.24, "world", {2.30, -0.70, 0.002}},
      {10, 0.13, "link6", {0.13, 0.0, 0.0915}},
      {11, 0.13, "link6", {0.13, 0.0915, 0.0}, {s, -s, 0, 0}},
      {12, 0.13, "link6", {0.13, -0.0915, 0.0}, {s, s, 0, 0}},
      {13, 0.13, "link6", {0.13, 0.0, -0.0915}, {0, 1, 0, 0}},
  };
}

}  // namespace cellmodel
}  // namespace arflex
