// Scripted disturbances: a push on the tool, a collision with an obstacle and a hand guiding
// the arm; the joint torques and the wrist force/torque sensor see them.
#include <gtest/gtest.h>

#include <cmath>

#include "arflex_sim/cell.h"

namespace arflex {
namespace sim {
namespace {

Eigen::Vector3d V(const Vec3& v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

const JointVector kPose = {0.0, 0.5, 0.3, 0.0, 0.8, 0.0};

TEST(DisturbanceTest, WristSensorReadsToolWeightAtRest) {
  std::string error;
  auto cell = Cell::Create(DefaultCellConfig(), kPose, &error);
  ASSERT_NE(cell, nullptr) << error;
  cell->Step(200);
  const Wrench w = cell->ReadWrench();
  const double tool = cell->config().arm.tool_mass;
  EXPECT_NEAR(V(w.force).norm(), tool * 9.81, 0.01 * tool * 9.81);
  cell->SetPayload(100.0, true);
  cell->Step(2000);
  EXPECT_NEAR(V(cell->ReadWrench().force).norm(), (tool + 100.0) * 9.81, 0.01 * 1226);
}

TEST(DisturbanceTest, PushDisplacesTheToolAndTheSensorFeelsIt) {
  CellConfig config = DefaultCellConfig();
  config.pushes = {{0.5, 0.5, {0.0, 400.0, 0.0}}};  // 400 N sideways from t = 0.5 s to 1.0 s
  std::string error;
  auto cell = Cell::Create(config, kPose, &error);
  ASSERT_NE(cell, nullptr) << error;
  cell->Step(500);
  const Eigen::Vector3d rest = cell->TrueTcp().translation();
  const Eigen::Vector3d f_rest = V(cell->ReadWrench().force);
  const JointVector tau_rest = cell->ReadJointState().tau;
  cell->Step(450);  // 450 ms into the push: settled under the push
  EXPECT_NEAR(V(cell->last_external_force()).y(), 400.0, 1e-9);
  const Eigen::Vector3d pushed = cell->TrueTcp().translation();
  EXPECT_GT(pushed.y() - rest.y(), 0.05e-3);  // moved along the push
  EXPECT_NEAR((V(cell->ReadWrench().force) - f_rest).norm(), 400.0, 20.0);
  // Joint 1 resists the sideways push: about 400 N times the TCP's distance from its axis.
  const double lever = std::hypot(pushed.x(), pushed.y());
  EXPECT_NEAR(cell->ReadJointState().tau[0] - tau_rest[0], -400.0 * lever, 0.1 * 400 * lever);
  cell->Step(2000);  // after the push
  EXPECT_EQ(V(cell->last_external_force()).norm(), 0.0);
  EXPECT_LT((cell->TrueTcp().translation() - rest).norm(), 5e-6);
}

// Reduced power (force-guard's protective stop): the servo's corrective torque is saturated at
// the fraction of each drive's max torque, so a push the full-power arm holds to 1.5 mrad moves
// the limited arm; gravity compensation is not limited, so the limited arm at rest does not sag.
TEST(DisturbanceTest, ReducedPowerSaturatesTheServoAndTheArmYields) {
  CellConfig config = DefaultCellConfig();
  config.pushes = {{0.5, 0.45, {0.0, 1500.0, 0.0}}};  // 1500 N sideways for 450 ms
  auto yield = [&](double fraction, double* max_p_term) {
    std::string error;
    auto cell = Cell::Create(config, kPose, &error);
    EXPECT_NE(cell, nullptr) << error;
    cell->SetPowerScale(fraction);
    cell->Step(500);
    const double q0 = cell->ReadJointState().q[0];
    *max_p_term = 0.0;
    for (int k = 0; k < 450; ++k) {
      cell->Step(1);
      const JointVector g = cell->NominalGravityTorque(cell->ReadJointState().q, 0.0);
      *max_p_term = std::max(*max_p_term, std::fabs(cell->data()->ctrl[0] - g[0]));
    }
    return std::fabs(cell->ReadJointState().q[0] - q0);
  };
  double p_full = 0, p_limited = 0;
  const double full = yield(1.0, &p_full);
  const double limited = yield(0.1, &p_limited);
  const double limit = 0.1 * config.arm.links[0].max_torque;  // 1500 N m on joint 1
  EXPECT_GT(p_full, 1.2 * limit);  // the full-power servo resists with more than the limit
  EXPECT_LE(p_limited, limit + 1e-6);
  EXPECT_LT(full, 3e-3);
  EXPECT_GT(limited, 5.0 * full) << "full power " << full << " rad, limited " << limited << " rad";

  // At rest the limited arm holds (gravity compensation is not limited).
  std::string error;
  auto cell = Cell::Create(DefaultCellConfig(), kPose, &error);
  ASSERT_NE(cell, nullptr) << error;
  cell->SetPowerScale(0.1);
  cell->Step(200);
  const Eigen::Vector3d rest = cell->TrueTcp().translation();
  cell->Step(2000);
  EXPECT_LT((cell->TrueTcp().translation() - rest).norm(), 5e-6);
  // Bad inputs: clamped, a non-finite fraction is no power.
  cell->SetPowerScale(2.0);
  EXPECT_EQ(cell->power_scale(), 1.0);
  cell->SetPowerScale(-1.0);
  EXPECT_EQ(cell->power_scale(), 0.0);
  cell->SetPowerScale(std::nan(""));
  EXPECT_EQ(cell->power_scale(), 0.0);
}

// Sweeps joint 1 from 0 to 0.5 rad at 0.25 rad/s, the reference updated every 10 ms.
void Sweep(Cell* cell, int* max_contacts, double* max_force) {
  JointVector ref = kPose;
  for (int k = 0; k <= 200; ++k) {
    ref[0] = 0.5 * k / 200.0;
    cell->SetJointReference(ref);
    cell->Step(10);
    *max_contacts = std::max(*max_contacts, cell->obstacle_contacts());
    *max_force = std::max(*max_force, V(cell->ReadWrench().force).norm());
  }
  cell->Step(1000);
}

TEST(DisturbanceTest, ObstacleInThePathStopsTheArm) {
  std::string error;
  auto free_cell = Cell::Create(DefaultCellConfig(), kPose, &error);
  ASSERT_NE(free_cell, nullptr) << error;
  int contacts = 0;
  double force = 0;
  Sweep(free_cell.get(), &contacts, &force);
  EXPECT_EQ(contacts, 0);
  EXPECT_NEAR(free_cell->ReadJointState().q[0], 0.5, 1e-4);
  const double free_force = force;

  // A box standing in the tool's path, half-way along the arc.
  auto cell = Cell::Create(DefaultCellConfig(), kPose, &error);
  ASSERT_NE(cell, nullptr) << error;
  const Eigen::Vector3d tcp = cell->TrueTcp().translation();
  const double r = std::hypot(tcp.x(), tcp.y());
  cell->SetObstacle(true, {r * std::cos(0.25), r * std::sin(0.25) + 0.15, tcp.z() + 0.1});
  contacts = 0;
  force = 0;
  Sweep(cell.get(), &contacts, &force);
  EXPECT_GT(contacts, 0);
  EXPECT_LT(cell->ReadJointState().q[0], 0.3);           // blocked
  EXPECT_GT(std::fabs(cell->ReadJointState().tau[0]), 1000.0);  // pushing against it
  EXPECT_GT(force, free_force + 500.0);                  // the wrist sensor feels the contact
  EXPECT_EQ(cell->warning_count(), 0);
}

TEST(DisturbanceTest, HandGuidingPullsTheToolTowardsTheHand) {
  std::string error;
  auto probe = Cell::Create(DefaultCellConfig(), kPose, &error);
  ASSERT_NE(probe, nullptr) << error;
  const Eigen::Vector3d tcp = probe->TrueTcp().translation();
  HandGuideSpec hand;
  hand.enabled = true;
  hand.start = 0.2;
  hand.duration = 1.0;
  hand.from = {tcp.x(), tcp.y(), tcp.z()};
  hand.to = {tcp.x(), tcp.y() + 0.2, tcp.z()};  // the hand walks 20 cm sideways
  hand.max_force = 150.0;
  CellConfig config = DefaultCellConfig();
  config.hand = hand;
  auto cell = Cell::Create(config, kPose, &error);
  ASSERT_NE(cell, nullptr) << error;
  cell->Step(200);
  EXPECT_EQ(V(cell->last_external_force()).norm(), 0.0);
  const Eigen::Vector3d f_rest = V(cell->ReadWrench().force);
  cell->Step(900);
  // The position-servoed arm barely yields, so the hand pulls at its saturation force,
  // towards the hand (+y).
  const Eigen::Vector3d f = V(cell->last_external_force());
  EXPECT_NEAR(f.norm(), 150.0, 1e-6);
  EXPECT_GT(f.y(), 0.99 * 150.0);
  EXPECT_GT(cell->TrueTcp().translation().y() - tcp.y(), 0.02e-3);
  EXPECT_NEAR((V(cell->ReadWrench().force) - f_rest).norm(), 150.0, 10.0);
  cell->Step(1000);  // the hand has let go
  EXPECT_EQ(V(cell->last_external_force()).norm(), 0.0);
}

}  // namespace
}  // namespace sim
}  // namespace arflex
