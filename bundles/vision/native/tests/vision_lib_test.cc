// vision.* tests: estimator and calibration on synthetic projections, detection on synthetic
// images of tag36h11 markers (golden corners from the homography that drew them).
#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <gtest/gtest.h>

#include <cerrno>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "arflex_vision/detector.h"
#include "arflex_vision/estimator.h"
#include "arflex_vision/geometry.h"
#include "synthetic_scene.h"

namespace arflex {
namespace vision {
namespace {

// A camera at `pos` looking at `at` (OpenCV axes), 1280x1024, fy as the simulator's 50 deg.
Camera LookAt(const Eigen::Vector3d& pos, const Eigen::Vector3d& at, int w = 1280, int h = 1024) {
  Camera c;
  c.k.width = w;
  c.k.height = h;
  c.k.fy = c.k.fx = 0.5 * h / std::tan(25.0 * M_PI / 180.0);
  c.k.cx = 0.5 * (w - 1);
  c.k.cy = 0.5 * (h - 1);
  const Eigen::Vector3d z = (at - pos).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  c.world_from_camera.linear().col(0) = x;
  c.world_from_camera.linear().col(1) = y;
  c.world_from_camera.linear().col(2) = z;
  c.world_from_camera.translation() = pos;
  c.calibrated = true;
  return c;
}

std::vector<Camera> FourCameras() {
  const Eigen::Vector3d at(1.8, 0, 0.5);
  return {LookAt({3.6, 1.6, 2.6}, at), LookAt({3.6, -1.6, 2.6}, at), LookAt({0.6, 2.2, 2.6}, at),
          LookAt({0.6, -2.2, 2.6}, at)};
}

// Tool block tags as in the simulator's default cell (flange frame).
std::vector<TagModel> ToolTags() {
  std::vector<TagModel> tags;
  const double s = 0.13;
  auto add = [&](int id, Eigen::Vector3d pos, Eigen::Matrix3d rot) {
    TagModel t;
    t.id = id;
    t.size = s;
    t.pose.linear() = rot;
    t.pose.translation() = pos;
    tags.push_back(t);
  };
  add(10, {0.13, 0, 0.092}, Eigen::Matrix3d::Identity());
  add(11, {0.13, 0.092, 0}, Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix());
  add(12, {0.13, -0.092, 0}, Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix());
  add(13, {0.13, 0, -0.092}, Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix());
  return tags;
}

Eigen::Isometry3d ToolPose() {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = (Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(0.8, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  p.translation() = Eigen::Vector3d(1.9, 0.1, 0.8);
  return p;
}

// Observations of every tag facing a camera, with Gaussian pixel noise.
int Observe(const std::vector<Camera>& cams, const std::vector<TagModel>& tags,
            const Eigen::Isometry3d& pose, double noise, std::mt19937* rng, Observation* obs) {
  std::normal_distribution<double> n(0.0, noise);
  int count = 0;
  for (size_t c = 0; c < cams.size(); ++c) {
    for (size_t t = 0; t < tags.size(); ++t) {
      const Eigen::Isometry3d tag_world = pose * tags[t].pose;
      const Eigen::Vector3d to_cam = cams[c].world_from_camera.translation() - tag_world.translation();
      if (tag_world.linear().col(2).dot(to_cam.normalized()) < 0.2) continue;  // facing away
      Observation& o = obs[count];
      o.camera = static_cast<int>(c);
      o.tag = static_cast<int>(t);
      const auto corners = TagCornerPoints(tags[t]);
      for (int k = 0; k < 4; ++k) {
        Eigen::Vector2d uv;
        EXPECT_TRUE(Project(cams[c], pose * corners[k], &uv));
        o.px[k] = uv + Eigen::Vector2d(noise > 0 ? n(*rng) : 0, noise > 0 ? n(*rng) : 0);
      }
      ++count;
    }
  }
  return count;
}

TEST(EstimatorTest, ExactProjectionsGiveTheExactPose) {
  const auto cams = FourCameras();
  const auto tags = ToolTags();
  std::mt19937 rng(1);
  std::array<Observation, kMaxObservations> obs;
  const int n = Observe(cams, tags, ToolPose(), 0.0, &rng, obs.data());
  ASSERT_GE(n, 4);
  const PoseEstimate e = EstimateObjectPose(cams, tags, obs.data(), n, nullptr, EstimatorOptions{});
  ASSERT_TRUE(e.valid) << e.reason;
  EXPECT_LT((e.pose.translation() - ToolPose().translation()).norm(), 1e-9);
  EXPECT_LT(Eigen::AngleAxisd(e.pose.linear() * ToolPose().linear().transpose()).angle(), 1e-9);
  EXPECT_LT(e.rms_px, 1e-6);
  EXPECT_EQ(e.n_views, 4);
  EXPECT_EQ(e.n_rejected, 0);
}

TEST(EstimatorTest, NoisyCornersGiveAStatedCovariance) {
  const auto cams = FourCameras();
  const auto tags = ToolTags();
  std::mt19937 rng(7);
  // Over many noise draws the position error matches the reported sigma (within 30 %).
  double sum_err2 = 0, sum_var = 0;
  const int trials = 200;
  for (int i = 0; i < trials; ++i) {
    std::array<Observation, kMaxObservations> obs;
    const int n = Observe(cams, tags, ToolPose(), 0.3, &rng, obs.data());
    const PoseEstimate e = EstimateObjectPose(cams, tags, obs.data(), n, nullptr, EstimatorOptions{});
    ASSERT_TRUE(e.valid) << e.reason;
    // RMS of the corner distance: sigma * sqrt(2) less the 6 fitted degrees of freedom.
    EXPECT_NEAR(e.rms_px, 0.38, 0.15);
    sum_err2 += (e.pose.translation() - ToolPose().translation()).squaredNorm();
    sum_var += e.covariance.topLeftCorner<3, 3>().trace();
  }
  EXPECT_NEAR(std::sqrt(sum_err2 / trials), std::sqrt(sum_var / trials), 0.3 * std::sqrt(sum_var / trials));
}

TEST(EstimatorTest, OutlierTagIsRejected) {
  const auto cams = FourCameras();
  const auto tags = ToolTags();
  std::mt19937 rng(3);
  std::array<Observation, kMaxObservations> obs;
  const int n = Observe(cams, tags, ToolPose(), 0.2, &rng, obs.data());
  ASSERT_GE(n, 5);
  for (auto& p : obs[2].px) p += Eigen::Vector2d(12.0, -7.0);  // a mismatched detection
  const PoseEstimate e = EstimateObjectPose(cams, tags, obs.data(), n, nullptr, EstimatorOptions{});
  ASSERT_TRUE(e.valid) << e.reason << " rms " << e.rms_px << " rejected " << e.n_rejected << " tags " << e.n_tags;
  EXPECT_EQ(e.n_rejected, 1);
  EXPECT_EQ(e.n_tags, n - 1);
  // The same as a fit that never saw the bad tag.
  std::array<Observation, kMaxObservations> clean;
  int m = 0;
  for (int i = 0; i < n; ++i) {
    if (i != 2) clean[m++] = obs[i];
  }
  const PoseEstimate c = EstimateObjectPose(cams, tags, clean.data(), m, nullptr, EstimatorOptions{});
  ASSERT_TRUE(c.valid);
  EXPECT_LT((e.pose.translation() - c.pose.translation()).norm(), 1e-7);
  EXPECT_NEAR(e.rms_px, c.rms_px, 1e-6);
}

TEST(EstimatorTest, BadMeasurementIsKnownAsBad) {
  const auto cams = FourCameras();
  const auto tags = ToolTags();
  std::mt19937 rng(5);
  std::array<Observation, kMaxObservations> obs;
  const int n = Observe(cams, tags, ToolPose(), 4.0, &rng, obs.data());
  const PoseEstimate e = EstimateObjectPose(cams, tags, obs.data(), n, nullptr, EstimatorOptions{});
  EXPECT_FALSE(e.valid);
  EXPECT_GT(e.rms_px, 1.0);
  EXPECT_STREQ(e.reason, "reprojection residual too large");
}

TEST(EstimatorTest, NoObservationsIsInvalidWithAReason) {
  const auto cams = FourCameras();
  const PoseEstimate e = EstimateObjectPose(cams, ToolTags(), nullptr, 0, nullptr, EstimatorOptions{});
  EXPECT_FALSE(e.valid);
  EXPECT_STREQ(e.reason, "too few tags seen by calibrated cameras");
  auto uncalibrated = cams;
  for (auto& c : uncalibrated) c.calibrated = false;
  std::mt19937 rng(1);
  std::array<Observation, kMaxObservations> obs;
  const int n = Observe(cams, ToolTags(), ToolPose(), 0.0, &rng, obs.data());
  EXPECT_FALSE(EstimateObjectPose(uncalibrated, ToolTags(), obs.data(), n, nullptr, EstimatorOptions{}).valid);
}

TEST(EstimatorTest, InitialGuessPathMatchesOpenCvPath) {
  const auto cams = FourCameras();
  const auto tags = ToolTags();
  std::mt19937 rng(11);
  std::array<Observation, kMaxObservations> obs;
  const int n = Observe(cams, tags, ToolPose(), 0.2, &rng, obs.data());
  Eigen::Isometry3d guess = ToolPose();
  guess.translation() += Eigen::Vector3d(0.004, -0.003, 0.002);  // a few mm off, as FK is
  guess.rotate(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ()));
  const PoseEstimate a = EstimateObjectPose(cams, tags, obs.data(), n, nullptr, EstimatorOptions{});
  const PoseEstimate b = EstimateObjectPose(cams, tags, obs.data(), n, &guess, EstimatorOptions{});
  ASSERT_TRUE(a.valid && b.valid);
  EXPECT_LT((a.pose.translation() - b.pose.translation()).norm(), 1e-8);
}

TEST(EstimatorTest, TransformEstimateMovesCovarianceToThePoint) {
  PoseEstimate e;
  e.valid = true;
  e.covariance.setZero();
  e.covariance(5, 5) = 1e-6;  // rotation about z only
  Eigen::Isometry3d tcp = Eigen::Isometry3d::Identity();
  tcp.translation() = Eigen::Vector3d(0.3, 0, 0);
  const PoseEstimate t = TransformEstimate(e, tcp);
  // A rotation about z moves a point 0.3 m along x in y: variance 0.09 * 1e-6.
  EXPECT_NEAR(t.covariance(1, 1), 0.09e-6, 1e-15);
  EXPECT_NEAR(t.covariance(0, 0), 0.0, 1e-15);
  EXPECT_NEAR(t.pose.translation().x(), 0.3, 1e-15);
}

TEST(CalibrationTest, BoardGivesTheCameraPose) {
  std::vector<TagModel> board;
  const double xs[2] = {1.40, 2.30}, ys[2] = {0.70, -0.70};
  int id = 0;
  for (double x : xs) {
    for (double y : ys) {
      TagModel t;
      t.id = id++;
      t.size = 0.24;
      t.pose.translation() = Eigen::Vector3d(x, y, 0.0025);
      board.push_back(t);
    }
  }
  std::mt19937 rng(2);
  for (double sigma : {0.0, 0.2}) {
    std::normal_distribution<double> noise(0.0, sigma > 0 ? sigma : 1.0);
    for (const Camera& truth : FourCameras()) {
      std::array<TagDetection, 4> dets;
      for (int t = 0; t < 4; ++t) {
        dets[t].id = board[t].id;
        const auto corners = TagCornerPoints(board[t]);
        for (int k = 0; k < 4; ++k) {
          Eigen::Vector2d uv;
          ASSERT_TRUE(Project(truth, corners[k], &uv));
          const double du = sigma > 0 ? noise(rng) : 0, dv = sigma > 0 ? noise(rng) : 0;
          dets[t].corners[k] = {uv.x() + du, uv.y() + dv};
        }
      }
      Camera cam;
      cam.k = truth.k;
      std::string error;
      ASSERT_TRUE(CalibrateCamera(&cam, board, dets.data(), 4, EstimatorOptions{}, nullptr, &error))
          << error;
      EXPECT_TRUE(cam.calibrated);
      const double dt = (cam.world_from_camera.translation() - truth.world_from_camera.translation()).norm();
      const double da = Eigen::AngleAxisd(cam.world_from_camera.linear() *
                                          truth.world_from_camera.linear().transpose()).angle();
      if (sigma == 0) {
        EXPECT_LT(dt, 1e-8);
        EXPECT_LT(da, 1e-9);
      } else {
        // Four 0.24 m tags at 3.3 m with 0.2 px noise: a few mm and about a milliradian.
        EXPECT_LT(dt, 20e-3);
        EXPECT_LT(da, 5e-3);
        EXPECT_NEAR(cam.calibration_rms_px, 0.25, 0.12);
      }
    }
  }
  Camera cam;
  cam.k = FourCameras()[0].k;
  std::string error;
  TagDetection stranger;
  stranger.id = 42;
  EXPECT_FALSE(CalibrateCamera(&cam, board, &stranger, 1, EstimatorOptions{}, nullptr, &error));
  EXPECT_EQ(error, "camera calibration: no reference-board tag detected");
  EXPECT_FALSE(cam.calibrated);
}

TEST(GeometryTest, PredictedRoiContainsTheTagsAndIsClipped) {
  const Camera cam = FourCameras()[0];
  const auto tags = ToolTags();
  const Roi roi = PredictRoi(cam, ToolPose(), tags, 20.0);
  ASSERT_FALSE(roi.empty());
  for (const auto& t : tags) {
    for (const auto& p : TagCornerPoints(t)) {
      Eigen::Vector2d uv;
      ASSERT_TRUE(Project(cam, ToolPose() * p, &uv));
      EXPECT_GE(uv.x(), roi.x0 + 19);
      EXPECT_LE(uv.x(), roi.x1 - 19);
      EXPECT_GE(uv.y(), roi.y0 + 19);
      EXPECT_LE(uv.y(), roi.y1 - 19);
    }
  }
  EXPECT_LT(roi.area(), 1280L * 1024 / 10);
  // Behind the camera: empty.
  Eigen::Isometry3d behind = cam.world_from_camera;
  behind.translate(Eigen::Vector3d(0, 0, -1.0));
  EXPECT_TRUE(PredictRoi(cam, behind, tags, 20.0).empty());
}

// Golden detections: tags drawn through a known homography are found with every corner
// within 0.25 px of the true projection, in TagCornerPoints' order.
class DetectorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    cams_ = testing::CellCameras(1280, 1024);
    image_ = cv::Mat(1024, 1280, CV_8UC1, cv::Scalar(150));
    for (const TagModel& t : ToolTags()) {
      if (drawer_.Draw(cams_[0], t, ToolPose(), &image_)) drawn_.push_back(t);
    }
    DetectorOptions o;
    std::string error;
    detector_ = TagDetector::Create(o, &error);
    ASSERT_TRUE(detector_) << error;
  }
  FrameView Gray() const {
    return FrameView{image_.data, image_.cols, image_.rows, static_cast<int>(image_.step),
                     PixelFormat::kGray8};
  }
  double CornerError(const TagDetection& d) const {
    double worst = 0;
    for (const TagModel& t : drawn_) {
      if (t.id != d.id) continue;
      const auto c = TagCornerPoints(t);
      for (int k = 0; k < 4; ++k) {
        Eigen::Vector2d uv;
        EXPECT_TRUE(Project(cams_[0], ToolPose() * c[k], &uv));
        worst = std::max(worst, std::hypot(d.corners[k][0] - uv.x(), d.corners[k][1] - uv.y()));
      }
      return worst;
    }
    return 1e9;
  }
  std::vector<Camera> cams_;
  cv::Mat image_;
  testing::SceneDrawer drawer_;
  std::vector<TagModel> drawn_;
  std::unique_ptr<TagDetector> detector_;
};

TEST_F(DetectorTest, FullFrameFindsTheDrawnTagsWithAccurateCorners) {
  ASSERT_GE(drawn_.size(), 2u);
  std::array<TagDetection, 16> dets;
  DetectStats stats;
  const int n = detector_->Detect(Gray(), nullptr, 0, dets.data(), 16, &stats);
  ASSERT_EQ(n, static_cast<int>(drawn_.size()));
  EXPECT_EQ(stats.rois, 1);
  EXPECT_EQ(stats.pixels, 1280L * 1024);
  for (int i = 0; i < n; ++i) EXPECT_LT(CornerError(dets[i]), 0.25) << "tag " << dets[i].id;
}

TEST_F(DetectorTest, RoiAroundThePredictionGivesTheSameCornersAndSearchesLess) {
  std::array<TagDetection, 16> full, roi_dets;
  const int n = detector_->Detect(Gray(), nullptr, 0, full.data(), 16, nullptr);
  Eigen::Isometry3d predicted = ToolPose();
  predicted.translation() += Eigen::Vector3d(0.003, -0.002, 0.002);  // FK is a few mm off
  const Roi roi = PredictRoi(cams_[0], predicted, ToolTags(), 30.0);
  DetectStats stats;
  const int m = detector_->Detect(Gray(), &roi, 1, roi_dets.data(), 16, &stats);
  ASSERT_EQ(m, n);
  EXPECT_LT(stats.pixels, 1280L * 1024 / 10);
  for (int i = 0; i < m; ++i) {
    bool found = false;
    for (int j = 0; j < n; ++j) {
      if (full[j].id != roi_dets[i].id) continue;
      found = true;
      for (int k = 0; k < 4; ++k) {
        EXPECT_NEAR(full[j].corners[k][0], roi_dets[i].corners[k][0], 1e-3);
        EXPECT_NEAR(full[j].corners[k][1], roi_dets[i].corners[k][1], 1e-3);
      }
    }
    EXPECT_TRUE(found);
  }
  // A region away from the tool finds nothing.
  const Roi empty_corner{0, 0, 100, 100};
  EXPECT_EQ(detector_->Detect(Gray(), &empty_corner, 1, roi_dets.data(), 16, nullptr), 0);
}

TEST_F(DetectorTest, RgbFrameGivesTheSameDetectionsAsGrey) {
  cv::Mat rgb;
  cv::cvtColor(image_, rgb, cv::COLOR_GRAY2RGB);
  const FrameView view{rgb.data, rgb.cols, rgb.rows, static_cast<int>(rgb.step), PixelFormat::kRgb8};
  std::array<TagDetection, 16> a, b;
  const int n = detector_->Detect(Gray(), nullptr, 0, a.data(), 16, nullptr);
  ASSERT_EQ(detector_->Detect(view, nullptr, 0, b.data(), 16, nullptr), n);
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(a[i].id, b[i].id);
    EXPECT_NEAR(a[i].corners[2][0], b[i].corners[2][0], 1e-9);
  }
}

TEST_F(DetectorTest, CapacityAndBadInputsAreReported) {
  std::array<TagDetection, 16> dets;
  DetectStats stats;
  ASSERT_GE(drawn_.size(), 2u);
  EXPECT_EQ(detector_->Detect(Gray(), nullptr, 0, dets.data(), 1, &stats), 1);
  EXPECT_EQ(stats.dropped_capacity, static_cast<int>(drawn_.size()) - 1);
  FrameView bad = Gray();
  bad.data = nullptr;
  EXPECT_EQ(detector_->Detect(bad, nullptr, 0, dets.data(), 16, nullptr), -EINVAL);
  bad = Gray();
  bad.stride = 10;
  EXPECT_EQ(detector_->Detect(bad, nullptr, 0, dets.data(), 16, nullptr), -EINVAL);
  cv::Mat large(1100, 1300, CV_8UC1, cv::Scalar(0));
  const FrameView too_big{large.data, large.cols, large.rows, static_cast<int>(large.step),
                          PixelFormat::kGray8};
  EXPECT_EQ(detector_->Detect(too_big, nullptr, 0, dets.data(), 16, nullptr), -EINVAL);
  std::string error;
  DetectorOptions o;
  o.quad_decimate = 0.5f;
  EXPECT_FALSE(TagDetector::Create(o, &error));
  EXPECT_EQ(error, "vision detector: quad_decimate must be in [1, 8] (got 0.500000)");
  o = DetectorOptions{};
  o.max_width = 0;
  EXPECT_FALSE(TagDetector::Create(o, &error));
  EXPECT_NE(error.find("max_width/max_height"), std::string::npos);
}

// Draws `tag` into `image` with area sampling: the tag is drawn 8x finer into the region
// `roi` and averaged down (a box filter: each pixel gets the tag's coverage), so that the
// edges are anti-aliased at any angle (the plain warp leaves axis-aligned edges quantised to
// the pixel grid).
void DrawAreaSampled(const Camera& cam, const TagModel& tag, const Roi& roi, cv::Mat* image) {
  const int s = 8;
  Camera fine = cam;
  fine.k.width = s * roi.width();
  fine.k.height = s * roi.height();
  fine.k.fx = s * cam.k.fx;
  fine.k.fy = s * cam.k.fy;
  fine.k.cx = s * (cam.k.cx - roi.x0 + 0.5) - 0.5;
  fine.k.cy = s * (cam.k.cy - roi.y0 + 0.5) - 0.5;
  cv::Mat big(fine.k.height, fine.k.width, CV_8UC1, cv::Scalar(150));
  testing::SceneDrawer drawer;
  ASSERT_TRUE(drawer.Draw(fine, tag, Eigen::Isometry3d::Identity(), &big));
  cv::Mat small;
  cv::resize(big, small, cv::Size(roi.width(), roi.height()), 0, 0, cv::INTER_AREA);
  small.copyTo((*image)(cv::Rect(roi.x0, roi.y0, roi.width(), roi.height())));
}

// Oblique views: a tag turned away from the camera by up to 65 degrees keeps sub-pixel
// corners. The corner re-fit measures each edge within half a module ACROSS the edge (the
// foreshortened width), so the neighbouring edges (the white ring's outer edge, the code's
// bits) do not pull it, and re-centres its profile on the fitted edge.
TEST(DetectorObliqueTest, CornerReFitStaysAccurateOnForeshortenedTags) {
  const Camera cam = LookAt({3.6, 1.6, 2.6}, {1.8, 0, 0.5});
  const Eigen::Vector3d centre(1.8, 0, 0.5);
  const Eigen::Vector3d sight = (cam.world_from_camera.translation() - centre).normalized();
  const Eigen::Vector3d axis = sight.cross(Eigen::Vector3d::UnitZ()).normalized();
  std::string error;
  DetectorOptions refit_options;
  DetectorOptions raw_options;
  raw_options.refine_corners = false;
  auto refit = TagDetector::Create(refit_options, &error);
  auto raw = TagDetector::Create(raw_options, &error);
  ASSERT_TRUE(refit && raw) << error;
  Eigen::Vector2d c;
  ASSERT_TRUE(Project(cam, centre, &c));
  const Roi roi{static_cast<int>(c.x()) - 64, static_cast<int>(c.y()) - 64,
                static_cast<int>(c.x()) + 64, static_cast<int>(c.y()) + 64};
  for (double deg : {0.0, 30.0, 50.0, 65.0}) {
    SCOPED_TRACE(deg);
    // The tag faces the camera (rolled 20 degrees about its normal, so that no edge is
    // aligned with the pixel grid), then turns by `deg` about an axis across the line of
    // sight.
    TagModel tag{10, 0.13, Eigen::Isometry3d::Identity()};
    Eigen::Matrix3d facing;
    facing.col(0) = axis;
    facing.col(1) = sight.cross(axis);
    facing.col(2) = sight;
    tag.pose.linear() = Eigen::AngleAxisd(deg * M_PI / 180.0, axis) * facing *
                        Eigen::AngleAxisd(20.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ());
    tag.pose.translation() = centre;
    cv::Mat image(1024, 1280, CV_8UC1, cv::Scalar(150));
    DrawAreaSampled(cam, tag, roi, &image);
    const FrameView frame{image.data, image.cols, image.rows, static_cast<int>(image.step),
                          PixelFormat::kGray8};
    std::array<TagDetection, 4> a, b;
    ASSERT_EQ(refit->Detect(frame, nullptr, 0, a.data(), 4, nullptr), 1);
    ASSERT_EQ(raw->Detect(frame, nullptr, 0, b.data(), 4, nullptr), 1);
    EXPECT_TRUE(a[0].refined);
    EXPECT_FALSE(b[0].refined);
    EXPECT_LT(a[0].edge_scatter_px, 0.2);
    const auto truth = TagCornerPoints(tag);
    double worst_refit = 0, worst_raw = 0;
    for (int k = 0; k < 4; ++k) {
      Eigen::Vector2d uv;
      ASSERT_TRUE(Project(cam, truth[k], &uv));
      worst_refit = std::max(worst_refit, std::hypot(a[0].corners[k][0] - uv.x(), a[0].corners[k][1] - uv.y()));
      worst_raw = std::max(worst_raw, std::hypot(b[0].corners[k][0] - uv.x(), b[0].corners[k][1] - uv.y()));
    }
    std::printf("view %4.0f deg: worst corner error, re-fit %.3f px, AprilTag %.3f px\n", deg,
                worst_refit, worst_raw);
    EXPECT_LT(worst_refit, 0.1);
  }
}

TEST_F(DetectorTest, EndToEndPoseFromFourSyntheticViews) {
  std::array<Observation, kMaxObservations> obs;
  int nobs = 0;
  for (int c = 0; c < 4; ++c) {
    cv::Mat img(1024, 1280, CV_8UC1, cv::Scalar(150));
    for (const TagModel& t : ToolTags()) drawer_.Draw(cams_[c], t, ToolPose(), &img);
    std::array<TagDetection, 16> dets;
    const FrameView v{img.data, img.cols, img.rows, static_cast<int>(img.step), PixelFormat::kGray8};
    const int n = detector_->Detect(v, nullptr, 0, dets.data(), 16, nullptr);
    ASSERT_GT(n, 0) << "camera " << c;
    CollectObservations(c, dets.data(), n, ToolTags(), obs.data(), &nobs);
  }
  const PoseEstimate e = EstimateObjectPose(cams_, ToolTags(), obs.data(), nobs, nullptr, EstimatorOptions{});
  ASSERT_TRUE(e.valid) << e.reason;
  EXPECT_EQ(e.n_views, 4);
  EXPECT_LT((e.pose.translation() - ToolPose().translation()).norm(), 0.1e-3);
  EXPECT_LT(e.rms_px, 0.3);
}

}  // namespace
}  // namespace vision
}  // namespace arflex
