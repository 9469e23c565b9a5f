// Camera frames as non-owning views, and regions of interest.
//
// Ownership: a GrayView or FrameView never owns its pixels; the caller keeps the buffer alive
// (for a frame port: the slot it holds) for as long as the view is used. Nothing here
// allocates.
#ifndef ARFLEX_VISION_IMAGE_H_
#define ARFLEX_VISION_IMAGE_H_

#include <cstdint>

namespace arflex {
namespace vision {

enum class PixelFormat : uint32_t {
  kGray8 = 1,  // one byte per pixel (arflex.ImageFrame FORMAT_GRAY8)
  kRgb8 = 2,   // three bytes per pixel, R G B (FORMAT_RGB8)
};

// A camera frame as it arrives: pixels owned by someone else, row 0 at the top, `stride`
// bytes from one row to the next.
struct FrameView {
  const uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  int stride = 0;
  PixelFormat format = PixelFormat::kGray8;
};

// A half-open pixel rectangle [x0, x1) x [y0, y1).
struct Roi {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  long area() const { return empty() ? 0 : static_cast<long>(width()) * height(); }
};

// Returns `roi` clipped to a width x height image (possibly empty).
Roi ClipRoi(const Roi& roi, int width, int height);

// Returns whether `frame` is usable: non-null data, positive size, stride large enough for
// its format.
bool FrameValid(const FrameView& frame);

// Converts the pixels of `roi` (clipped to the frame) from an RGB frame into `gray`, a
// caller-owned buffer of at least roi.area() bytes, written with stride roi.width()
// (ITU-R BT.601 weights, the simulator's convention). Does not allocate.
void RgbRoiToGray(const FrameView& frame, const Roi& roi, uint8_t* gray);

}  // namespace vision
}  // namespace arflex

#endif  // ARFLEX_VISION_IMAGE_H_
