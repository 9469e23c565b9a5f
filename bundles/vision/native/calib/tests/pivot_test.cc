// vision.calib.Pivot*: the pivot solver on synthetic marker poses (exact, with noise, and the
// sets it must refuse).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "arflex_vision_calib/pivot.h"

namespace arflex {
namespace vision {
namespace calib {
namespace {

const Eigen::Vector3d kTip(0.3004, -0.0007, 0.0005);    // tip in the marker frame
const Eigen::Vector3d kPivot(1.9, 0.1, 0.75);           // divot in the world

Eigen::Matrix3d Rot(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// The marker pose that puts kTip on kPivot with orientation r.
Eigen::Isometry3d PoseAt(const Eigen::Matrix3d& r) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = r;
  p.translation() = kPivot - r * kTip;
  return p;
}

// n orientations: the tool pitched down 45 deg, turned about the vertical by +-25 deg, tilted
// by +-20 deg and rolled by +-30 deg (a real pivot set's shape).
std::vector<Eigen::Isometry3d> PivotSet(int n) {
  std::vector<Eigen::Isometry3d> out;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    out.push_back(PoseAt(Rot(0.44 * std::cos(a), 0.785 + 0.35 * std::sin(a),
                             0.52 * std::sin(2 * a + 0.3))));
  }
  return out;
}

TEST(PivotTest, ExactPosesGiveTheExactTip) {
  const PivotResult r = SolvePivot(PivotSet(12));
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_EQ(r.reason, "ok");
  EXPECT_LT((r.tip_in_marker - kTip).norm(), 1e-9);
  EXPECT_LT((r.pivot_in_world - kPivot).norm(), 1e-9);
  EXPECT_LT(r.rms_m, 1e-10);
  EXPECT_EQ(r.poses, 12);
  EXPECT_EQ(r.residual_m.size(), 12u);
  EXPECT_GT(r.spread_deg, 5.0);
}

TEST(PivotTest, NoisyPosesGiveTheTipWithinTheReportedSigma) {
  // Vision-like noise: 20 um per axis on the marker position, 0.05 mrad per axis on its
  // orientation (x 0.3 m lever = 15 um at the tip). Over 200 draws of 24 poses the actual
  // spread of the tip error matches the reported sigma (within 30 %), and the error is small.
  std::mt19937 rng(7);
  std::normal_distribution<double> dp(0.0, 20e-6), dr(0.0, 0.05e-3);
  const int draws = 200;
  Eigen::Vector3d err2 = Eigen::Vector3d::Zero(), sigma2 = Eigen::Vector3d::Zero();
  double rms = 0;
  for (int d = 0; d < draws; ++d) {
    std::vector<Eigen::Isometry3d> set = PivotSet(24);
    for (Eigen::Isometry3d& p : set) {
      const Eigen::Vector3d w(dr(rng), dr(rng), dr(rng));
      p.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * p.linear();
      p.translation() += Eigen::Vector3d(dp(rng), dp(rng), dp(rng));
    }
    const PivotResult r = SolvePivot(set);
    ASSERT_TRUE(r.ok) << r.reason;
    err2 += (r.tip_in_marker - kTip).cwiseAbs2();
    sigma2 += r.tip_sigma_m.cwiseAbs2();
    rms += r.rms_m / draws;
  }
  const Eigen::Vector3d actual = (err2 / draws).cwiseSqrt(), reported = (sigma2 / draws).cwiseSqrt();
  std::printf("tip error RMS %.4f %.4f %.4f mm, reported sigma %.4f %.4f %.4f mm, residual RMS %.4f mm\n",
              1e3 * actual.x(), 1e3 * actual.y(), 1e3 * actual.z(), 1e3 * reported.x(), 1e3 * reported.y(),
              1e3 * reported.z(), 1e3 * rms);
  for (int k = 0; k < 3; ++k) {
    EXPECT_GT(actual(k) / reported(k), 0.7) << "axis " << k;
    EXPECT_LT(actual(k) / reported(k), 1.3) << "axis " << k;
  }
  EXPECT_LT(actual.norm(), 0.03e-3);
  // The residual is the noise at the tip (~25 um per axis), reduced by the 6 fitted unknowns.
  EXPECT_GT(rms, 30e-6);
  EXPECT_LT(rms, 50e-6);
}

TEST(PivotTest, RotationsAboutOneAxisAreRefusedNamingTheAxis) {
  // Every pose turned about the marker's x axis (the tool axis) only: the tip's x cannot be
  // seen.
  std::vector<Eigen::Isometry3d> set;
  for (int i = 0; i < 10; ++i) set.push_back(PoseAt(Rot(0, 0.785, 0) * Rot(0, 0, -0.6 + 0.13 * i)));
  const PivotResult r = SolvePivot(set);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("orientations too similar"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("marker x"), std::string::npos) << r.reason;
  EXPECT_LT(r.spread_deg, 1e-6);
  EXPECT_GT(std::abs(r.weakest_axis.x()), 0.999);
}

TEST(PivotTest, SmallTiltsAreRefused) {
  std::vector<Eigen::Isometry3d> set;
  for (int i = 0; i < 10; ++i) {
    const double a = 2 * M_PI * i / 10;
    set.push_back(PoseAt(Rot(0.02 * std::cos(a), 0.785 + 0.02 * std::sin(a), 0.02 * std::cos(2 * a))));
  }
  const PivotResult r = SolvePivot(set);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("orientations too similar"), std::string::npos) << r.reason;
  EXPECT_GT(r.spread_deg, 0.1);
  EXPECT_LT(r.spread_deg, 5.0);
}

TEST(PivotTest, TooFewPosesAreRefused) {
  const PivotResult r = SolvePivot(PivotSet(4));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("4 poses"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("at least 6"), std::string::npos) << r.reason;
}

TEST(PivotTest, ABadPoseIsRefusedNamingIt) {
  std::vector<Eigen::Isometry3d> set = PivotSet(10);
  set[3].translation().y() = std::nan("");
  PivotResult r = SolvePivot(set);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("pose 3"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("not finite"), std::string::npos) << r.reason;

  set = PivotSet(10);
  set[5].linear() *= 1.01;  // not a rotation
  r = SolvePivot(set);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("pose 5"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("not a rotation"), std::string::npos) << r.reason;
}

TEST(PivotTest, ASlippedTipIsRefusedNamingThePose) {
  std::vector<Eigen::Isometry3d> set = PivotSet(12);
  set[7].translation() += Eigen::Vector3d(0.002, 0.0, 0.0);  // the tip left the divot by 2 mm
  const PivotResult r = SolvePivot(set);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.worst_pose, 7);
  EXPECT_NE(r.reason.find("pose 7"), std::string::npos) << r.reason;
  EXPECT_GT(r.max_residual_m, 0.5e-3);
  ASSERT_EQ(r.residual_m.size(), 12u);
}

TEST(PivotTest, WeightsTakeTheWorsePosesLessIntoAccount) {
  // A quarter of the poses is measured 5x worse (as a pose whose tags are seen obliquely):
  // weighted by 1/sigma^2 the tip error over 100 draws is markedly smaller than unweighted.
  std::mt19937 rng(11);
  std::normal_distribution<double> unit(0.0, 1.0);
  double err_plain = 0, err_weighted = 0;
  for (int d = 0; d < 100; ++d) {
    std::vector<Eigen::Isometry3d> set = PivotSet(24);
    std::vector<double> w(set.size());
    for (size_t i = 0; i < set.size(); ++i) {
      const double sigma = (i % 4 == 1) ? 100e-6 : 20e-6;
      set[i].translation() += sigma * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      w[i] = 1.0 / (sigma * sigma);
    }
    const PivotResult plain = SolvePivot(set);
    const PivotResult weighted = SolvePivot(set, PivotOptions(), &w);
    ASSERT_TRUE(plain.ok) << plain.reason;
    ASSERT_TRUE(weighted.ok) << weighted.reason;
    err_plain += (plain.tip_in_marker - kTip).squaredNorm() / 100;
    err_weighted += (weighted.tip_in_marker - kTip).squaredNorm() / 100;
  }
  std::printf("tip error RMS: unweighted %.4f mm, weighted %.4f mm\n", 1e3 * std::sqrt(err_plain),
              1e3 * std::sqrt(err_weighted));
  EXPECT_LT(std::sqrt(err_weighted), 0.6 * std::sqrt(err_plain));
  // Exact poses: any positive weights give the exact tip.
  std::vector<double> w(12, 1.0);
  w[3] = 1e-3;
  const PivotResult exact = SolvePivot(PivotSet(12), PivotOptions(), &w);
  ASSERT_TRUE(exact.ok) << exact.reason;
  EXPECT_LT((exact.tip_in_marker - kTip).norm(), 1e-9);
}

TEST(PivotTest, BadWeightsAreRefusedNamingThePose) {
  std::vector<double> w(10, 1.0);
  w[4] = -1.0;
  PivotResult r = SolvePivot(PivotSet(10), PivotOptions(), &w);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("weight of pose 4"), std::string::npos) << r.reason;
  w.resize(9);
  r = SolvePivot(PivotSet(10), PivotOptions(), &w);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("9 weights for 10 poses"), std::string::npos) << r.reason;
}

}  // namespace
}  // namespace calib
}  // namespace vision
}  // namespace arflex
