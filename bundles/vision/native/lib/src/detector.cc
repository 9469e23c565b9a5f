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

// Distance of point p from the line through a and b.
double LineDistance(const double* a, const double* b, const double* p) {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double len = std::sqrt(dx * dx + dy * dy);
  return len > 0 ? std::abs((p[0] - a[0]) * dy - (p[1] - a[1]) * dx) / len : 0.0;
}

// Refines the four corners `c` (region pixel coordinates, counter-clockwise) by fitting a line
// to each side of the black border and intersecting neighbouring lines. Every pixel along a
// side gives one edge point: the centroid of the grey-level gradient magnitude on a profile
// across the edge. The profile stays within half a module of the edge on both sides (the
// border and the white ring around it are one module wide; the module width ACROSS the edge
// is measured from the opposite side, so it shrinks with foreshortening), and it is re-centred
// on the fitted line and measured again (a truncated window that is not centred on a
// symmetric edge pulls the centroid towards its own centre). Writes the RMS distance of the
// edge points from their lines (largest of the four sides) to `*scatter_px`: the local
// consistency of the edge, large where the border is too thin in the image to be resolved.
// Returns false (corners unchanged) if a side has too few edge points.
bool RefineCorners(const uint8_t* buf, int w, int h, int stride, double c[4][2],
                   double* scatter_px) {
  double line[4][3];  // a x + b y = d, (a, b) unit normal
  double reach[4];
  for (int e = 0; e < 4; ++e) {
    const double* p0 = c[e];
    const double* p1 = c[(e + 1) % 4];
    const double dx = p1[0] - p0[0], dy = p1[1] - p0[1];
    const double len = std::sqrt(dx * dx + dy * dy);
    if (len < 12.0) return false;
    // Module width across this side: the tag's extent perpendicular to it over 8 modules.
    const double across = std::min(LineDistance(p0, p1, c[(e + 2) % 4]),
                                   LineDistance(p0, p1, c[(e + 3) % 4]));
    reach[e] = std::min(3.0, 0.5 * across / 8.0);
    if (reach[e] < 0.5) return false;  // border under a pixel wide: nothing to refine with
    const double nx = -dy / len, ny = dx / len;
    line[e][0] = nx;
    line[e][1] = ny;
    line[e][2] = nx * p0[0] + ny * p0[1];
  }
  double worst_scatter = 0.0;
  const double step = 0.25;
  for (int pass = 0; pass < 3; ++pass) {
    double next[4][3];
    for (int e = 0; e < 4; ++e) {
      // The side's extent: between its corners (intersections with the neighbouring lines).
      double ends[2][2];
      for (int k = 0; k < 2; ++k) {
        const double* l0 = line[(e + 3 + k) % 4];
        const double* l1 = line[(e + k) % 4];
        const double det = l0[0] * l1[1] - l0[1] * l1[0];
        if (std::abs(det) < 1e-6) return false;
        ends[k][0] = (l0[2] * l1[1] - l0[1] * l1[2]) / det;
        ends[k][1] = (l0[0] * l1[2] - l0[2] * l1[0]) / det;
      }
      const double nx = line[e][0], ny = line[e][1];
      const double dx = ends[1][0] - ends[0][0], dy = ends[1][1] - ends[0][1];
      const double len = std::sqrt(dx * dx + dy * dy);
      if (len < 12.0) return false;
      const double ux = dx / len, uy = dy / len;
      const double r = reach[e];
      double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
      int n = 0;
      for (double t = 0.12 * len; t <= 0.88 * len; t += 1.0) {
        // The point on the current line at parameter t.
        const double bx = ends[0][0] + ux * t, by = ends[0][1] + uy * t;
        const double off0 = line[e][2] - (nx * bx + ny * by);  // ~0: bx, by is on the line
        double wsum = 0, ssum = 0, prev = 0;
        bool ok = Sample(buf, w, h, stride, bx + nx * (off0 - r), by + ny * (off0 - r), &prev);
        for (double s = -r + step; ok && s <= r + 1e-9; s += step) {
          double v;
          ok = Sample(buf, w, h, stride, bx + nx * (off0 + s), by + ny * (off0 + s), &v);
          const double g = std::abs(v - prev);
          wsum += g;
          ssum += g * (s - 0.5 * step);
          prev = v;
        }
        if (!ok || wsum < 20.0) continue;  // outside the image or no edge here
        const double off = off0 + ssum / wsum;
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
      // Line direction = principal axis of the edge points; normal = the other axis, oriented
      // as the current normal.
      const double theta = 0.5 * std::atan2(2 * cxy, cxx - cyy);
      double a = -std::sin(theta), b = std::cos(theta);
      if (a * nx + b * ny < 0) {
        a = -a;
        b = -b;
      }
      next[e][0] = a;
      next[e][1] = b;
      next[e][2] = a * mx + b * my;
      // Variance across the line: the smaller eigenvalue of the scatter matrix.
      const double tr = cxx + cyy, dif = cxx - cyy;
      const double minor = 0.5 * (tr - std::sqrt(dif * dif + 4 * cxy * cxy));
      if (pass == 2) worst_scatter = std::max(worst_scatter, std::sqrt(std::max(0.0, minor)));
    }
    for (int e = 0; e < 4; ++e) {
      for (int k = 0; k < 3; ++k) line[e][k] = next[e][k];
    }
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
  *scatter_px = worst_scatter;
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
    t.refined = false;
    t.edge_scatter_px = 0.0;
    if (options_.refine_corners) {
      t.refined = RefineCorners(buf, roi.width(), roi.height(), stride, c, &t.edge_scatter_px);
    }
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
