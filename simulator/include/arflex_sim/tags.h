// AprilTag tag36h11 marker images generated from libapriltag's family codes.
#ifndef ARFLEX_SIM_TAGS_H_
#define ARFLEX_SIM_TAGS_H_

#include <cstdint>
#include <vector>

namespace arflex {
namespace sim {

// Number of modules across a tag36h11 image including the white quiet zone (10).
int Tag36h11TotalModules();

// Writes the tag36h11 marker `id` as an 8-bit grey image, row 0 at the top as printed,
// `px_per_module` pixels per module, black = 0, white = 255, with a one-module white
// border (AprilTag's layout). Returns false and leaves `image` empty if `id` is not in the
// family or px_per_module < 1. The caller owns `image`.
bool Tag36h11Image(int id, int px_per_module, std::vector<uint8_t>* image);

}  // namespace sim
}  // namespace arflex

#endif  // ARFLEX_SIM_TAGS_H_
