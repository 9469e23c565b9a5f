#include "arflex_vision/estimator.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace arflex {
namespace vision {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

// Normal equations and costs of the reprojection problem at `pose`. The parameters are a
// perturbation about the object origin o: P' = o + dt + R(dw) (P - o).
struct Linearisation {
  Matrix6d h = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  double sse = 0.0;
  double wsse = 0.0;  // weighted, what Levenberg-Marquardt minimises
  double max_px = 0.0;
  int corners = 0;
  bool ok = true;  // false if a point fell behind a camera
  std::array<double, kMaxObservations> obs_sse{};
};

// Precomputed per-observation data (object-frame corners, camera transforms).
struct Problem {
  int n = 0;
  std::array<std::array<Eigen::Vector3d, 4>, kMaxObservations> corners;  // object frame
  std::array<Eigen::Matrix3d, kMaxObservations> r_cw;
  std::array<Eigen::Vector3d, kMaxObservations> t_cw;
  std::array<const Intrinsics*, kMaxObservations> k{};
  std::array<int, kMaxObservations> camera{};
  std::array<const Observation*, kMaxObservations> obs{};
  std::array<bool, kMaxObservations> keep{};
  std::array<double, kMaxObservations> weight{};  // robust (IRLS) weight of an observation
};

Linearisation Linearise(const Problem& pb, const Eigen::Isometry3d& pose, bool jacobian) {
  Linearisation lin;
  const Eigen::Vector3d o = pose.translation();
  for (int i = 0; i < pb.n; ++i) {
    if (!pb.keep[i]) continue;
    const Intrinsics& k = *pb.k[i];
    double sse = 0.0;
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d p = pose * pb.corners[i][c];
      const Eigen::Vector3d pc = pb.r_cw[i] * p + pb.t_cw[i];
      if (pc.z() <= 1e-6) {
        lin.ok = false;
        return lin;
      }
      const double iz = 1.0 / pc.z();
      const Eigen::Vector2d pred(k.cx + k.fx * pc.x() * iz, k.cy + k.fy * pc.y() * iz);
      const Eigen::Vector2d e = pb.obs[i]->px[c] - pred;
      const double e2 = e.squaredNorm();
      sse += e2;
      lin.max_px = std::max(lin.max_px, std::sqrt(e2));
      ++lin.corners;
      if (!jacobian) continue;
      Eigen::Matrix<double, 2, 3> du;
      du << k.fx * iz, 0, -k.fx * pc.x() * iz * iz, 0, k.fy * iz, -k.fy * pc.y() * iz * iz;
      Eigen::Matrix<double, 3, 6> dp;
      dp.leftCols<3>() = Eigen::Matrix3d::Identity();
      dp.rightCols<3>() = -Skew(p - o);
      const Eigen::Matrix<double, 2, 6> j = du * pb.r_cw[i] * dp;
      lin.h.noalias() += pb.weight[i] * (j.transpose() * j);
      lin.g.noalias() += pb.weight[i] * (j.transpose() * e);
    }
    lin.obs_sse[i] = sse;
    lin.sse += sse;
    lin.wsse += pb.weight[i] * sse;
  }
  return lin;
}

Eigen::Isometry3d Apply(const Eigen::Isometry3d& pose, const Vector6d& d) {
  Eigen::Isometry3d out = pose;
  const Eigen::Vector3d w = d.tail<3>();
  const double a = w.norm();
  const Eigen::Matrix3d r =
      a > 1e-15 ? Eigen::AngleAxisd(a, w / a).toRotationMatrix() : Eigen::Matrix3d::Identity();
  out.linear() = r * pose.linear();
  out.translation() = pose.translation() + d.head<3>();
  return out;
}

// Levenberg-Marquardt on the kept observations, from `*pose`.
Linearisation Refine(const Problem& pb, Eigen::Isometry3d* pose, int max_iterations,
                     int* iterations) {
  Linearisation lin = Linearise(pb, *pose, true);
  double lambda = 1e-3;
  for (int it = 0; it < max_iterations && lin.ok; ++it) {
    ++*iterations;
    Matrix6d a = lin.h;
    for (int d = 0; d < 6; ++d) a(d, d) += lambda * std::max(lin.h(d, d), 1e-9);
    const Vector6d step = a.ldlt().solve(lin.g);
    if (!step.allFinite()) break;
    const Eigen::Isometry3d candidate = Apply(*pose, step);
    const Linearisation next = Linearise(pb, candidate, true);
    if (next.ok && next.wsse <= lin.wsse) {
      const bool small = step.head<3>().norm() < 1e-10 && step.tail<3>().norm() < 1e-10;
      *pose = candidate;
      const double gain = lin.wsse - next.wsse;
      lin = next;
      lambda = std::max(lambda * 0.3, 1e-9);
      if (small || gain <= 1e-12 * (1.0 + lin.wsse)) break;
    } else {
      lambda *= 10.0;
      if (lambda > 1e8) break;
    }
  }
  return lin;
}

