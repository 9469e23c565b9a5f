// Lock-step: N periods give exactly N physics steps; the servo follows the reference and the
// correction adds to it; stepping is deterministic.
#include <gtest/gtest.h>

#include "arflex_sim/cell.h"

namespace arflex {
namespace sim {
namespace {

// Counts MuJoCo's calls of the control callback: one per mj_step, independent of Cell's
// own counter.
int g_control_calls = 0;
void CountControl(const mjModel*, mjData*) { ++g_control_calls; }

class SteppingTest : public ::testing::Test {
 protected:
  void SetUp() override {
    g_control_calls = 0;
    mjcb_control = CountControl;
  }
  void TearDown() override { mjcb_control = nullptr; }
};

TEST_F(SteppingTest, NPeriodsGiveExactlyNPhysicsSteps) {
  std::string error;
  auto cell = Cell::Create(DefaultCellConfig(), JointVector{}, &error);
  ASSERT_NE(cell, nullptr) << error;
  g_control_calls = 0;
  const double dt = cell->timestep();
  EXPECT_DOUBLE_EQ(dt, 0.001);
  uint64_t expected = 0;
  for (int n : {1, 1, 7, 1000, 0, 333}) {
    cell->Step(n);
    expected += n;
    EXPECT_EQ(cell->step_count(), expected);
    EXPECT_EQ(g_control_calls, static_cast<int>(expected));
    EXPECT_NEAR(cell->time(), expected * dt, 1e-9);
  }
  for (int i = 0; i < 500; ++i) cell->Step(1);
  EXPECT_EQ(cell->step_count(), expected + 500);
  EXPECT_EQ(g_control_calls, static_cast<int>(expected + 500));
}

TEST_F(SteppingTest, TimestepIsAParameter) {
  CellConfig config = DefaultCellConfig();
  config.timestep = 0.0005;
  std::string error;
  auto cell = Cell::Create(config, JointVector{}, &error);
  ASSERT_NE(cell, nullptr) << error;
  cell->Step(2000);
  EXPECT_EQ(cell->step_count(), 2000u);
  EXPECT_NEAR(cell->time(), 1.0, 1e-9);
}

TEST_F(SteppingTest, ServoFollowsReferencePlusCorrection) {
  const JointVector q0 = {0.0, 0.4, 0.2, 0.0, 0.6, 0.0};
  std::string error;
  auto cell = Cell::Create(DefaultCellConfig(), q0, &error);
  ASSERT_NE(cell, nullptr) << error;
  JointVector ref = q0;
  ref[0] += 0.02;
  ref[2] -= 0.01;
  ref[5] += 0.05;
  cell->SetJointReference(ref);
  cell->Step(2000);
  JointState js = cell->ReadJointState();
  for (int i = 0; i < kNumJoints; ++i) EXPECT_NEAR(js.q[i], ref[i], 2e-6) << "joint " << i + 1;

  const JointVector correction = {1e-4, -2e-4, 3e-4, 0.0, -1e-4, 0.0};
  cell->SetCorrection(correction);
  cell->Step(2000);
  js = cell->ReadJointState();
  for (int i = 0; i < kNumJoints; ++i) {
    EXPECT_NEAR(js.q[i], ref[i] + correction[i], 2e-6) << "joint " << i + 1;
  }
  EXPECT_EQ(cell->warning_count(), 0);
}

TEST_F(SteppingTest, CorrectionMovesTheTcpAsTheJacobianPredicts) {
  const JointVector q = {0.2, 0.5, 0.3, 0.1, 0.7, 0.2};
  std::string error;
  auto cell = Cell::Create(DefaultCellConfig(), q, &error);
  ASSERT_NE(cell, nullptr) << error;
  cell->Step(500);
  const Eigen::Vector3d before = cell->TrueTcp().translation();
  Eigen::Matrix<double, 6, 1> dq;
  dq << 2e-4, -1e-4, 1e-4, 3e-4, -2e-4, 1e-4;
  JointVector correction;
  for (int i = 0; i < kNumJoints; ++i) correction[i] = dq[i];
  cell->SetCorrection(correction);
  cell->Step(2000);
  const Eigen::Vector3d moved = cell->TrueTcp().translation() - before;
  const Eigen::Vector3d predicted = cell->nominal().TcpJacobian(q).topRows<3>() * dq;
  EXPECT_LT((moved - predicted).norm(), 0.02 * predicted.norm());
}

TEST_F(SteppingTest, SteppingIsDeterministic) {
  std::string error;
  const JointVector q0 = {0.1, 0.3, 0.1, 0.2, 0.5, 0.0};
  auto a = Cell::Create(DefaultCellConfig(), q0, &error);
  auto b = Cell::Create(DefaultCellConfig(), q0, &error);
  ASSERT_NE(a, nullptr) << error;
  ASSERT_NE(b, nullptr) << error;
  JointVector ref = q0;
  for (int k = 0; k < 100; ++k) {
    ref[0] = q0[0] + 0.001 * k;
    a->SetJointReference(ref);
    b->SetJointReference(ref);
    a->Step(5);
    b->Step(5);
  }
  for (int i = 0; i < a->model()->nq; ++i) EXPECT_EQ(a->qpos()[i], b->qpos()[i]);
}

}  // namespace
}  // namespace sim
}  // namespace arflex
