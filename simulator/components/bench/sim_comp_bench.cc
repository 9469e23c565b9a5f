// arflex-sim-comp-bench: the sim-robot RT half's period latency (wake-up latency and execution
// time from its control-block statistics) with and without a sim-camera rendering beside it.
// A benchmark, not a test: prints a table and writes JSON.
//
//   arflex-sim-comp-bench [--seconds S] [--priority P] [--width W --height H --camera-ms M]
//                         [--json FILE]
//
// Scenario "alone": sim-robot at 1 kHz (SCHED_FIFO priority P when permitted). Scenario
// "rendering": the same plus one sim-camera (SCHED_OTHER, W x H grey, period M ms) bound to
// the robot's joint_state. Both run under the rt-core host API in a runtime id of their own
// and are shut down and removed afterwards.
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <arflex/host.h>
#include <arflex_types/image_frame.h>
#include <arflex_types/joint_state.h>
#include <arflex_types/sample.h>
#include <arflex_types/wrench.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

constexpr uint64_t kMs = 1000000ull;
constexpr uint64_t kSec = 1000 * kMs;

struct Options {
  double seconds = 10;
  int priority = 80;
  int width = 640, height = 480;
  int camera_ms = 33;
  std::string json = "sim-comp-bench.json";
};

struct MetricSummary {
  double min_us, mean_us, p50_us, p99_us, p999_us, max_us;
};

struct Result {
  std::string name;
  uint64_t cycles = 0, overruns = 0, deadline_misses = 0, update_errors = 0;
  MetricSummary latency{}, exec{};
  double latency_max_all_us = 0, exec_max_all_us = 0;  // including the start-up cycles
  uint64_t steady_cycles = 0;
  long robot_rss_kib = 0, camera_rss_kib = 0;
  bool fifo = false;
  uint64_t frames = 0;
  double camera_fps = 0, render_mean_ms = 0, render_max_ms = 0;
  uint64_t camera_overruns = 0;
};

// Summary of the samples taken between two snapshots `a` (earlier) and `b` of a metric: the
// histograms, counts and sums subtract; min and max come from the histogram's 100 ns bins
// (the max exactly when it was set inside the window).
MetricSummary Summarise(const arflex_metric& a, const arflex_metric& b, double* max_all_us) {
  MetricSummary s{};
  *max_all_us = b.count ? b.max_ns / 1e3 : 0;
  static arflex_metric d;  // 16 KB: not on the stack
  std::memset(&d, 0, sizeof(d));
  d.count = b.count - a.count;
  d.sum_ns = b.sum_ns - a.sum_ns;
  int first = -1, last = -1;
  for (unsigned i = 0; i <= ARFLEX_HIST_BINS; ++i) {
    d.hist[i] = b.hist[i] - a.hist[i];
    if (d.hist[i]) {
      if (first < 0) first = static_cast<int>(i);
      last = static_cast<int>(i);
    }
  }
  if (d.count == 0 || first < 0) return s;
  d.max_ns = (b.max_ns > a.max_ns || a.count == 0) ? b.max_ns
                                                   : static_cast<uint64_t>(last + 1) * ARFLEX_HIST_BIN_NS;
  if (d.max_ns > b.max_ns) d.max_ns = b.max_ns;
  s.min_us = first * ARFLEX_HIST_BIN_NS / 1e3;
  s.mean_us = static_cast<double>(d.sum_ns) / d.count / 1e3;
  s.p50_us = arflex_metric_percentile(&d, 50.0) / 1e3;
  s.p99_us = arflex_metric_percentile(&d, 99.0) / 1e3;
  s.p999_us = arflex_metric_percentile(&d, 99.9) / 1e3;
  s.max_us = d.max_ns / 1e3;
  // A percentile in the overflow bin (>= 200 us) is only known as "at least 200 us": the
  // histogram gives no better bound; reported as -1 (">200" in the table, null in JSON).
  const double hist_top_us = ARFLEX_HIST_BINS * ARFLEX_HIST_BIN_NS / 1e3;
  for (double* v : {&s.p50_us, &s.p99_us, &s.p999_us}) {
    if (*v > hist_top_us) *v = -1;
  }
  return s;
}

arflex_param_slot ParamI(const char* name, int64_t v) {
  arflex_param_slot s;
  std::memset(&s, 0, sizeof(s));
  std::snprintf(s.name, sizeof(s.name), "%s", name);
  s.type = ARFLEX_PARAM_INT64;
  s.min_bits = static_cast<uint64_t>(v);
  s.max_bits = static_cast<uint64_t>(v);
  s.default_bits = static_cast<uint64_t>(v);
  return s;
}