// OpenCV initial solve from the view with the most kept observations.
bool InitialSolve(const Problem& pb, const std::vector<Camera>& cameras,
                  Eigen::Isometry3d* pose) {
  std::array<int, kMaxObservations> per_camera{};
  int best = -1;
  for (int i = 0; i < pb.n; ++i) {
    if (!pb.keep[i]) continue;
    const int c = pb.camera[i];
    if (c >= 0 && c < kMaxObservations && ++per_camera[c] > (best < 0 ? 0 : per_camera[best])) {
      best = c;
    }
  }
  if (best < 0) return false;
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (int i = 0; i < pb.n; ++i) {
    if (!pb.keep[i] || pb.camera[i] != best) continue;
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d& p = pb.corners[i][c];
      object.emplace_back(p.x(), p.y(), p.z());
      image.emplace_back(pb.obs[i]->px[c].x(), pb.obs[i]->px[c].y());
    }
  }
  const Intrinsics& k = cameras[best].k;
  const cv::Matx33d kk(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  cv::Vec3d rvec, tvec;
  bool ok = false;
  try {
    const int method = per_camera[best] == 1 ? cv::SOLVEPNP_IPPE : cv::SOLVEPNP_SQPNP;
    ok = cv::solvePnP(object, image, kk, cv::noArray(), rvec, tvec, false, method);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) return false;
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) camera_from_object.linear()(a, b) = r(a, b);
    camera_from_object.translation()(a) = tvec[a];
  }
  *pose = cameras[best].world_from_camera * camera_from_object;
  return true;
}

}  // namespace

void CollectObservations(int camera, const TagDetection* dets, int ndets,
                         const std::vector<TagModel>& tags, Observation* obs, int* nobs) {
  for (int d = 0; d < ndets && *nobs < kMaxObservations; ++d) {
    for (size_t t = 0; t < tags.size(); ++t) {
      if (tags[t].id != dets[d].id) continue;
      Observation& o = obs[(*nobs)++];
      o.camera = camera;
      o.tag = static_cast<int>(t);
      for (int c = 0; c < 4; ++c) o.px[c] = Eigen::Vector2d(dets[d].corners[c][0], dets[d].corners[c][1]);
      o.edge_scatter_px = dets[d].edge_scatter_px;
      break;
    }
  }
}

