// Camera model, tag layouts and the projections the estimator and the ROI tracker share.
// Plain values, no allocation beyond the caller's containers.
#ifndef ARFLEX_VISION_GEOMETRY_H_
#define ARFLEX_VISION_GEOMETRY_H_

#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "arflex_vision/image.h"

namespace arflex {
namespace vision {

// Pinhole intrinsics (no distortion), OpenCV convention: the centre of the top-left pixel is
// (0, 0), u right, v down.
struct Intrinsics {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
};

// A camera: intrinsics (known) and its pose in the cell (world) frame, OpenCV axes (x right,
// y down, z forward). `calibrated` is false until an extrinsic calibration succeeded.
struct Camera {
  Intrinsics k;
  Eigen::Isometry3d world_from_camera = Eigen::Isometry3d::Identity();
  bool calibrated = false;
  double calibration_rms_px = 0.0;  // reprojection RMS of the last calibration
};

// A square tag36h11 marker rigidly attached to a frame (the world for the reference board,
// the marker block / flange for the tool). `size` is the edge of the black border; the tag
// lies in the x-y plane of `pose` and faces its +z axis.
struct TagModel {
  int id = -1;
  double size = 0.0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

// The four corners of `tag` in its parent frame, in AprilTag's detection order
// ((-,-), (+,-), (+,+), (-,+) of the tag's x and y), on the plane z = `surface` of the tag.
std::array<Eigen::Vector3d, 4> TagCornerPoints(const TagModel& tag, double surface = 0.0);

// Projects the world point `p` into `camera`. Returns false if it is behind the camera.
bool Project(const Camera& camera, const Eigen::Vector3d& p, Eigen::Vector2d* uv);

// The region of `camera`'s image that should contain the tags `tags` of an object at the
// world pose `object_pose`, grown by `margin_px` and clipped to the image; empty if no tag
// corner projects in front of the camera or the box lies outside the image.
Roi PredictRoi(const Camera& camera, const Eigen::Isometry3d& object_pose,
               const std::vector<TagModel>& tags, double margin_px);

}  // namespace vision
}  // namespace arflex

#endif  // ARFLEX_VISION_GEOMETRY_H_
