// Golden images: the four cameras at two poses; AprilTag detection finds the expected tags
// with corners within the stated tolerance of the projected true corners.
#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "arflex_sim/cell.h"
#include "arflex_sim/render.h"

namespace arflex {
namespace sim {
namespace {

constexpr int kWidth = 800;
constexpr int kHeight = 600;
// Corner tolerance (px): the largest distance between a detected corner and the projection
// of the true 3-D corner through the camera model. AprilTag reports pixel centres at +0.5
// (pixel i covers [i, i+1)); CameraIntrinsics uses OpenCV's convention (centre at i), so
// 0.5 px is subtracted from the detections before comparing.
constexpr double kCornerTolerancePx = 1.0;

struct Detection {
  int id;
  double corners[4][2];
};

class Detector {
 public:
  Detector() : family_(tag36h11_create()), detector_(apriltag_detector_create()) {
    apriltag_detector_add_family(detector_, family_);
    detector_->quad_decimate = 1.0;
    detector_->nthreads = 1;
  }
  ~Detector() {
    apriltag_detector_destroy(detector_);
    tag36h11_destroy(family_);
  }
  std::vector<Detection> Detect(const std::vector<uint8_t>& rgb, int w, int h) {
    std::vector<uint8_t> gray(static_cast<size_t>(w) * h);
    RgbToGray(rgb.data(), w, h, gray.data());
    image_u8_t im = {w, h, w, gray.data()};
    zarray_t* dets = apriltag_detector_detect(detector_, &im);
    std::vector<Detection> out;
    for (int i = 0; i < zarray_size(dets); ++i) {
      apriltag_detection_t* d;
      zarray_get(dets, i, &d);
      if (d->hamming != 0) continue;
      Detection det{d->id, {}};
      for (int k = 0; k < 4; ++k) {
        det.corners[k][0] = d->p[k][0] - 0.5;
        det.corners[k][1] = d->p[k][1] - 0.5;
      }
      out.push_back(det);
    }
    apriltag_detections_destroy(dets);
    return out;
  }

 private:
  apriltag_family_t* family_;
  apriltag_detector_t* detector_;
};

double Contrast(const std::vector<uint8_t>& rgb) {
  double mean = 0, sq = 0;
  for (uint8_t v : rgb) mean += v;
  mean /= rgb.size();
  for (uint8_t v : rgb) sq += (v - mean) * (v - mean);
  return std::sqrt(sq / rgb.size());
}

class RenderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    cell_ = Cell::Create(DefaultCellConfig(), JointVector{}, &error);
    ASSERT_NE(cell_, nullptr) << error;
    renderer_ = Renderer::Create(cell_->model(), kWidth, kHeight, &error);
    ASSERT_NE(renderer_, nullptr) << error;
    rgb_.resize(static_cast<size_t>(kWidth) * kHeight * 3);
  }
  // Renders camera `cam` at the cell's current state; returns the detections and checks the
  // corner errors. Writes the image to the test's working directory for inspection.
  std::set<int> RenderAndCheck(int cam, const std::string& tag, double* worst) {
    EXPECT_EQ(renderer_->Render(cam, rgb_.data(), nullptr), 0);
    WritePng("sim_render_" + tag + "_cam" + std::to_string(cam) + ".png", rgb_.data(), kWidth,
             kHeight, 3);
    EXPECT_GT(Contrast(rgb_), 20.0) << "camera " << cam << " image looks blank";
    std::set<int> ids;
    for (const Detection& d : detector_.Detect(rgb_, kWidth, kHeight)) {
      ids.insert(d.id);
      std::array<Eigen::Vector3d, 4> corners;
      EXPECT_TRUE(renderer_->TagCorners(d.id, &corners)) << "unknown tag " << d.id;
      for (int k = 0; k < 4; ++k) {
        double u = -1e9, v = -1e9;
        EXPECT_TRUE(renderer_->Project(cam, corners[k], &u, &v));
        const double e = std::hypot(d.corners[k][0] - u, d.corners[k][1] - v);
        *worst = std::max(*worst, e);
        EXPECT_LT(e, kCornerTolerancePx) << "camera " << cam << " tag " << d.id << " corner " << k;
      }
    }
    return ids;
  }

