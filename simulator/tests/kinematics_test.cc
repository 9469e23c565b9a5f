// The independent product-of-exponentials kinematics of the nominal arm agrees with
// MuJoCo's kinematics of the generated nominal model.
#include <gtest/gtest.h>

#include "arflex_sim/kinematics.h"
#include "arflex_sim/mjcf.h"

namespace arflex {
namespace sim {
namespace {

class KinematicsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    config_ = DefaultCellConfig();
    std::string error;
    model_ = LoadMjcf(GenerateMjcf(config_, ModelKind::kNominal), "nominal", &error);
    ASSERT_NE(model_, nullptr) << error;
    data_ = mj_makeData(model_);
    tcp_ = mj_name2id(model_, mjOBJ_SITE, "tcp");
    flange_ = mj_name2id(model_, mjOBJ_SITE, "flange");
    ASSERT_GE(tcp_, 0);
    ASSERT_GE(flange_, 0);
  }
  void TearDown() override {
    if (data_) mj_deleteData(data_);
    if (model_) mj_deleteModel(model_);
  }
  // Deterministic pseudo-random joint vectors spanning the joint limits.
  JointVector Sample(int n) const {
    JointVector q;
    uint64_t x = 0x9E3779B97F4A7C15ULL * static_cast<uint64_t>(n + 1);
    for (int i = 0; i < kNumJoints; ++i) {
      x ^= x << 13;
      x ^= x >> 7;
      x ^= x << 17;
      const double u = static_cast<double>(x >> 11) * 0x1.0p-53;
      const LinkParams& l = config_.arm.links[i];
      q[i] = l.lower + u * (l.upper - l.lower);
    }
    return q;
  }
  void MujocoKinematics(const JointVector& q) {
    for (int i = 0; i < kNumJoints; ++i) data_->qpos[i] = q[i];
    mj_kinematics(model_, data_);
    mj_comPos(model_, data_);
  }

  CellConfig config_;
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  int tcp_ = -1;
  int flange_ = -1;
};

TEST_F(KinematicsTest, ZeroPoseIsTheDocumentedGeometry) {
  const NominalKinematics kin(config_.arm);
  const Eigen::Vector3d p = kin.Tcp(JointVector{}).translation();
  // 350 + 500 + 700 + 215 mm forward plus the 300 mm tool; 675 + 1150 + 41 mm up.
  EXPECT_NEAR(p.x(), 0.35 + 0.5 + 0.7 + 0.215 + 0.30, 1e-12);
  EXPECT_NEAR(p.y(), 0.0, 1e-12);
  EXPECT_NEAR(p.z(), 0.675 + 1.15 + 0.041, 1e-12);
}

TEST_F(KinematicsTest, TcpPoseMatchesMujocoBelowOneNanometre) {
  const NominalKinematics kin(config_.arm);
  double worst_pos = 0.0, worst_rot = 0.0;
  for (int n = 0; n < 500; ++n) {
    const JointVector q = Sample(n);
    MujocoKinematics(q);
    for (const auto& [site, pose] :
         {std::pair<int, Eigen::Isometry3d>{tcp_, kin.Tcp(q)}, {flange_, kin.Flange(q)}}) {
      const double* p = data_->site_xpos + 3 * site;
      const double* r = data_->site_xmat + 9 * site;
      worst_pos = std::max(worst_pos,
                           (pose.translation() - Eigen::Vector3d(p[0], p[1], p[2])).norm());
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          worst_rot = std::max(worst_rot, std::fabs(pose.linear()(a, b) - r[3 * a + b]));
        }
      }
    }
  }
  EXPECT_LT(worst_pos, 1e-9);
  EXPECT_LT(worst_rot, 1e-9);
}

TEST_F(KinematicsTest, JacobianMatchesMujoco) {
  const NominalKinematics kin(config_.arm);
  std::vector<double> jacp(3 * model_->nv), jacr(3 * model_->nv);
  double worst = 0.0;
  for (int n = 0; n < 200; ++n) {
    const JointVector q = Sample(n);
    MujocoKinematics(q);
    mj_jacSite(model_, data_, jacp.data(), jacr.data(), tcp_);
    const Jacobian6 jac = kin.TcpJacobian(q);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < kNumJoints; ++c) {
        worst = std::max(worst, std::fabs(jac(r, c) - jacp[r * model_->nv + c]));
        worst = std::max(worst, std::fabs(jac(3 + r, c) - jacr[r * model_->nv + c]));
      }
    }
  }
  EXPECT_LT(worst, 1e-9);
}

TEST_F(KinematicsTest, JacobianIsTheDerivativeOfTheTcpPosition) {
  const NominalKinematics kin(config_.arm);
  const JointVector q = Sample(7);
  const Jacobian6 jac = kin.TcpJacobian(q);
  const double h = 1e-6;
  for (int c = 0; c < kNumJoints; ++c) {
    JointVector qp = q, qm = q;
    qp[c] += h;
    qm[c] -= h;
    const Eigen::Vector3d d = (kin.Tcp(qp).translation() - kin.Tcp(qm).translation()) / (2 * h);
    EXPECT_LT((d - jac.block<3, 1>(0, c)).norm(), 1e-6) << "joint " << c + 1;
  }
}

}  // namespace
}  // namespace sim
}  // namespace arflex
