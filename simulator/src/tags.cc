#include "arflex_sim/tags.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>

namespace arflex {
namespace sim {

int Tag36h11TotalModules() {
  apriltag_family_t* family = tag36h11_create();
  const int total = family->total_width;
  tag36h11_destroy(family);
  return total;
}

bool Tag36h11Image(int id, int px_per_module, std::vector<uint8_t>* image) {
  image->clear();
  apriltag_family_t* family = tag36h11_create();
  if (id < 0 || static_cast<uint32_t>(id) >= family->ncodes || px_per_module < 1) {
    tag36h11_destroy(family);
    return false;
  }
  // Module grid: black everywhere, a white ring just outside the black border (the quiet
  // zone), and white modules for the 1-bits of the code. Bit i (most significant first) sits
  // at (bit_x[i], bit_y[i]) counted from the black border's top-left module.
  const int total = family->total_width;
  const int border_start = (total - family->width_at_border) / 2;
  std::vector<uint8_t> modules(static_cast<size_t>(total * total), 0);
  const int ring = border_start - 1;
  const int ring_end = total - border_start;
  for (int i = ring; i <= ring_end; ++i) {
    modules[ring * total + i] = 255;
    modules[ring_end * total + i] = 255;
    modules[i * total + ring] = 255;
    modules[i * total + ring_end] = 255;
  }
  const uint64_t code = family->codes[id];
  for (uint32_t i = 0; i < family->nbits; ++i) {
    if (code & (UINT64_C(1) << (family->nbits - i - 1))) {
      modules[(family->bit_y[i] + border_start) * total + family->bit_x[i] + border_start] = 255;
    }
  }
  const int side = total * px_per_module;
  image->resize(static_cast<size_t>(side * side));
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      (*image)[y * side + x] = modules[(y / px_per_module) * total + x / px_per_module];
    }
  }
  tag36h11_destroy(family);
  return true;
}

}  // namespace sim
}  // namespace arflex