  std::unique_ptr<Cell> cell_;
  std::unique_ptr<Renderer> renderer_;
  std::vector<uint8_t> rgb_;
  Detector detector_;
};

TEST_F(RenderTest, CamerasHaveTheConfiguredIntrinsicsAndPoses) {
  const CellConfig& config = cell_->config();
  ASSERT_EQ(renderer_->camera_count(), 4);
  for (int c = 0; c < 4; ++c) {
    EXPECT_EQ(renderer_->FindCamera(config.cameras[c].name), c);
    const CameraIntrinsics k = renderer_->Intrinsics(c);
    EXPECT_NEAR(k.fy, 0.5 * kHeight / std::tan(0.5 * config.cameras[c].fovy_deg * M_PI / 180),
                1e-9);
    const Eigen::Isometry3d pose = renderer_->CameraPose(c);
    const Vec3& p = config.cameras[c].pos;
    EXPECT_LT((pose.translation() - Eigen::Vector3d(p[0], p[1], p[2])).norm(), 1e-9);
    // The optical axis points at the configured look-at point: it projects to the centre.
    const Vec3& t = config.cameras[c].look_at;
    double u, v;
    ASSERT_TRUE(renderer_->Project(c, Eigen::Vector3d(t[0], t[1], t[2]), &u, &v));
    EXPECT_NEAR(u, k.cx, 1e-6);
    EXPECT_NEAR(v, k.cy, 1e-6);
  }
  EXPECT_EQ(renderer_->Render(4, rgb_.data(), nullptr), -EINVAL);
  std::string error;
  EXPECT_EQ(Renderer::Create(cell_->model(), 4000, 3000, &error), nullptr);
  EXPECT_NE(error.find("4000x3000"), std::string::npos) << error;
}

TEST_F(RenderTest, GoldenDetectionsAtTwoPoses) {
  // Expected tag ids per camera (cameras: front-left, front-right, back-left, back-right).
  // Reference board: 0-3 on the floor; tool block: 10 (+z face), 11 (+y), 12 (-y), 13 (-z).
  const struct {
    const char* name;
    JointVector q;
    std::set<int> expected[4];
  } poses[] = {
      {"pose_a", {0.0, 0.5, 0.3, 0.0, 0.8, 0.0}, {{0, 1, 3, 10, 11}, {1, 2, 3, 10, 12}, {0, 1, 2, 11, 13}, {0, 2, 3, 12}}},
      {"pose_b",
       {0.4, 0.3, 0.6, 0.5, -0.7, 1.0},
       {{0, 1, 2, 3, 11}, {0, 1, 2, 3, 10, 11}, {0, 1, 3, 11, 13}, {0, 1, 2, 3, 10}}},
  };
  double worst = 0.0;
  for (const auto& pose : poses) {
    cell_->ResetTo(pose.q);
    renderer_->SetState(cell_->qpos());
    for (int c = 0; c < 4; ++c) {
      const std::set<int> ids = RenderAndCheck(c, pose.name, &worst);
      std::string found;
      for (int id : ids) found += std::to_string(id) + " ";
      EXPECT_EQ(ids, pose.expected[c]) << pose.name << " camera " << c << " found " << found;
    }
  }
  RecordProperty("worst_corner_error_px", std::to_string(worst));
  std::printf("worst corner error over both poses and four cameras: %.3f px\n", worst);
}

TEST_F(RenderTest, NoiseAndBlurBehaveAsConfigured) {
  cell_->ResetTo({0.0, 0.5, 0.3, 0.0, 0.8, 0.0});
  renderer_->SetState(cell_->qpos());
  std::vector<uint8_t> clean(rgb_.size()), noisy(rgb_.size()), noisy2(rgb_.size()),
      blurred(rgb_.size());
  ASSERT_EQ(renderer_->Render(0, clean.data(), nullptr), 0);
  SensorEffects noise;
  noise.noise_sigma = 4.0;
  ASSERT_EQ(renderer_->Render(0, noisy.data(), &noise), 0);
  ASSERT_EQ(renderer_->Render(0, noisy2.data(), &noise), 0);
  // Noise statistics: zero mean, standard deviation sigma (pixels away from 0 and 255 only).
  double sum = 0, sq = 0;
  int n = 0;
  for (size_t i = 0; i < clean.size(); ++i) {
    if (clean[i] < 20 || clean[i] > 235) continue;
    const double d = static_cast<double>(noisy[i]) - clean[i];
    sum += d;
    sq += d * d;
    ++n;
  }
  ASSERT_GT(n, 100000);
  EXPECT_NEAR(sum / n, 0.0, 0.1);
  EXPECT_NEAR(std::sqrt(sq / n), 4.0, 0.2);
  EXPECT_NE(noisy, noisy2);  // fresh noise every frame
  // Detection survives the noise.
  EXPECT_GE(detector_.Detect(noisy, kWidth, kHeight).size(), 4u);
  // Blur lowers the image's gradient energy.
  SensorEffects blur;
  blur.blur_sigma = 1.5;
  ASSERT_EQ(renderer_->Render(0, blurred.data(), &blur), 0);
  auto gradient = [](const std::vector<uint8_t>& im) {
    double g = 0;
    for (size_t i = 3; i < im.size(); ++i) g += std::abs(im[i] - im[i - 3]);
    return g;
  };
  EXPECT_LT(gradient(blurred), 0.8 * gradient(clean));
}

TEST_F(RenderTest, RendersFromACopyOfTheStateNotFromTheCell) {
  // The renderer owns its state: after SetState() the cell may step on (as the physics
  // thread does while a render thread draws), the frame still shows the copied state.
  cell_->ResetTo({0.0, 0.5, 0.3, 0.0, 0.8, 0.0});
  std::vector<double> snapshot(cell_->qpos(), cell_->qpos() + cell_->model()->nq);
  renderer_->SetState(snapshot.data());
  std::array<Eigen::Vector3d, 4> before;
  ASSERT_TRUE(renderer_->TagCorners(10, &before));
  JointVector ref = {0.3, 0.5, 0.3, 0.0, 0.8, 0.0};
  cell_->SetJointReference(ref);
  cell_->Step(1500);  // the arm swings 0.3 rad away
  std::array<Eigen::Vector3d, 4> after;
  ASSERT_TRUE(renderer_->TagCorners(10, &after));
  EXPECT_EQ((before[0] - after[0]).norm(), 0.0);
  std::vector<uint8_t> a(rgb_.size()), b(rgb_.size());
  ASSERT_EQ(renderer_->Render(0, a.data(), nullptr), 0);
  renderer_->SetState(snapshot.data());
  ASSERT_EQ(renderer_->Render(0, b.data(), nullptr), 0);
  EXPECT_EQ(a, b);  // rendering is deterministic for a given state
}

TEST(RenderThreadTest, PhysicsStepsWhileARenderThreadDraws) {
  // The intended deployment: the physics thread steps and publishes qpos snapshots; a render
  // thread owns the Renderer (its OSMesa context is current there) and draws the latest
  // snapshot. Physics never waits for a frame.
  std::string error;
  auto cell = Cell::Create(DefaultCellConfig(), {0.0, 0.5, 0.3, 0.0, 0.8, 0.0}, &error);
  ASSERT_NE(cell, nullptr) << error;
  const int nq = cell->model()->nq;
  std::mutex mu;
  std::condition_variable cv;
  std::vector<double> snapshot(cell->qpos(), cell->qpos() + nq);
  int frames = 0;
  std::string render_error;
  std::atomic<bool> stop{false};
  std::thread render([&] {
    std::string err;
    auto renderer = Renderer::Create(cell->model(), 320, 240, &err);
    std::vector<uint8_t> rgb(320 * 240 * 3);
    std::vector<double> local(nq);
    while (renderer && !stop.load()) {
      {
        std::lock_guard<std::mutex> lock(mu);
        local = snapshot;
      }
      renderer->SetState(local.data());
      if (renderer->Render(frames % 4, rgb.data(), nullptr) != 0) err = "render failed";
      std::lock_guard<std::mutex> lock(mu);
      ++frames;
      cv.notify_all();
    }
    std::lock_guard<std::mutex> lock(mu);
    render_error = renderer ? err : "renderer: " + err;
    cv.notify_all();
  });
  JointVector ref = {0.0, 0.5, 0.3, 0.0, 0.8, 0.0};
  for (int k = 0; k < 3000; ++k) {
    ref[0] = 0.2 * k / 3000.0;
    cell->SetJointReference(ref);
    cell->Step(1);
    if (k % 10 == 0) {
      std::lock_guard<std::mutex> lock(mu);
      std::copy(cell->qpos(), cell->qpos() + nq, snapshot.begin());
    }
  }
  EXPECT_EQ(cell->step_count(), 3000u);
  {
    std::unique_lock<std::mutex> lock(mu);
    const bool drew = cv.wait_until(lock, std::chrono::steady_clock::now() + std::chrono::seconds(60),
                                    [&] { return frames >= 4 || !render_error.empty(); });
    EXPECT_TRUE(drew) << "no frames within 60 s; frames = " << frames;
  }
  stop.store(true);
  render.join();
  EXPECT_EQ(render_error, "");
  EXPECT_GE(frames, 4);
}

}  // namespace
}  // namespace sim
}  // namespace arflex
