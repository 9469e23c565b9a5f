// The layout of the showcase cell around the arm: the four fixed cameras and the AprilTag
// markers (a reference board on the floor and four tags on the tool block). The simulator
// renders exactly this cell (DefaultCellConfig in simulator/src/params.cc); vision measures
// against it (bundles/vision/native/lib/src/cell_layout.cc). No MuJoCo.
#ifndef ARFLEX_CELLMODEL_LAYOUT_H_
#define ARFLEX_CELLMODEL_LAYOUT_H_

#include <array>
#include <string>
#include <vector>

#include "arflex_cellmodel/arm.h"

namespace arflex {
namespace cellmodel {

// A fixed camera. The pose is given as position and a point it looks at with an up hint;
// intrinsics are MuJoCo's: vertical field of view, square pixels, principal point at the
// image centre.
struct CameraSpec {
  std::string name;
  Vec3 pos;
  Vec3 look_at;
  Vec3 up = {0, 0, 1};
  double fovy_deg = 45.0;
};

// An AprilTag tag36h11 marker rendered as a textured square. `size` is the edge of the
// black border square (AprilTag's "tag size"); the rendered square is 10/8 of that because
// of the white quiet zone. `body` is "world" or one of the arm bodies ("link6", ...). The
// tag faces the +z axis of its frame, given as position and a rotation (quaternion w x y z)
// in the body frame.
struct TagSpec {
  int id;
  double size;
  std::string body;
  Vec3 pos;
  std::array<double, 4> quat = {1, 0, 0, 0};
};

// The showcase cell's four cameras around the work area (caller owns the vector).
std::vector<CameraSpec> DefaultCameras();

// The showcase cell's markers (caller owns the vector): the reference board on the floor
// (ids 0-3, body "world") and four tags on the faces of the tool block (ids 10-13, body
// "link6": the block is 0.2 x 0.18 x 0.18 m, centred 0.13 m in front of the flange).
std::vector<TagSpec> DefaultTags();

}  // namespace cellmodel
}  // namespace arflex

#endif  // ARFLEX_CELLMODEL_LAYOUT_H_