PoseEstimate EstimateObjectPose(const std::vector<Camera>& cameras,
                                const std::vector<TagModel>& tags, const Observation* obs,
                                int nobs, const Eigen::Isometry3d* initial,
                                const EstimatorOptions& options) {
  PoseEstimate est;
  if (nobs < 0 || nobs > kMaxObservations || (nobs > 0 && obs == nullptr)) {
    est.reason = "bad observation count";
    return est;
  }
  Problem pb;
  for (int i = 0; i < nobs; ++i) {
    const Observation& o = obs[i];
    if (o.camera < 0 || o.camera >= static_cast<int>(cameras.size()) ||
        !cameras[o.camera].calibrated || o.tag < 0 || o.tag >= static_cast<int>(tags.size())) {
      continue;
    }
    const Camera& cam = cameras[o.camera];
    const int j = pb.n++;
    pb.corners[j] = TagCornerPoints(tags[o.tag]);
    pb.r_cw[j] = cam.world_from_camera.linear().transpose();
    pb.t_cw[j] = -pb.r_cw[j] * cam.world_from_camera.translation();
    pb.k[j] = &cam.k;
    pb.camera[j] = o.camera;
    pb.obs[j] = &o;
    pb.keep[j] = true;
    pb.weight[j] = 1.0;
  }
  if (pb.n < std::max(1, options.min_tags)) {
    est.reason = "too few tags seen by calibrated cameras";
    return est;
  }
  Eigen::Isometry3d pose;
  if (initial != nullptr) {
    pose = *initial;
  } else if (!InitialSolve(pb, cameras, &pose)) {
    est.reason = "initial solve failed";
    return est;
  }
  int kept = pb.n;
  const double min_cos = std::cos(options.max_view_angle_deg * M_PI / 180.0);
  for (int i = 0; i < pb.n; ++i) {
    const TagModel& tag = tags[pb.obs[i]->tag];
    const Eigen::Vector3d n = pose.linear() * tag.pose.linear().col(2);
    const Eigen::Vector3d c = pose * tag.pose.translation();
    const Eigen::Vector3d eye = cameras[pb.camera[i]].world_from_camera.translation();
    if (n.dot((eye - c).normalized()) < min_cos && kept > std::max(1, options.min_tags)) {
      pb.keep[i] = false;
      --kept;
      ++est.n_oblique;
    }
  }
  auto tag_rms = [](const Linearisation& l, int i) { return std::sqrt(l.obs_sse[i] / 4.0); };
  Linearisation lin = Refine(pb, &pose, options.max_iterations, &est.iterations);
  if (lin.ok && pb.n > 1) {
    // Robust pass (iteratively reweighted, Cauchy weights per tag) so that a wrong detection
    // does not drag the fit, then reject the tags it leaves far off, then a plain fit.
    for (int round = 0; round < 4 && lin.ok; ++round) {
      for (int i = 0; i < pb.n; ++i) {
        const double r = tag_rms(lin, i) / options.outlier_px;
        pb.weight[i] = 1.0 / (1.0 + r * r);
      }
      lin = Refine(pb, &pose, options.max_iterations, &est.iterations);
    }
    for (int i = 0; i < pb.n; ++i) pb.weight[i] = 1.0;
    while (lin.ok && kept > std::max(1, options.min_tags) &&
           est.n_rejected < options.max_rejections) {
      std::array<double, kMaxObservations> rms{};
      int m = 0, worst = -1;
      for (int i = 0; i < pb.n; ++i) {
        if (!pb.keep[i]) continue;
        rms[m++] = tag_rms(lin, i);
        if (worst < 0 || tag_rms(lin, i) > tag_rms(lin, worst)) worst = i;
      }
      std::nth_element(rms.begin(), rms.begin() + m / 2, rms.begin() + m);
      const double w = tag_rms(lin, worst);
      if (!(w > options.outlier_px && w > options.outlier_ratio * rms[m / 2])) break;
      pb.keep[worst] = false;
      --kept;
      ++est.n_rejected;
      lin = Linearise(pb, pose, true);  // residuals of the rest at the robust pose
    }
    lin = Refine(pb, &pose, options.max_iterations, &est.iterations);
  }
  if (!lin.ok) {
    est.reason = "a tag corner fell behind a camera";
    return est;
  }
  std::array<bool, kMaxObservations> view{};
  for (int i = 0; i < pb.n; ++i) {
    if (pb.keep[i] && pb.camera[i] < kMaxObservations && !view[pb.camera[i]]) {
      view[pb.camera[i]] = true;
      ++est.n_views;
    }
  }
  est.pose = pose;
  est.n_tags = kept;
  est.rms_px = lin.corners > 0 ? std::sqrt(lin.sse / lin.corners) : 0.0;
  est.max_px = lin.max_px;
  const int dof = 2 * lin.corners - 6;
  const double floor2 = options.pixel_sigma_floor * options.pixel_sigma_floor;
  const double s2 = dof > 0 ? std::max(lin.sse / dof, floor2) : std::max(est.rms_px * est.rms_px, floor2);
  Eigen::LDLT<Matrix6d> ldlt(lin.h);
  if (ldlt.info() != Eigen::Success || ldlt.rcond() < 1e-14) {
    est.covariance = Matrix6d::Identity();
    est.reason = "pose not observable from these tags";
    return est;
  }
  est.covariance = s2 * ldlt.solve(Matrix6d::Identity());
  const double pos_sigma = std::sqrt(std::max(0.0, est.covariance.topLeftCorner<3, 3>().trace()));
  if (est.rms_px > options.max_rms_px) {
    est.reason = "reprojection residual too large";
  } else if (!(pos_sigma <= options.max_position_sigma)) {
    est.reason = "position uncertainty too large";
  } else {
    est.valid = true;
    est.reason = "ok";
  }
  return est;
}

bool CalibrateCamera(Camera* camera, const std::vector<TagModel>& board,
                     const TagDetection* dets, int ndets, const EstimatorOptions& options,
                     PoseEstimate* estimate, std::string* error) {
  std::array<Observation, kMaxObservations> obs;
  int nobs = 0;
  CollectObservations(0, dets, ndets, board, obs.data(), &nobs);
  if (nobs == 0) {
    if (error) *error = "camera calibration: no reference-board tag detected";
    return false;
  }
  // The "object" is the world, seen by a camera at the origin: the estimate is
  // camera_from_world.
  std::vector<Camera> solo(1);
  solo[0].k = camera->k;
  solo[0].calibrated = true;
  // The "object" origin is the cell origin, metres away from the board: its position
  // uncertainty is not the measure of a good calibration; the reprojection residual is.
  EstimatorOptions calibration = options;
  calibration.max_position_sigma = 1.0;
  const PoseEstimate est = EstimateObjectPose(solo, board, obs.data(), nobs, nullptr, calibration);
  if (estimate != nullptr) *estimate = est;
  if (!est.valid) {
    if (error) {
      *error = std::string("camera calibration: ") + est.reason + " (" + std::to_string(nobs) +
               " board tags, rms " + std::to_string(est.rms_px) + " px)";
    }
    return false;
  }
  camera->world_from_camera = est.pose.inverse();
  camera->calibrated = true;
  camera->calibration_rms_px = est.rms_px;
  return true;
}

PoseEstimate TransformEstimate(const PoseEstimate& estimate,
                               const Eigen::Isometry3d& object_from_point) {
  PoseEstimate out = estimate;
  out.pose = estimate.pose * object_from_point;
  const Eigen::Vector3d lever = out.pose.translation() - estimate.pose.translation();
  Matrix6d a = Matrix6d::Identity();
  a.topRightCorner<3, 3>() = -Skew(lever);
  out.covariance = a * estimate.covariance * a.transpose();
  return out;
}

}  // namespace vision
}  // namespace arflex