// VmRSS of process `pid` in KiB (0 if unreadable).
long RssKib(pid_t pid) {
  char path[64];
  std::snprintf(path, sizeof(path), "/proc/%d/status", static_cast<int>(pid));
  FILE* f = std::fopen(path, "r");
  if (!f) return 0;
  char line[256];
  long kib = 0;
  while (std::fgets(line, sizeof(line), f)) {
    if (std::sscanf(line, "VmRSS: %ld kB", &kib) == 1) break;
  }
  std::fclose(f);
  return kib;
}

void Sleep(uint64_t ns) {
  timespec ts = {static_cast<time_t>(ns / kSec), static_cast<long>(ns % kSec)};
  while (nanosleep(&ts, &ts) != 0) {
  }
}

bool Run(const Options& opt, bool with_camera, Result* out) {
  char rid[ARFLEX_ID_MAX + 1];
  std::snprintf(rid, sizeof(rid), "simbench-%d-%d", static_cast<int>(getpid()),
                with_camera ? 1 : 0);
  arflex_host robot, camera;
  std::memset(&robot, 0, sizeof(robot));
  std::memset(&camera, 0, sizeof(camera));
  bool ok = false;

  const arflex_port_type js_type = {ARFLEX_TYPE_JOINT_STATE_NAME, 1, 0,
                                    ARFLEX_TYPE_JOINT_STATE_SIZE};
  const arflex_port_type wr_type = {ARFLEX_TYPE_WRENCH_NAME, 1, 0, ARFLEX_TYPE_WRENCH_SIZE};
  const arflex_port_type pw_type = {ARFLEX_TYPE_SAMPLE_NAME, 1, 0, ARFLEX_TYPE_SAMPLE_SIZE};
  const arflex_port_type fr_type = {
      ARFLEX_TYPE_IMAGE_FRAME_NAME, 1, 0,
      ARFLEX_TYPE_IMAGE_FRAME_SIZE + ARFLEX_TYPE_IMAGE_FRAME_MAX_PAYLOAD};
  struct arflex_host_output robot_outs[3] = {
      {"joint_state", {ARFLEX_PORT_STATE, js_type, 1, ARFLEX_OVERFLOW_NONE}},
      {"wrench", {ARFLEX_PORT_STATE, wr_type, 1, ARFLEX_OVERFLOW_NONE}},
      {"servo_power", {ARFLEX_PORT_STATE, pw_type, 1, ARFLEX_OVERFLOW_NONE}},
  };
  arflex_host_opts ro{};
  ro.runtime = rid;
  ro.instance = "robot";
  ro.config.period_ns = 1 * kMs;
  ro.config.priority = opt.priority;
  ro.config.hb_timeout_ns = 0;
  ro.config.cfg_flags = ARFLEX_CFG_MOVES_HARDWARE;
  ro.outputs = robot_outs;
  ro.noutputs = 3;

  arflex_param_slot cam_params[3] = {ParamI("camera", 0), ParamI("width", opt.width),
                                     ParamI("height", opt.height)};
  struct arflex_host_output cam_outs[1] = {
      {"frames", {ARFLEX_PORT_FRAME, fr_type, 2, ARFLEX_OVERFLOW_NONE}}};
  arflex_host_opts co{};
  co.runtime = rid;
  co.instance = "camera";
  co.config.period_ns = static_cast<uint64_t>(opt.camera_ms) * kMs;
  co.config.priority = 0;
  co.config.cfg_flags = ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
  co.params = cam_params;
  co.nparams = 3;
  co.outputs = cam_outs;
  co.noutputs = 1;

  static arflex_stats st, cst, st0, cst0;  // 32 KB each
  int r = arflex_host_create(&robot, &ro);
  if (r == 0) r = arflex_host_spawn(&robot, SIM_ROBOT_EXE, nullptr, nullptr);
  if (r == 0) r = arflex_host_wait_state(&robot, ARFLEX_STATE_READY, 60 * kSec);
  if (r == 0 && with_camera) {
    r = arflex_host_create(&camera, &co);
    if (r == 0) r = arflex_host_spawn(&camera, SIM_CAMERA_EXE, nullptr, nullptr);
    if (r == 0) r = arflex_host_wait_state(&camera, ARFLEX_STATE_READY, 60 * kSec);
    if (r == 0) {
      r = arflex_host_bind(&camera, "joint_state",
                           arflex_host_output_name(&robot, "joint_state"), 5 * kSec);
    }
  }
  if (r == 0) r = arflex_host_start(&robot, 5 * kSec);
  if (r == 0 && with_camera) r = arflex_host_start(&camera, 5 * kSec);
  if (r != 0) {
    std::fprintf(stderr, "arflex-sim-comp-bench: setting up '%s' failed: %s\n",
                 with_camera ? "rendering" : "alone", std::strerror(-r));
    goto out;
  }
  // Warm-up (start-up page faults, first frames), then the measured window.
  Sleep(1 * kSec);
  if (arflex_ctl_stats_read(robot.ctl, &st0) != 0 ||
      (with_camera && arflex_ctl_stats_read(camera.ctl, &cst0) != 0)) {
    std::fprintf(stderr, "arflex-sim-comp-bench: statistics unreadable\n");
    goto out;
  }
  Sleep(static_cast<uint64_t>(opt.seconds * 1e9));
  out->robot_rss_kib = RssKib(robot.pid);
  if (with_camera) out->camera_rss_kib = RssKib(camera.pid);
  if (with_camera) arflex_host_stop(&camera, 5 * kSec);
  arflex_host_stop(&robot, 5 * kSec);
  if (arflex_ctl_stats_read(robot.ctl, &st) != 0 ||
      (with_camera && arflex_ctl_stats_read(camera.ctl, &cst) != 0)) {
    std::fprintf(stderr, "arflex-sim-comp-bench: statistics unreadable\n");
    goto out;
  }
  out->name = with_camera ? "rendering" : "alone";
  out->cycles = st.cycles;
  out->overruns = st.overruns;
  out->deadline_misses = st.deadline_misses;
  out->update_errors = st.update_errors;
  out->latency = Summarise(st0.latency, st.latency, &out->latency_max_all_us);
  out->exec = Summarise(st0.exec, st.exec, &out->exec_max_all_us);
  out->steady_cycles = st.cycles - st0.cycles;
  out->fifo = (arflex_ctl_flags(robot.ctl) & ARFLEX_FLAG_SCHED_FIFO) != 0;
  if (with_camera) {
    out->frames = cst.cycles - cst0.cycles;
    out->camera_fps = out->frames / opt.seconds;
    const uint64_t n = cst.exec.count - cst0.exec.count;
    out->render_mean_ms = n ? (cst.exec.sum_ns - cst0.exec.sum_ns) / 1e6 / n : 0;
    out->render_max_ms = cst.exec.max_ns / 1e6;
    out->camera_overruns = cst.overruns - cst0.overruns;
  }
  ok = true;
out:
  if (with_camera) {
    arflex_host_shutdown(&camera, 5 * kSec);
    arflex_host_wait_exit(&camera, 10 * kSec);
    arflex_host_destroy(&camera);
  }
  arflex_host_shutdown(&robot, 5 * kSec);
  arflex_host_wait_exit(&robot, 10 * kSec);
  arflex_host_destroy(&robot);
  return ok;
}

