#include "arflex_vision_calib/pivot.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <cstdio>

namespace arflex {
namespace vision {
namespace calib {
namespace {

std::string Format(const char* fmt, double a, double b = 0, double c = 0, double d = 0, double e = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d, e);
  return buf;
}

// "marker x" for a direction within 25 deg of a marker axis, else its components.
std::string AxisName(const Eigen::Vector3d& a) {
  static const char* kNames[3] = {"marker x", "marker y", "marker z"};
  int k;
  const double m = a.cwiseAbs().maxCoeff(&k);
  if (m > std::cos(25.0 * M_PI / 180.0)) return kNames[k];
  return Format("marker direction (%.3f, %.3f, %.3f)", a.x(), a.y(), a.z());
}

// Checks pose i: finite, and its linear part a proper rotation. Empty string if fine.
std::string CheckPose(const Eigen::Isometry3d& p, int i) {
  if (!p.matrix().allFinite()) return "pose " + std::to_string(i) + ": not finite";
  const Eigen::Matrix3d r = p.linear();
  const double ortho = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (ortho > 1e-6 || r.determinant() < 0) {
    return "pose " + std::to_string(i) +
           Format(": not a rotation (|R^T R - I| = %.2e, det %.6f)", ortho, r.determinant());
  }
  return "";
}

}  // namespace

PivotResult SolvePivot(const std::vector<Eigen::Isometry3d>& poses, const PivotOptions& options,
                       const std::vector<double>* weights) {
  PivotResult out;
  const int n = static_cast<int>(poses.size());
  out.poses = n;
  if (n < options.min_poses || n < 3) {
    out.reason = std::to_string(n) + " poses: a pivot calibration needs at least " +
                 std::to_string(std::max(options.min_poses, 3)) + " orientations of the tool";
    return out;
  }
  for (int i = 0; i < n; ++i) {
    const std::string bad = CheckPose(poses[i], i);
    if (!bad.empty()) {
      out.reason = bad;
      return out;
    }
  }
  if (weights != nullptr && static_cast<int>(weights->size()) != n) {
    out.reason = std::to_string(weights->size()) + " weights for " + std::to_string(n) + " poses";
    return out;
  }
  for (int i = 0; weights != nullptr && i < n; ++i) {
    const double w = (*weights)[i];
    if (!(std::isfinite(w) && w > 0)) {
      out.reason = "the weight of pose " + std::to_string(i) + Format(" is %g (must be finite and > 0)", w);
      return out;
    }
  }

  // Rotation spread: M = sum (R_i - Rm)^T (R_i - Rm); x^T M x = sum |(R_i - Rm) x|^2 is how far
  // the poses move a marker direction x against each other. Its smallest eigenvalue's
  // direction is the one the poses turn least (the common rotation axis, if any).
  Eigen::Matrix3d mean = Eigen::Matrix3d::Zero();
  for (const Eigen::Isometry3d& p : poses) mean += p.linear();
  mean /= n;
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (const Eigen::Isometry3d& p : poses) {
    const Eigen::Matrix3d d = p.linear() - mean;
    m += d.transpose() * d;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
  const double lambda = std::max(0.0, eig.eigenvalues()(0));
  out.weakest_axis = eig.eigenvectors().col(0);
  out.spread_deg = std::sqrt(lambda / n) * 180.0 / M_PI;
  if (!(out.spread_deg >= options.min_spread_deg)) {
    out.reason = "orientations too similar: the poses turn the " + AxisName(out.weakest_axis) +
                 Format(" axis by %.3f deg RMS against each other (at least %.1f deg needed): "
                        "tilt the tool across that axis too",
                        out.spread_deg, options.min_spread_deg);
    return out;
  }

  // Least squares [R_i -I][t; c] = -p_i, each pose's rows scaled by sqrt(w_i).
  Eigen::MatrixXd a(3 * n, 6);
  Eigen::VectorXd b(3 * n);
  for (int i = 0; i < n; ++i) {
    const double s = weights != nullptr ? std::sqrt((*weights)[i]) : 1.0;
    a.block<3, 3>(3 * i, 0) = s * poses[i].linear();
    a.block<3, 3>(3 * i, 3) = -s * Eigen::Matrix3d::Identity();
    b.segment<3>(3 * i) = -s * poses[i].translation();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd x = svd.solve(b);
  out.tip_in_marker = x.head<3>();
  out.pivot_in_world = x.tail<3>();

  double sum2 = 0, wsum2 = 0;
  out.residual_m.resize(n);
  for (int i = 0; i < n; ++i) {
    const double r = (poses[i].linear() * out.tip_in_marker + poses[i].translation() -
                      out.pivot_in_world).norm();
    out.residual_m[i] = r;
    sum2 += r * r;
    wsum2 += (weights != nullptr ? (*weights)[i] : 1.0) * r * r;
    if (r > out.max_residual_m) {
      out.max_residual_m = r;
      out.worst_pose = i;
    }
  }
  out.rms_m = std::sqrt(sum2 / n);
  // Covariance s^2 (A^T W A)^-1 = s^2 V S^-2 V^T, s^2 = sum w r^2 / (3N - 6).
  const double s2 = wsum2 / std::max(1, 3 * n - 6);
  const Eigen::VectorXd inv_s2 = svd.singularValues().cwiseInverse().cwiseAbs2();
  const Eigen::MatrixXd cov = s2 * svd.matrixV() * inv_s2.asDiagonal() * svd.matrixV().transpose();
  for (int k = 0; k < 3; ++k) out.tip_sigma_m(k) = std::sqrt(std::max(0.0, cov(k, k)));

  if (out.max_residual_m > options.max_residual_m) {
    out.reason = "pose " + std::to_string(out.worst_pose) +
                 Format(": the tip is %.3f mm from the fitted pivot (limit %.3f mm; RMS of all "
                        "poses %.3f mm): the tip slipped or the pose was measured wrong",
                        1e3 * out.max_residual_m, 1e3 * options.max_residual_m, 1e3 * out.rms_m);
    return out;
  }
  out.ok = true;
  out.reason = "ok";
  return out;
}

}  // namespace calib
}  // namespace vision
}  // namespace arflex
