// arflex-sim-bench [output.json]
// Physics steps per second of the servoed TRUE arm (the work of one 1 kHz period), and
// frames per second per camera at 1280x1024 and 640x480 (render + read-back, and with
// sensor noise). Prints a table and writes JSON (default arflex-sim-bench.json).
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "arflex_sim/cell.h"
#include "arflex_sim/render.h"

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

int main(int argc, char** argv) {
  using namespace arflex::sim;
  const std::string json_path = argc > 1 ? argv[1] : "arflex-sim-bench.json";
  std::string error;
  const JointVector q0 = {0.0, 0.5, 0.3, 0.0, 0.8, 0.0};
  auto cell = Cell::Create(DefaultCellConfig(), q0, &error);
  if (!cell) {
    std::fprintf(stderr, "cell: %s\n", error.c_str());
    return 1;
  }
  // Physics: a slow joint-1 sweep so the servo and the contacts do real work.
  const int kSteps = 20000;
  JointVector ref = q0;
  auto t0 = Clock::now();
  for (int k = 0; k < kSteps; ++k) {
    ref[0] = 0.3 * std::sin(k * 1e-3);
    cell->SetJointReference(ref);
    cell->Step(1);
  }
  const double physics_sps = kSteps / Seconds(t0, Clock::now());

  struct Row {
    int width, height, camera;
    double fps, fps_noise;
  };
  std::vector<Row> rows;
  for (const auto& size : {std::pair<int, int>{1280, 1024}, {640, 480}}) {
    auto renderer = Renderer::Create(cell->model(), size.first, size.second, &error);
    if (!renderer) {
      std::fprintf(stderr, "renderer: %s\n", error.c_str());
      return 1;
    }
    renderer->SetState(cell->qpos());
    std::vector<uint8_t> rgb(static_cast<size_t>(size.first) * size.second * 3);
    for (int c = 0; c < renderer->camera_count(); ++c) {
      renderer->Render(c, rgb.data(), nullptr);  // warm-up
      const int kFrames = 10;
      auto a = Clock::now();
      for (int f = 0; f < kFrames; ++f) renderer->Render(c, rgb.data(), nullptr);
      const double fps = kFrames / Seconds(a, Clock::now());
      SensorEffects fx;
      fx.noise_sigma = 2.0;
      a = Clock::now();
      for (int f = 0; f < kFrames; ++f) renderer->Render(c, rgb.data(), &fx);
      const double fps_noise = kFrames / Seconds(a, Clock::now());
      rows.push_back({size.first, size.second, c, fps, fps_noise});
    }
  }

  std::printf("physics: %.0f steps/s (%.1f x real time at 1 kHz)\n", physics_sps,
              physics_sps / 1000.0);
  std::printf("%-10s %-7s %12s %18s\n", "size", "camera", "fps", "fps (noise 2 DN)");
  for (const Row& r : rows) {
    std::printf("%4dx%-5d %-7d %12.1f %18.1f\n", r.width, r.height, r.camera, r.fps,
                r.fps_noise);
  }
  FILE* f = std::fopen(json_path.c_str(), "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", json_path.c_str());
    return 1;
  }
  std::fprintf(f, "{\n  \"physics_steps_per_second\": %.1f,\n  \"render\": [\n", physics_sps);
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    std::fprintf(f,
                 "    {\"width\": %d, \"height\": %d, \"camera\": %d, \"fps\": %.2f, "
                 "\"fps_with_noise\": %.2f}%s\n",
                 r.width, r.height, r.camera, r.fps, r.fps_noise,
                 i + 1 < rows.size() ? "," : "");
  }
  std::fprintf(f, "  ]\n}\n");
  std::fclose(f);
  std::printf("wrote %s\n", json_path.c_str());
  return 0;
}
