#include "arflex_vision/cell_layout.h"

#include <string>

#include "arflex_cellmodel/layout.h"

namespace arflex {
namespace vision {
namespace {

TagModel Tag(const cellmodel::TagSpec& spec) {
  TagModel t;
  t.id = spec.id;
  t.size = spec.size;
  t.pose = Eigen::Isometry3d::Identity();
  t.pose.linear() =
      Eigen::Quaterniond(spec.quat[0], spec.quat[1], spec.quat[2], spec.quat[3]).toRotationMatrix();
  t.pose.translation() = Eigen::Vector3d(spec.pos[0], spec.pos[1], spec.pos[2]);
  t.pose.translate(Eigen::Vector3d(0, 0, 0.0005));  // printed on the top face of the box
  return t;
}

std::vector<TagModel> TagsOn(const std::string& body) {
  std::vector<TagModel> tags;
  for (const cellmodel::TagSpec& spec : cellmodel::DefaultTags()) {
    if (spec.body == body) tags.push_back(Tag(spec));
  }
  return tags;
}

}  // namespace

std::vector<TagModel> CellBoardTags() { return TagsOn("world"); }

std::vector<TagModel> CellToolTags() { return TagsOn("link6"); }

}  // namespace vision
}  // namespace arflex
