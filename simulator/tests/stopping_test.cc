// How the arm stops (docs/safety.md): Cell::Stop decelerates a moving arm along a planned
// profile and holds where it ends, well before the servo alone, holding the angles measured at
// the stop, has damped out its swing back (about 100 ms); both end within milliradians.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "arflex_sim/cell.h"

namespace arflex {
namespace sim {
namespace {

constexpr double kStill = 2e-3;  // rad/s on every joint: "stopped", as the integration tests say
const JointVector kStart = {0.3, 0.5, 0.3, 0.0, 0.8, 0.0};

double MaxSpeed(const JointState& js) {
  double m = 0;
  for (double v : js.dq) m = std::max(m, std::fabs(v));
  return m;
}

struct Stop {
  int still_ms;      // steps until the speed stays below kStill for 50 steps
  double drift_rad;  // largest joint distance from where the stop began, once still
};

// Runs the arm for 600 ms along a ramp of @speed rad/s on each joint in @dir, stops it with
// @brake ? Cell::Stop : a reference at the measured angles, and measures the stop.
Stop RunAndStop(const JointVector& dir, double speed, bool brake) {
  std::string error;
  auto cell = Cell::Create(DefaultCellConfig(), kStart, &error);
  EXPECT_NE(cell, nullptr) << error;
  cell->Step(300);
  JointVector ref = kStart;
  for (int k = 0; k < 600; ++k) {  // the servo follows a constant-speed ramp
    for (int i = 0; i < kNumJoints; ++i) ref[i] += dir[i] * speed * cell->timestep();
    cell->SetJointReference(ref);
    cell->Step(1);
  }
  EXPECT_GT(MaxSpeed(cell->ReadJointState()), 0.09);  // joint 1's drive saturates at 0.25 rad/s
  const JointVector at_stop = cell->ReadJointState().q;
  if (brake) {
    cell->Stop();
    cell->SetJointReference(kStart);  // ignored while braking
  } else {
    cell->SetJointReference(at_stop);
  }
  int still = 0, first_still = -1;
  for (int k = 1; k <= 1000 && still < 50; ++k) {
    cell->Step(1);
    if (MaxSpeed(cell->ReadJointState()) <= kStill) {
      if (still++ == 0) first_still = k;
    } else {
      still = 0;
    }
  }
  EXPECT_EQ(still, 50) << "never still";
  if (brake) {
    EXPECT_FALSE(cell->braking());
    for (int i = 0; i < kNumJoints; ++i)
      EXPECT_NEAR(cell->ReadJointState().q[i], cell->StopTarget()[i], 2e-3) << "joint " << i << " holds where the stop ended";
  }
  double drift = 0;
  for (int i = 0; i < kNumJoints; ++i) drift = std::max(drift, std::fabs(cell->ReadJointState().q[i] - at_stop[i]));
  return {first_still, drift};
}

TEST(StoppingTest, AnArmAtRestStaysWhereItIsAndFollowsAgain) {
  std::string error;
  auto cell = Cell::Create(DefaultCellConfig(), kStart, &error);
  ASSERT_NE(cell, nullptr) << error;
  cell->Step(500);
  const JointVector q = cell->ReadJointState().q;
  cell->Stop();
  EXPECT_TRUE(cell->braking());
  cell->Step(static_cast<int>(Cell::kStopTime / cell->timestep()) + 1);
  EXPECT_FALSE(cell->braking());
  cell->Step(200);
  for (int i = 0; i < kNumJoints; ++i) EXPECT_NEAR(cell->ReadJointState().q[i], q[i], 1e-5) << "joint " << i;
  JointVector ref = q;
  ref[0] += 0.01;
  cell->SetJointReference(ref);
  cell->Step(500);
  EXPECT_NEAR(cell->ReadJointState().q[0], ref[0], 1e-4);
}

TEST(StoppingTest, BrakesAMovingArmFasterThanTheServoHoldsIt) {
  const JointVector base = {1, 0, 0, 0, 0, 0};
  const JointVector all = {1, -1, 1, -1, 1, -1};
  for (const JointVector& dir : {base, all}) {
    for (double speed : {0.1, 0.2, 0.5}) {
      const Stop held = RunAndStop(dir, speed, false);
      const Stop stopped = RunAndStop(dir, speed, true);
      std::printf("ramp %.1f rad/s, %s: still after %d ms holding the measured pose, %d ms braking "
                  "(drift %.2f / %.2f mrad)\n",
                  speed, dir[1] == 0 ? "base only" : "every joint", held.still_ms, stopped.still_ms,
                  1e3 * held.drift_rad, 1e3 * stopped.drift_rad);
      EXPECT_LE(stopped.still_ms, held.still_ms - 30) << "speed " << speed;
      EXPECT_LE(stopped.still_ms, 60) << "speed " << speed;
      EXPECT_LT(stopped.drift_rad, 10e-3) << "speed " << speed;
    }
  }
}

}  // namespace
}  // namespace sim
}  // namespace arflex