std::string Us(double v) {
  char b[32];
  if (v < 0) return ">200";
  std::snprintf(b, sizeof(b), "%.1f", v);
  return b;
}

std::string JsonUs(double v) { return v < 0 ? "null" : Us(v); }

void PrintRow(const char* what, const MetricSummary& m) {
  std::printf("  %-22s %8.1f %8.1f %8s %8s %8s %8.1f\n", what, m.min_us, m.mean_us,
              Us(m.p50_us).c_str(), Us(m.p99_us).c_str(), Us(m.p999_us).c_str(), m.max_us);
}

void JsonMetric(FILE* f, const char* name, const MetricSummary& m, bool comma) {
  std::fprintf(f,
               "      \"%s\": {\"min_us\": %.1f, \"mean_us\": %.2f, \"p50_us\": %s, "
               "\"p99_us\": %s, \"p999_us\": %s, \"max_us\": %.1f}%s\n",
               name, m.min_us, m.mean_us, JsonUs(m.p50_us).c_str(), JsonUs(m.p99_us).c_str(),
               JsonUs(m.p999_us).c_str(), m.max_us,
               comma ? "," : "");
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* v = i + 1 < argc ? argv[i + 1] : nullptr;
    if (a == "--seconds" && v) {
      opt.seconds = std::atof(v), ++i;
    } else if (a == "--priority" && v) {
      opt.priority = std::atoi(v), ++i;
    } else if (a == "--width" && v) {
      opt.width = std::atoi(v), ++i;
    } else if (a == "--height" && v) {
      opt.height = std::atoi(v), ++i;
    } else if (a == "--camera-ms" && v) {
      opt.camera_ms = std::atoi(v), ++i;
    } else if (a == "--json" && v) {
      opt.json = v, ++i;
    } else {
      std::fprintf(stderr,
                   "usage: %s [--seconds S] [--priority P] [--width W] [--height H] "
                   "[--camera-ms M] [--json FILE]\n(unknown or incomplete option '%s')\n",
                   argv[0], a.c_str());
      return 2;
    }
  }
  if (!(opt.seconds > 0) || opt.priority < 0 || opt.priority > 98 || opt.camera_ms < 1) {
    std::fprintf(stderr, "arflex-sim-comp-bench: --seconds > 0, --priority 0..98, "
                 "--camera-ms >= 1\n");
    return 2;
  }
  Result res[2];
  for (int k = 0; k < 2; ++k) {
    if (!Run(opt, k == 1, &res[k])) return 1;
  }
  std::printf("sim-robot RT half, 1 kHz, %.0f s per scenario, priority %d (%s); camera %dx%d "
              "grey every %d ms\n",
              opt.seconds, opt.priority, res[0].fifo ? "SCHED_FIFO" : "SCHED_OTHER: refused",
              opt.width, opt.height, opt.camera_ms);
  std::printf("  %-22s %8s %8s %8s %8s %8s %8s   (percentiles from 100 ns bins to 200 us)\n", "(us)", "min", "mean", "p50", "p99",
              "p99.9", "max");
  for (const Result& r : res) {
    std::printf("%s: cycles %llu (measured %llu after 1 s warm-up), overruns %llu, deadline "
                "misses %llu, update errors %llu (all cycles); max incl. start-up: latency "
                "%.1f us, execution %.1f us\n",
                r.name.c_str(), static_cast<unsigned long long>(r.cycles),
                static_cast<unsigned long long>(r.steady_cycles),
                static_cast<unsigned long long>(r.overruns),
                static_cast<unsigned long long>(r.deadline_misses),
                static_cast<unsigned long long>(r.update_errors), r.latency_max_all_us,
                r.exec_max_all_us);
    PrintRow("wake-up latency", r.latency);
    PrintRow("execution time", r.exec);
  }
  std::printf("resident memory: sim-robot %.0f MiB (mlockall), sim-camera %.0f MiB\n",
              res[1].robot_rss_kib / 1024.0, res[1].camera_rss_kib / 1024.0);
  std::printf("camera: %llu frames, %.1f fps, render+publish mean %.1f ms, max %.1f ms, "
              "overruns %llu\n",
              static_cast<unsigned long long>(res[1].frames), res[1].camera_fps,
              res[1].render_mean_ms, res[1].render_max_ms,
              static_cast<unsigned long long>(res[1].camera_overruns));

  FILE* f = std::fopen(opt.json.c_str(), "w");
  if (!f) {
    std::perror(opt.json.c_str());
    return 1;
  }
  std::fprintf(f, "{\n  \"benchmark\": \"sim-comp\",\n  \"seconds\": %.1f,\n  \"priority\": %d,\n"
               "  \"sched_fifo\": %s,\n  \"camera\": {\"width\": %d, \"height\": %d, "
               "\"period_ms\": %d, \"frames\": %llu, \"fps\": %.2f, \"render_mean_ms\": %.2f, "
               "\"render_max_ms\": %.2f, \"overruns\": %llu, \"rss_mib\": %.0f},\n  \"robot_rss_mib\": %.0f,\n  \"scenarios\": [\n",
               opt.seconds, opt.priority, res[0].fifo ? "true" : "false", opt.width,
               opt.height, opt.camera_ms, static_cast<unsigned long long>(res[1].frames),
               res[1].camera_fps, res[1].render_mean_ms, res[1].render_max_ms,
               static_cast<unsigned long long>(res[1].camera_overruns),
               res[1].camera_rss_kib / 1024.0, res[1].robot_rss_kib / 1024.0);
  for (int k = 0; k < 2; ++k) {
    const Result& r = res[k];
    std::fprintf(f, "    {\"name\": \"%s\", \"cycles\": %llu, \"measured_cycles\": %llu, "
                 "\"latency_max_incl_startup_us\": %.1f, \"exec_max_incl_startup_us\": %.1f, "
                 "\"overruns\": %llu, \"deadline_misses\": %llu, \"update_errors\": %llu,\n",
                 r.name.c_str(), static_cast<unsigned long long>(r.cycles),
                 static_cast<unsigned long long>(r.steady_cycles), r.latency_max_all_us,
                 r.exec_max_all_us,
                 static_cast<unsigned long long>(r.overruns),
                 static_cast<unsigned long long>(r.deadline_misses),
                 static_cast<unsigned long long>(r.update_errors));
    JsonMetric(f, "latency", r.latency, true);
    JsonMetric(f, "exec", r.exec, false);
    std::fprintf(f, "    }%s\n", k == 0 ? "," : "");
  }
  std::fprintf(f, "  ]\n}\n");
  std::fclose(f);
  std::printf("JSON: %s\n", opt.json.c_str());
  return 0;
}
