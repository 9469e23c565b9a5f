// Forward kinematics and Jacobian of the NOMINAL arm, computed independently of MuJoCo as a
// product of exponentials (space-frame screw axes) from the same ArmParams that generate the
// MJCF. This is what a TCP-correction component may use: it knows only the nominal arm.
#ifndef ARFLEX_CELLMODEL_KINEMATICS_H_
#define ARFLEX_CELLMODEL_KINEMATICS_H_

#include <Eigen/Geometry>
#include <array>

#include "arflex_cellmodel/arm.h"

namespace arflex {
namespace cellmodel {

using Jacobian6 = Eigen::Matrix<double, 6, kNumJoints>;

class NominalKinematics {
 public:
  // Builds the screw axes and the zero-configuration TCP pose from `arm` (the nominal
  // geometry: body frames aligned with the world at q = 0, as DefaultArm() has them).
  explicit NominalKinematics(const ArmParams& arm);

  // Pose of the TCP frame in the world at joint angles `q`.
  Eigen::Isometry3d Tcp(const JointVector& q) const;

  // Pose of the flange frame (origin of link 6) in the world.
  Eigen::Isometry3d Flange(const JointVector& q) const;

  // Geometric Jacobian of the TCP in world coordinates: rows 0-2 map joint rates to the
  // linear velocity of the TCP point, rows 3-5 to the angular velocity.
  Jacobian6 TcpJacobian(const JointVector& q) const;

 private:
  // Product exp([S1] q1) ... exp([S6] q6).
  Eigen::Isometry3d Product(const JointVector& q) const;

  std::array<Eigen::Vector3d, kNumJoints> omega_;  // joint axis directions at q = 0
  std::array<Eigen::Vector3d, kNumJoints> v_;      // -omega x point on axis
  Eigen::Isometry3d tcp_home_;
  Eigen::Isometry3d flange_home_;
};

}  // namespace cellmodel
}  // namespace arflex

#endif  // ARFLEX_CELLMODEL_KINEMATICS_H_
