// Pose estimation from tag corners: the extrinsic calibration of one camera from the
// reference board, and the multi-view least-squares pose of a rigid marker object (the tool
// block) seen by any number of calibrated cameras.
//
// Method: an initial solve with OpenCV (solvePnP: IPPE for one planar tag, SQPnP otherwise)
// from the single view with the most corners, unless the caller gives an initial guess (the
// prediction from the joint state); then Levenberg-Marquardt in Eigen on the reprojection
// error of every corner in every view (a 6-parameter update of the object pose, left
// perturbation about the object origin). Outliers: a robust pass first (iteratively
// reweighted, Cauchy weight per tag observation with scale `outlier_px`) so that a wrong
// detection does not drag the fit; then, largest first, a tag observation whose RMS corner
// residual exceeds both `outlier_px` and `outlier_ratio` x the median is dropped; then a plain
// least-squares fit of the rest. The covariance is s^2 (J^T J)^-1 with s^2
// the residual variance (floored at `pixel_sigma_floor`^2), so a bad measurement shows as a
// large residual or covariance and is flagged invalid.
//
// Ownership and allocation: everything is passed by caller-owned arrays and returned by
// value; the Levenberg-Marquardt part uses fixed-size Eigen types only and does not allocate.
// The OpenCV initial solve allocates (skip it by passing an initial guess).
#ifndef ARFLEX_VISION_ESTIMATOR_H_
#define ARFLEX_VISION_ESTIMATOR_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

#include "arflex_vision/detector.h"
#include "arflex_vision/geometry.h"

namespace arflex {
namespace vision {

inline constexpr int kMaxObservations = 64;  // tag sightings in one estimate

// One tag seen by one camera: `camera` indexes the camera array, `tag` the tag-model array.
struct Observation {
  int camera = -1;
  int tag = -1;
  std::array<Eigen::Vector2d, 4> px;
  // The detector's edge scatter for this tag (TagDetection::edge_scatter_px; 0 if unknown).
  double edge_scatter_px = 0.0;
};

struct EstimatorOptions {
  int max_iterations = 30;
  double outlier_px = 1.5;         // a tag's RMS residual must exceed this to be rejected...
  double outlier_ratio = 4.0;      // ...and this multiple of the median tag residual
  int max_rejections = 4;
  double max_rms_px = 1.0;         // estimates with a larger RMS residual are invalid
  double max_position_sigma = 5e-3;  // m; larger standard deviation: invalid
  double pixel_sigma_floor = 0.05; // px; lower bound of the residual sigma in the covariance
  int min_tags = 1;
  // Tags seen more obliquely than this (angle between the tag normal and the line of sight
  // at the initial pose) are not used: their corners are the least accurate.
  double max_view_angle_deg = 70.0;
};

using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct PoseEstimate {
  bool valid = false;
  const char* reason = "no estimate";  // why it is invalid (static string), "ok" if valid
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // world_from_object
  // Covariance of the left perturbation (translation m, rotation rad) in the world frame,
  // about the object frame's origin.
  Matrix6d covariance = Matrix6d::Zero();
  double rms_px = 0.0;   // reprojection RMS over the corners kept
  double max_px = 0.0;   // largest corner residual kept
  int n_views = 0;       // distinct cameras among the observations kept
  int n_tags = 0;        // observations kept
  int n_rejected = 0;    // observations rejected as outliers
  int n_oblique = 0;     // observations not used because the tag was seen too obliquely
  int iterations = 0;
};

// Estimates the world pose of an object carrying `tags` (poses in the object frame) from
// `obs[0..nobs)` (nobs <= kMaxObservations) seen by `cameras` (world_from_camera used as is;
// uncalibrated cameras are skipped). `initial` may be null (OpenCV initial solve). Never
// throws; an impossible input gives valid = false with the reason.
PoseEstimate EstimateObjectPose(const std::vector<Camera>& cameras,
                                const std::vector<TagModel>& tags, const Observation* obs,
                                int nobs, const Eigen::Isometry3d* initial,
                                const EstimatorOptions& options);

// Builds observations from one camera's detections: keeps those whose id is in `tags`
// (appended at obs[*nobs], at most kMaxObservations in all).
void CollectObservations(int camera, const TagDetection* dets, int ndets,
                         const std::vector<TagModel>& tags, Observation* obs, int* nobs);

// Extrinsic calibration of `camera` (intrinsics known) from detections of the reference
// board `board` (tag poses in the world). Needs at least one board tag (two or more for a
// well-conditioned pose). `dets` may hold the detections of several frames of the static
// scene one after the other (each board tag once per frame): they are pooled into one fit,
// which averages the sensor noise (at most kMaxObservations board sightings are used). With a
// planar board a few metres away the camera's rotation is the weak part of the fit: every
// board tag that the camera cannot see (e.g. hidden by the arm) makes it markedly worse. On success sets world_from_camera, calibrated and
// calibration_rms_px and returns true; otherwise leaves the camera unchanged, sets `*error`
// naming the reason and returns false. `estimate` (may be null) receives the fit details.
bool CalibrateCamera(Camera* camera, const std::vector<TagModel>& board,
                     const TagDetection* dets, int ndets, const EstimatorOptions& options,
                     PoseEstimate* estimate, std::string* error);

// The pose and covariance of a point frame rigidly attached to the estimated object at
// `object_from_point` (e.g. the TCP in the marker frame): the covariance is moved from the
// object origin to that point.
PoseEstimate TransformEstimate(const PoseEstimate& estimate,
                               const Eigen::Isometry3d& object_from_point);

}  // namespace vision
}  // namespace arflex

#endif  // ARFLEX_VISION_ESTIMATOR_H_
