#include "arflex_vision/image.h"

#include <algorithm>

namespace arflex {
namespace vision {

Roi ClipRoi(const Roi& roi, int width, int height) {
  Roi r;
  r.x0 = std::max(0, roi.x0);
  r.y0 = std::max(0, roi.y0);
  r.x1 = std::min(width, roi.x1);
  r.y1 = std::min(height, roi.y1);
  if (r.empty()) r = Roi{};
  return r;
}

bool FrameValid(const FrameView& frame) {
  if (frame.data == nullptr || frame.width <= 0 || frame.height <= 0) return false;
  const int bpp = frame.format == PixelFormat::kRgb8 ? 3 : 1;
  if (frame.format != PixelFormat::kRgb8 && frame.format != PixelFormat::kGray8) return false;
  return frame.stride >= frame.width * bpp;
}

void RgbRoiToGray(const FrameView& frame, const Roi& roi, uint8_t* gray) {
  const Roi r = ClipRoi(roi, frame.width, frame.height);
  const int w = r.width();
  for (int y = r.y0; y < r.y1; ++y) {
    const uint8_t* src = frame.data + static_cast<long>(y) * frame.stride + 3L * r.x0;
    uint8_t* dst = gray + static_cast<long>(y - r.y0) * w;
    for (int x = 0; x < w; ++x) {
      const int v = 299 * src[3 * x] + 587 * src[3 * x + 1] + 114 * src[3 * x + 2];
      dst[x] = static_cast<uint8_t>((v + 500) / 1000);
    }
  }
}

}  // namespace vision
}  // namespace arflex
