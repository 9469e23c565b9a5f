// Test helper: draws tag36h11 markers into a grey image through the pinhole model (a
// homography per tag), so that the true corner positions are known exactly.
#ifndef ARFLEX_VISION_TESTS_SYNTHETIC_SCENE_H_
#define ARFLEX_VISION_TESTS_SYNTHETIC_SCENE_H_

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>

#include <array>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "arflex_vision/geometry.h"

namespace arflex {
namespace vision {
namespace testing {

// A camera at `pos` looking at `at`, fovy 50 degrees as the cell's cameras.
inline Camera LookAt(const Eigen::Vector3d& pos, const Eigen::Vector3d& at, int w, int h) {
  Camera c;
  c.k.width = w;
  c.k.height = h;
  c.k.fy = c.k.fx = 0.5 * h / std::tan(25.0 * M_PI / 180.0);
  c.k.cx = 0.5 * (w - 1);
  c.k.cy = 0.5 * (h - 1);
  const Eigen::Vector3d z = (at - pos).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  c.world_from_camera.linear().col(0) = x;
  c.world_from_camera.linear().col(1) = y;
  c.world_from_camera.linear().col(2) = z;
  c.world_from_camera.translation() = pos;
  c.calibrated = true;
  return c;
}

// The four cameras of the cell.
inline std::vector<Camera> CellCameras(int w, int h) {
  const Eigen::Vector3d at(1.8, 0, 0.5);
  return {LookAt({3.6, 1.6, 2.6}, at, w, h), LookAt({3.6, -1.6, 2.6}, at, w, h),
          LookAt({0.6, 2.2, 2.6}, at, w, h), LookAt({0.6, -2.2, 2.6}, at, w, h)};
}

class SceneDrawer {
 public:
  SceneDrawer() : family_(tag36h11_create()) {}
  ~SceneDrawer() { tag36h11_destroy(family_); }
  SceneDrawer(const SceneDrawer&) = delete;
  SceneDrawer& operator=(const SceneDrawer&) = delete;

  // Draws tag `tag` of an object at `object_pose` into `image` (CV_8UC1) if it faces the
  // camera and lies in front of it. Returns whether it was drawn.
  bool Draw(const Camera& cam, const TagModel& tag, const Eigen::Isometry3d& object_pose,
            cv::Mat* image) {
    const Eigen::Isometry3d world = object_pose * tag.pose;
    const Eigen::Vector3d eye = cam.world_from_camera.translation();
    if (world.linear().col(2).dot((eye - world.translation()).normalized()) < 0.15) return false;
    // The quiet zone too: the tag image is 10 modules, the black border 8.
    TagModel outer = tag;
    outer.size = tag.size * 10.0 / 8.0;
    const auto corners = TagCornerPoints(outer);
    std::vector<cv::Point2f> dst;
    for (const auto& p : corners) {
      Eigen::Vector2d uv;
      if (!Project(cam, object_pose * p, &uv)) return false;
      dst.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
    }
    image_u8_t* im = apriltag_to_image(family_, tag.id);  // owned here
    const int scale = 24;
    cv::Mat small(im->height, im->width, CV_8UC1, im->buf, im->stride);
    cv::Mat big;
    cv::resize(small, big, cv::Size(), scale, scale, cv::INTER_NEAREST);
    image_u8_destroy(im);
    // Edge coordinates of the whole tag image (pixel centres at integers): -0.5 .. n-0.5.
    const float e = static_cast<float>(big.cols) - 0.5f;
    // Tag x to the right, tag y up in the printed image (the simulator's texture mapping).
    const std::vector<cv::Point2f> src = {{-0.5f, e}, {e, e}, {e, -0.5f}, {-0.5f, -0.5f}};
    const cv::Mat h = cv::getPerspectiveTransform(src, dst);
    cv::Mat warped, mask;
    cv::warpPerspective(big, warped, h, image->size(), cv::INTER_AREA, cv::BORDER_CONSTANT, 0);
    cv::warpPerspective(cv::Mat(big.size(), CV_8UC1, cv::Scalar(255)), mask, h, image->size(),
                        cv::INTER_AREA, cv::BORDER_CONSTANT, 0);
    // Blend by the (anti-aliased) coverage.
    for (int y = 0; y < image->rows; ++y) {
      uint8_t* out = image->ptr<uint8_t>(y);
      const uint8_t* w = warped.ptr<uint8_t>(y);
      const uint8_t* m = mask.ptr<uint8_t>(y);
      for (int x = 0; x < image->cols; ++x) {
        if (m[x] == 0) continue;
        out[x] = static_cast<uint8_t>((w[x] * 255 + out[x] * (255 - m[x]) + 127) / 255);
      }
    }
    return true;
  }

 private:
  apriltag_family_t* family_;
};

}  // namespace testing
}  // namespace vision
}  // namespace arflex

#endif  // ARFLEX_VISION_TESTS_SYNTHETIC_SCENE_H_
