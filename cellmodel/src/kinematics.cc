#include "arflex_cellmodel/kinematics.h"

#include <cmath>

namespace arflex {
namespace cellmodel {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return m;
}

// exp of the twist (w, v) * theta for a unit rotation axis w (Lynch & Park, eq. 3.88).
Eigen::Isometry3d ScrewExp(const Eigen::Vector3d& w, const Eigen::Vector3d& v, double theta) {
  const Eigen::Matrix3d W = Skew(w);
  const Eigen::Matrix3d W2 = W * W;
  const double s = std::sin(theta);
  const double c = std::cos(theta);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Matrix3d::Identity() + s * W + (1.0 - c) * W2;
  t.translation() =
      (Eigen::Matrix3d::Identity() * theta + (1.0 - c) * W + (theta - s) * W2) * v;
  return t;
}

}  // namespace

NominalKinematics::NominalKinematics(const ArmParams& arm) {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (int i = 0; i < kNumJoints; ++i) {
    const LinkParams& l = arm.links[i];
    origin += Eigen::Vector3d(l.offset[0], l.offset[1], l.offset[2]);
    omega_[i] = Eigen::Vector3d(l.axis[0], l.axis[1], l.axis[2]).normalized();
    v_[i] = -omega_[i].cross(origin);
  }
  flange_home_ = Eigen::Isometry3d::Identity();
  flange_home_.translation() = origin;
  tcp_home_ = Eigen::Isometry3d::Identity();
  tcp_home_.translation() =
      origin + Eigen::Vector3d(arm.tcp_offset[0], arm.tcp_offset[1], arm.tcp_offset[2]);
}

Eigen::Isometry3d NominalKinematics::Product(const JointVector& q) const {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < kNumJoints; ++i) t = t * ScrewExp(omega_[i], v_[i], q[i]);
  return t;
}

Eigen::Isometry3d NominalKinematics::Tcp(const JointVector& q) const {
  return Product(q) * tcp_home_;
}

Eigen::Isometry3d NominalKinematics::Flange(const JointVector& q) const {
  return Product(q) * flange_home_;
}

Jacobian6 NominalKinematics::TcpJacobian(const JointVector& q) const {
  Jacobian6 jac;
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d p = Tcp(q).translation();
  for (int i = 0; i < kNumJoints; ++i) {
    // Space-frame twist of joint i: the adjoint of the product of the preceding exponentials.
    const Eigen::Vector3d w = t.linear() * omega_[i];
    const Eigen::Vector3d v = t.linear() * v_[i] + t.translation().cross(w);
    jac.block<3, 1>(0, i) = v + w.cross(p);
    jac.block<3, 1>(3, i) = w;
    t = t * ScrewExp(omega_[i], v_[i], q[i]);
  }
  return jac;
}

}  // namespace cellmodel
}  // namespace arflex
