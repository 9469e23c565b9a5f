// tcpcorr.* tests: the correction law on a synthetic plant (the true arm answers a joint
// correction through a Jacobian that differs from the nominal one), its limits, holding and
// ramping.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arflex_tcpcorr/correction.h"

namespace arflex {
namespace tcpcorr {
namespace {

Matrix6d RandomJacobian(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix6d j;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) j(r, c) = u(rng);
  }
  return j + 2.0 * Matrix6d::Identity();  // well conditioned
}

Eigen::Isometry3d Desired() {
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  d.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  d.translation() = Eigen::Vector3d(1.8, 0.2, 0.7);
  return d;
}

// The pose whose error from `desired` is `e` (PoseError(desired, result) == e).
Eigen::Isometry3d Offset(const Eigen::Isometry3d& desired, const Vector6d& e) {
  Eigen::Isometry3d m = desired;
  m.translation() -= e.head<3>();
  const double a = e.tail<3>().norm();
  const Eigen::Matrix3d r = a > 0 ? Eigen::AngleAxisd(a, e.tail<3>() / a).toRotationMatrix()
                                  : Eigen::Matrix3d::Identity();
  m.linear() = r.transpose() * desired.linear();
  return m;
}

// A quasi-static plant: the measured error is e0 - J_true * applied correction.
struct Plant {
  Matrix6d j_true;
  Vector6d e0;
  Vector6d Error(const Vector6d& applied) const { return e0 - j_true * applied; }
};

Vector6d InitialError() {
  Vector6d e;
  e << 1.5e-3, -1.0e-3, 0.8e-3, 2e-4, -1e-4, 3e-4;
  return e;
}

TEST(CorrectionTest, PoseErrorMatchesItsDefinition) {
  const Vector6d e = InitialError();
  const Vector6d got = PoseError(Desired(), Offset(Desired(), e));
  EXPECT_LT((got - e).norm(), 1e-12);
  EXPECT_LT(PoseError(Desired(), Desired()).norm(), 1e-15);
}

TEST(CorrectionTest, DampedSolveInvertsAWellConditionedJacobian) {
  const Matrix6d j = RandomJacobian(1);
  const Vector6d x = InitialError();
  EXPECT_LT((DampedSolve(j, j * x, 0.0) - x).norm(), 1e-12);
  EXPECT_LT((DampedSolve(j, j * x, 1e-6) - x).norm(), 1e-9);
}

TEST(CorrectionTest, ConvergesOnASyntheticPlantWithModelMismatch) {
  const Matrix6d j_nom = RandomJacobian(2);
  Matrix6d mismatch = Matrix6d::Identity() + 0.1 * (RandomJacobian(3) - 2.0 * Matrix6d::Identity());
  const Plant plant{j_nom * mismatch, InitialError()};  // the true arm answers differently
  CorrectionLaw law(CorrectionOptions{});
  const double dt = 1e-3;
  for (int it = 0; it < 40; ++it) {
    law.Update(j_nom, Desired(), Offset(Desired(), plant.Error(law.applied())), true);
    for (int k = 0; k < 100; ++k) law.Tick(dt);  // 100 ms between measurements
  }
  EXPECT_LT(plant.Error(law.applied()).norm(), 1e-6 * plant.e0.norm());
  EXPECT_GE(law.updates(), 40);
}

TEST(CorrectionTest, StepIsLimitedPerMeasurementAndKeepsItsDirection) {
  CorrectionOptions o;
  o.max_step = 1e-4;
  CorrectionLaw law(o);
  const Matrix6d j = RandomJacobian(4);
  const Vector6d e = InitialError() * 5;
  EXPECT_EQ(law.Update(j, Desired(), Offset(Desired(), e), true), UpdateResult::kLimited);
  EXPECT_NEAR(law.target().cwiseAbs().maxCoeff(), 1e-4, 1e-15);
  const Vector6d unlimited = DampedSolve(j, e, o.damping);
  EXPECT_NEAR(law.target().normalized().dot(unlimited.normalized()), 1.0, 1e-12);
}

TEST(CorrectionTest, SizeIsLimitedWhenThePlantDoesNotRespond) {
  CorrectionOptions o;
  o.max_correction = 3e-3;
  CorrectionLaw law(o);
  const Matrix6d j = RandomJacobian(5);
  for (int it = 0; it < 200; ++it) {
    law.Update(j, Desired(), Offset(Desired(), InitialError()), true);
    law.Tick(0.1);
    ASSERT_LE(law.target().cwiseAbs().maxCoeff(), 3e-3 + 1e-15);
    ASSERT_LE(law.applied().cwiseAbs().maxCoeff(), 3e-3 + 1e-15);
  }
}

TEST(CorrectionTest, AppliedCorrectionNeverJumps) {
  CorrectionOptions o;
  o.max_rate = 5e-3;
  CorrectionLaw law(o);
  const Matrix6d j = RandomJacobian(6);
  const double dt = 1e-3;
  Vector6d last = law.applied();
  for (int it = 0; it < 20; ++it) {
    law.Update(j, Desired(), Offset(Desired(), InitialError() * (it % 2 ? -3 : 3)), true);
    for (int k = 0; k < 50; ++k) {
      const Vector6d now = law.Tick(dt);
      ASSERT_LE((now - last).cwiseAbs().maxCoeff(), o.max_rate * dt + 1e-15);
      last = now;
    }
  }
  // Disabling ramps down at the same rate, to exactly zero.
  law.SetEnabled(false);
  EXPECT_EQ(law.Update(j, Desired(), Offset(Desired(), InitialError()), true), UpdateResult::kDisabled);
  for (int k = 0; k < 20000; ++k) {
    const Vector6d now = law.Tick(dt);
    ASSERT_LE((now - last).cwiseAbs().maxCoeff(), o.max_rate * dt + 1e-15);
    last = now;
  }
  EXPECT_EQ(law.applied().norm(), 0.0);
}

TEST(CorrectionTest, HoldsTheLastCorrectionWhenTheMeasurementIsInvalid) {
  CorrectionLaw law(CorrectionOptions{});
  const Matrix6d j = RandomJacobian(7);
  law.Update(j, Desired(), Offset(Desired(), InitialError()), true);
  for (int k = 0; k < 1000; ++k) law.Tick(1e-3);
  const Vector6d held = law.applied();
  ASSERT_GT(held.norm(), 0.0);
  // Vision drops out: invalid flag, NaN pose, an absurd error.
  EXPECT_EQ(law.Update(j, Desired(), Offset(Desired(), InitialError() * 7), false), UpdateResult::kHeld);
  Eigen::Isometry3d nan = Desired();
  nan.translation().x() = std::nan("");
  EXPECT_EQ(law.Update(j, Desired(), nan, true), UpdateResult::kHeld);
  Vector6d huge = InitialError();
  huge(0) = 0.5;
  EXPECT_EQ(law.Update(j, Desired(), Offset(Desired(), huge), true), UpdateResult::kRejected);
  for (int k = 0; k < 1000; ++k) law.Tick(1e-3);
  EXPECT_EQ((law.applied() - held).norm(), 0.0);
  EXPECT_EQ(law.holds(), 3);
  EXPECT_EQ(law.updates(), 1);
}

TEST(CorrectionTest, PositionOnlyLeavesOrientationAlone) {
  CorrectionOptions o;
  o.orientation = false;
  CorrectionLaw law(o);
  const Matrix6d j = RandomJacobian(8);
  Vector6d e = Vector6d::Zero();
  e.tail<3>() << 1e-3, 0, 0;  // orientation error only
  law.Update(j, Desired(), Offset(Desired(), e), true);
  EXPECT_LT(law.target().norm(), 1e-12);
}

TEST(CorrectionTest, BadOptionsAreNamed) {
  const char* what = nullptr;
  CorrectionOptions o;
  EXPECT_TRUE(ValidateOptions(o, &what));
  o.gain = 1.5;
  EXPECT_FALSE(ValidateOptions(o, &what));
  EXPECT_STREQ(what, "gain must be in (0, 1]");
  o = CorrectionOptions{};
  o.max_rate = 0;
  EXPECT_FALSE(ValidateOptions(o, &what));
  EXPECT_STREQ(what, "max_rate must be > 0");
  CorrectionLaw law(CorrectionOptions{});
  EXPECT_FALSE(law.SetOptions(o));
  EXPECT_EQ(law.options().max_rate, CorrectionOptions{}.max_rate);
}

TEST(CorrectionTest, ShrinkingTheLimitClipsTheTarget) {
  CorrectionLaw law(CorrectionOptions{});
  const Matrix6d j = RandomJacobian(9);
  for (int i = 0; i < 5; ++i) law.Update(j, Desired(), Offset(Desired(), InitialError()), true);
  CorrectionOptions o;
  o.max_correction = 1e-5;
  ASSERT_TRUE(law.SetOptions(o));
  EXPECT_LE(law.target().cwiseAbs().maxCoeff(), 1e-5);
}

}  // namespace
}  // namespace tcpcorr
}  // namespace arflex
