#include "arflex_vision/detector.h"

#include <apriltag/apriltag.h>
#include <apriltag/common/image_u8.h>
#include <apriltag/common/zarray.h>
#include <apriltag/tag36h11.h>

#include <cerrno>
#include <cmath>

namespace arflex {
namespace vision {

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
    for (int k = 0; k < 4; ++k) {
      t.corners[k][0] = d->p[k][0] - 0.5 + roi.x0;
      t.corners[k][1] = d->p[k][1] - 0.5 + roi.y0;
    }
    t.center[0] = d->c[0] - 0.5 + roi.x0;
    t.center[1] = d->c[1] - 0.5 + roi.y0;
  }
  apriltag_detections_destroy(dets);
  return count;
}

}  // namespace vision
}  // namespace arflex
