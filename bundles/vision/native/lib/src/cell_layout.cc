#include "arflex_vision/cell_layout.h"

namespace arflex {
namespace vision {
namespace {

TagModel Tag(int id, double size, const Eigen::Vector3d& pos, const Eigen::Quaterniond& q) {
  TagModel t;
  t.id = id;
  t.size = size;
  t.pose = Eigen::Isometry3d::Identity();
  t.pose.linear() = q.toRotationMatrix();
  t.pose.translation() = pos;
  t.pose.translate(Eigen::Vector3d(0, 0, 0.0005));  // printed on the top face of the box
  return t;
}

}  // namespace

std::vector<TagModel> CellBoardTags() {
  const Eigen::Quaterniond up = Eigen::Quaterniond::Identity();
  return {Tag(0, 0.24, {1.40, 0.70, 0.002}, up), Tag(1, 0.24, {2.30, 0.70, 0.002}, up),
          Tag(2, 0.24, {1.40, -0.70, 0.002}, up), Tag(3, 0.24, {2.30, -0.70, 0.002}, up)};
}

std::vector<TagModel> CellToolTags() {
  const double s = 0.7071067811865476;
  return {Tag(10, 0.13, {0.13, 0.0, 0.0915}, Eigen::Quaterniond(1, 0, 0, 0)),
          Tag(11, 0.13, {0.13, 0.0915, 0.0}, Eigen::Quaterniond(s, -s, 0, 0)),
          Tag(12, 0.13, {0.13, -0.0915, 0.0}, Eigen::Quaterniond(s, s, 0, 0)),
          Tag(13, 0.13, {0.13, 0.0, -0.0915}, Eigen::Quaterniond(0, 1, 0, 0))};
}

}  // namespace vision
}  // namespace arflex
