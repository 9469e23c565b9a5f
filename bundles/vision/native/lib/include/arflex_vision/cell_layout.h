// The marker layout of the showcase cell as vision's tag models, from the cell model
// (cellmodel/include/arflex_cellmodel/layout.h, DefaultTags; the simulator renders the same
// tags): four 0.24 m reference-board tags on the floor (ids 0-3, poses in the cell frame) and four
// 0.13 m tags on the faces of the tool block (ids 10-13, poses in the flange frame). The
// printed face of each tag is 0.5 mm above its box centre.
#ifndef ARFLEX_VISION_CELL_LAYOUT_H_
#define ARFLEX_VISION_CELL_LAYOUT_H_

#include <vector>

#include "arflex_vision/geometry.h"

namespace arflex {
namespace vision {

// Returns the reference board (caller owns the vector).
std::vector<TagModel> CellBoardTags();
// Returns the tool-block tags in the flange frame (caller owns the vector).
std::vector<TagModel> CellToolTags();

}  // namespace vision
}  // namespace arflex

#endif  // ARFLEX_VISION_CELL_LAYOUT_H_
