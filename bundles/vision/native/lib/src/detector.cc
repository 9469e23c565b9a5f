#include "arflex_vision/detector.h"

#include <apriltag/apriltag.h>
#include <apriltag/common/image_u8.h>
#include <apriltag/common/zarray.h>
#include <apriltag/tag36h11.h>

#include <cerrno>
#include <algorithm>
#include <cmath>

namespace arflex {
namespace vision {
namespace {

// Bilinear grey value at (x, y) (pixel centres at integers); false outside the image.
bool Sample(const uint8_t* buf, int w, int h, int stride, double x, double y, double* v) {
  if (!(x >= 0 && y >= 0 && x <= w - 1 && y <= h - 1)) return false;
  const int x0 = std::min(static_cast<int>(x), w - 2), y0 = std::min(static_cast<int>(y), h - 2);
  const double fx = x - x0, fy = y - y0;
  const uint8_t* p = buf + static_cast<long>(y0) * stride + x0;
  *v = (1 - fy) * ((1 - fx) * p[0] + fx * p[1]) + fy * ((1 - fx) * p[stride] + fx * p[stride + 1]);
  return true;
}

// Refines the four corners `c` (region pixel coordinates, counter-clockwise) by fitting a line
// to each side of the border. Returns false (corners unchanged) if a side has too few edge
// points.
bool RefineCorners(const uint8_t* buf, int w, int h, int stride, double c[4][2]) {
  double line[4][3];  // a x + b y = d, (a, b) unit normal
  for (int e = 0; e < 4; ++e) {
    const double* p0 = c[e];
    const double* p1 = c[(e + 1) % 4];
    const double dx = p1[0] - p0[0], dy = p1[1] - p0[1];
    const double len = std::sqrt(dx * dx + dy * dy);
    if (len < 12.0) return false;
    const double ux = dx / len, uy = dy / len;
    const double nx = -uy, ny = ux;
    // The black border is one module (1/8 of the side) wide: stay within it.
    const double reach = std::min(3.0, 0.4 * len / 8.0);
    const double step = 0.25;
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    int n = 0;
    for (double t = 0.12 * len; t <= 0.88 * len; t += 1.0) {
      const double bx = p0[0] + ux * t, by = p0[1] + uy * t;
      double wsum = 0, ssum = 0, prev = 0;
      bool ok = Sample(buf, w, h, stride, bx - nx * reach, by - ny * reach, &prev);
      for (double s = -reach + step; ok && s <= reach + 1e-9; s += step) {
        double v;
        ok = Sample(buf, w, h, stride, bx + nx * s, by + ny * s, &v);
        const double g = std::abs(v - prev);
        wsum += g;
        ssum += g * (s - 0.5 * step);
        prev = v;
      }
      if (!ok || wsum < 20.0) continue;  // outside the image or no edge here
      const double off = ssum / wsum;
      const double x = bx + nx * off, y = by + ny * off;
      sx += x;
      sy += y;
      sxx += x * x;
      syy += y * y;
      sxy += x * y;
      ++n;
    }
    if (n < 6) return false;
    const double mx = sx / n, my = sy / n;
    const double cxx = sxx / n - mx * mx, cyy = syy / n - my * my, cxy = sxy / n - mx * my;
    // Line direction = principal axis of the edge points; normal = the other axis.
    const double theta = 0.5 * std::atan2(2 * cxy, cxx - cyy);
    const double a = -std::sin(theta), b = std::cos(theta);
    line[e][0] = a;
    line[e][1] = b;
    line[e][2] = a * mx + b * my;
  }
  double out[4][2];
  for (int k = 0; k < 4; ++k) {
    // Corner k lies on side k-1 (ending at it) and side k (starting at it).
    const double* l0 = line[(k + 3) % 4];
    const double* l1 = line[k];
    const double det = l0[0] * l1[1] - l0[1] * l1[0];
    if (std::abs(det) < 1e-6) return false;
    out[k][0] = (l0[2] * l1[1] - l0[1] * l1[2]) / det;
    out[k][1] = (l0[0] * l1[2] - l0[2] * l1[0]) / det;
    const double mx = out[k][0] - c[k][0], my = out[k][1] - c[k][1];
    if (mx * mx + my * my > 4.0) return false;  // more than 2 px away: do not trust it
  }
  for (int k = 0; k < 4; ++k) {
    c[k][0] = out[k][0];
    c[k][1] = out[k][1];
  }
  return true;
}

}  // namespace

std::unique_ptr<TagDetector> TagDetector::Create(const DetectorOptions& options,
                                                 std::string* error) {
  auto fail = [error](const std::string& what) -> std::unique_ptr<TagDetector> {
    if (error) *error = "vision detector: " + what;
    return nullptr;
  };
  if (options.max_width <= 0 || options.max_height <= 0 || options.max_width > 8192 ||
      options.max_height > 8192) {
    return fail("max_width/max_height must be in 1..8192 (got " +
                std::to_string(options.max_width) + "x" + std::to_string(options.max_height) +
                ")");
  }
  if (!(options.quad_decimate >= 1.0f) || options.quad_decimate > 8.0f) {
    return fail("quad_decimate must be in [1, 8] (got " + std::to_string(options.quad_decimate) +
                ")");
  }
  if (!(options.quad_sigma >= 0.0f)) return fail("quad_sigma must be >= 0");
  if (options.nthreads < 1 || options.nthreads > 16) return fail("nthreads must be in 1..16");
  if (options.max_hamming < 0 || options.max_hamming > 2) return fail("max_hamming must be in 0..2");
  std::unique_ptr<TagDetector> d(new TagDetector());
  d->options_ = options;
  d->family_ = tag36h11_create();
  d->detector_ = apriltag_detector_create();
  if (d->family_ == nullptr || d->detector_ == nullptr) return fail("libapriltag create failed");
  apriltag_detector_add_family_bits(d->detector_, d->family_, options.max_hamming);
  d->detector_->quad_decimate = options.quad_decimate;
  d->detector_->quad_sigma = options.quad_sigma;
  d->detector_->nthreads = options.nthreads;
  d->detector_->refine_edges = true;
  d->gray_.reset(new uint8_t[static_cast<size_t>(options.max_width) * options.max_height]);
  return d;
}

TagDetector::~TagDetector() {
  if (detector_ != nullptr) apriltag_detector_destroy(detector_);
  if (family_ != nullptr) tag36h11_destroy(family_);
}

int TagDetector::Detect(const FrameView& frame, const Roi* rois, int nroi, TagDetection* out,
                        int capacity, DetectStats* stats) {
  DetectStats local;
  DetectStats* s = stats != nullptr ? stats : &local;
  *s = DetectStats{};
  if (!FrameValid(frame) || nroi < 0 || (nroi > 0 && rois == nullptr) || capacity < 0 ||
      (capacity > 0 && out == nullptr)) {
    return -EINVAL;
  }
  if (frame.width > options_.max_width || frame.height > options_.max_height) return -EINVAL;
  int count = 0;
  if (nroi == 0) {
    count = DetectRegion(frame, Roi{0, 0, frame.width, frame.height}, out, count, capacity, s);
  } else {
    for (int i = 0; i < nroi; ++i) {
      const Roi r = ClipRoi(rois[i], frame.width, frame.height);
      // AprilTag needs some room around a quad; tiny regions cannot hold a tag.
      if (r.width() < 16 || r.height() < 16) continue;
      count = DetectRegion(frame, r, out, count, capacity, s);
    }
  }
  s->kept = count;
  return count;
}

int TagDetector::DetectRegion(const FrameView& frame, const Roi& roi, TagDetection* out,
                              int count, int capacity, DetectStats* stats) {
  ++stats->rois;
  stats->pixels += roi.area();
  uint8_t* buf;
  int stride;
  if (frame.format == PixelFormat::kGray8) {
    // A sub-image view of the caller's frame: no copy. libapriltag only reads it.
    buf = const_cast<uint8_t*>(frame.data) + static_cast<long>(roi.y0) * frame.stride + roi.x0;
    stride = frame.stride;
  } else {
    RgbRoiToGray(frame, roi, gray_.get());
    buf = gray_.get();
    stride = roi.width();
  }
  image_u8_t im = {roi.width(), roi.height(), stride, buf};
  zarray_t* dets = apriltag_detector_detect(detector_, &im);  // owned here, destroyed below
  const int n = zarray_size(dets);
  stats->raw_detections += n;
  for (int i = 0; i < n; ++i) {
    apriltag_detection_t* d;
    zarray_get(dets, i, &d);
    if (d->hamming > options_.max_hamming || d->decision_margin < options_.min_decision_margin) {
      continue;
    }
    bool seen = false;
    for (int j = 0; j < count; ++j) seen = seen || out[j].id == d->id;
    if (seen) continue;
    if (count >= capacity) {
      ++stats->dropped_capacity;
      continue;
    }
    TagDetection& t = out[count++];
    t.id = d->id;
    t.hamming = d->hamming;
    t.decision_margin = d->decision_margin;
    // AprilTag's pixel coordinates put pixel centres at +0.5; ours at 0.
    double c[4][2];
    for (int k = 0; k < 4; ++k) {
      c[k][0] = d->p[k][0] - 0.5;
      c[k][1] = d->p[k][1] - 0.5;
    }
    if (options_.refine_corners) RefineCorners(buf, roi.width(), roi.height(), stride, c);
    for (int k = 0; k < 4; ++k) {
      t.corners[k][0] = c[k][0] + roi.x0;
      t.corners[k][1] = c[k][1] + roi.y0;
    }
    t.center[0] = d->c[0] - 0.5 + roi.x0;
    t.center[1] = d->c[1] - 0.5 + roi.y0;
  }
  apriltag_detections_destroy(dets);
  return count;
}

}  // namespace vision
}  // namespace arflex
