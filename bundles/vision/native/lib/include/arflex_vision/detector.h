// AprilTag tag36h11 detection on camera frames, restricted to regions of interest.
//
// Ownership (AprilTag's habit, stated per function): TagDetector::Create returns a detector
// owned by the caller (a unique_ptr; destroying it releases libapriltag's detector and
// family). Detect() writes into caller-owned storage and keeps no reference to the frame.
//
// Allocation: the detector's grey conversion buffer is allocated in Create() for the largest
// frame it will see; Detect() itself does not allocate, but libapriltag allocates internally
// during detection (its zarrays, quads and the detections it returns, all freed before
// Detect() returns). Callers with a no-allocation rule run Detect() off the RT thread.
#ifndef ARFLEX_VISION_DETECTOR_H_
#define ARFLEX_VISION_DETECTOR_H_

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "arflex_vision/image.h"

struct apriltag_detector;
struct apriltag_family;

namespace arflex {
namespace vision {

// One detected tag. Corners are in full-frame pixel coordinates, OpenCV convention (the
// centre of the top-left pixel is (0, 0); AprilTag's +0.5 px offset is removed), in
// AprilTag's order: counter-clockwise, starting at the tag's (-1, -1) corner of its own
// frame as seen in the image (the same order arflex_sim's Renderer::TagCorners uses).
struct TagDetection {
  int id = -1;
  int hamming = 0;
  float decision_margin = 0.0f;
  std::array<std::array<double, 2>, 4> corners{};
  std::array<double, 2> center{};
  // Whether the corner re-fit succeeded (otherwise the corners are AprilTag's own), and the
  // RMS distance of the re-fit's edge points from their fitted side (the worst side, px): a
  // measure of how well the border is resolved (large for tags seen very obliquely).
  bool refined = false;
  double edge_scatter_px = 0.0;
};

struct DetectorOptions {
  int max_width = 1280;        // largest frame Detect() accepts (grey buffer size)
  int max_height = 1024;
  float quad_decimate = 1.0f;  // AprilTag's decimation of the quad search image
  float quad_sigma = 0.0f;     // Gaussian blur of the quad search image (px)
  int nthreads = 1;            // AprilTag's worker threads
  int max_hamming = 0;         // bits corrected; detections above are dropped
  float min_decision_margin = 20.0f;  // weaker decodes are dropped
  // Re-fit each side of the tag's outer border at full resolution (grey-level gradient
  // centroid across the edge at every pixel along it, then a line fit) and intersect the
  // lines for the corners. AprilTag's own quad fit is biased by up to a few tenths of a pixel.
  bool refine_corners = true;
};

// Counters of the last Detect() call.
struct DetectStats {
  int rois = 0;             // regions searched
  long pixels = 0;          // pixels searched (sum of ROI areas)
  int raw_detections = 0;   // AprilTag's detections before filtering
  int kept = 0;             // detections written
  int dropped_capacity = 0; // detections lost because `out` was full
};

class TagDetector {
 public:
  // Creates a tag36h11 detector. Returns nullptr and sets `*error` naming the bad option if
  // `options` is invalid or libapriltag fails. The caller owns the result.
  static std::unique_ptr<TagDetector> Create(const DetectorOptions& options,
                                             std::string* error);
  ~TagDetector();
  TagDetector(const TagDetector&) = delete;
  TagDetector& operator=(const TagDetector&) = delete;

  // Detects tags in `frame` within the regions `rois[0..nroi)` (clipped to the frame; a
  // region is searched as a sub-image, without copying grey frames), or in the full frame
  // when `nroi` is 0. A tag is reported once even if regions overlap (the detection from the
  // first region wins). Writes at most `capacity` detections to `out` (caller-owned) and
  // returns how many, or a negative errno: -EINVAL for an invalid frame or a frame larger
  // than the options' maximum. `stats` may be null.
  int Detect(const FrameView& frame, const Roi* rois, int nroi, TagDetection* out,
             int capacity, DetectStats* stats);

 private:
  TagDetector() = default;
  int DetectRegion(const FrameView& frame, const Roi& roi, TagDetection* out, int count,
                   int capacity, DetectStats* stats);

  DetectorOptions options_;
  apriltag_detector* detector_ = nullptr;
  apriltag_family* family_ = nullptr;
  std::unique_ptr<uint8_t[]> gray_;  // RGB -> grey conversion of one region
};

}  // namespace vision
}  // namespace arflex

#endif  // ARFLEX_VISION_DETECTOR_H_
