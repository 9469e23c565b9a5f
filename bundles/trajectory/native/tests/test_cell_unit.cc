// test_cell_unit - CTest cell.unit.*: the nominal model (cellkin) and the trajectory player,
// in process, every cycle checked.
//   test_cell_unit <kinematics|program|trajectory_limits|trajectory_pause|trajectory_via|trajectory_loop|builtin>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>
#include <unistd.h>

#include "cellkin.h"
#include "trajectory_plan.h"

using arflex::cellkin::Model;
using arflex::cellkin::Program;
using arflex::cellkin::Q;
namespace traj = arflex::traj;

static int failures;
#define CHECK(c, ...)                                                      \
  do {                                                                     \
    if (!(c)) {                                                            \
      fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #c);         \
      fprintf(stderr, __VA_ARGS__);                                        \
      fputc('\n', stderr);                                                 \
      ++failures;                                                          \
      return;                                                              \
    }                                                                      \
  } while (0)

// Potential energy of the nominal arm (links + tool + payload) at q, for a finite-difference
// check of GravityTorque (which must equal dV/dq).
static double Potential(const Model& m, const Q& q, double payload) {
  const auto& arm = m.arm();
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  double v = 0;
  for (int i = 0; i < 6; ++i) {
    const auto& l = arm.links[i];
    t = t * Eigen::Translation3d(l.offset[0], l.offset[1], l.offset[2]) *
        Eigen::AngleAxisd(q[i], Eigen::Vector3d(l.axis[0], l.axis[1], l.axis[2]).normalized());
    v += l.mass * 9.81 * (t * Eigen::Vector3d(l.com[0], l.com[1], l.com[2])).z();
  }
  v += arm.tool_mass * 9.81 *
       (t * Eigen::Vector3d(arm.tool_com[0], arm.tool_com[1], arm.tool_com[2])).z();
  v += payload * 9.81 *
       (t * Eigen::Vector3d(arm.payload_com[0], arm.payload_com[1], arm.payload_com[2])).z();
  return v;
}

static void TestKinematics() {
  Model m;
  Q q;
  q << 0.3, 0.2, 0.5, -0.4, 0.7, 0.1;
  // IK: perturb, solve back to the FK pose.
  const Eigen::Isometry3d target = m.Tcp(q);
  Q q2 = q + Q::Constant(0.05);
  const double err = m.Ik(target, &q2, 20);
  CHECK(err < 1e-9, "IK error %g", err);
  CHECK((m.Tcp(q2).translation() - target.translation()).norm() < 1e-9, "IK position");
  // Gravity = dV/dq (central differences), with and without payload.
  for (double payload : {0.0, 100.0}) {
    const Q g = m.GravityTorque(q, payload);
    for (int j = 0; j < 6; ++j) {
      Q a = q, b = q;
      a[j] += 1e-6;
      b[j] -= 1e-6;
      const double fd = (Potential(m, a, payload) - Potential(m, b, payload)) / 2e-6;
      CHECK(std::fabs(fd - g[j]) < 1e-3 * (1 + std::fabs(fd)), "joint %d gravity %g vs dV/dq %g",
            j + 1, g[j], fd);
    }
  }
  // Tool weight at the wrist at q = 0: the flange frame is the world frame, force up.
  Eigen::Vector3d f, t;
  m.ToolWeightWrench(Q::Zero(), 0, &f, &t);
  CHECK(std::fabs(f.z() - m.arm().tool_mass * 9.81) < 1e-9 && std::fabs(f.x()) < 1e-9,
        "tool weight %g %g %g", f.x(), f.y(), f.z());
}

static void TestProgram() {
  Model m;
  Program p;
  std::string err;
  CHECK(arflex::cellkin::ParseProgram("arflex-program 1\nptp 0 0 0 0 0 0\nwait 1\n", "t", m, &p,
                                      &err),
        "%s", err.c_str());
  CHECK(p.motions.size() == 2, "motions %zu", p.motions.size());
  struct Bad {
    const char* text;
    const char* expect;
  } bad[] = {
      {"ptp 0 0 0 0 0 0\n", "t:1: expected the header"},
      {"arflex-program 1\nptp 0 0 0 0 0\n", "t:2: ptp needs 6 joint angles"},
      {"arflex-program 1\n\nptp 0 9 0 0 0 0\n", "t:3: joint 2 target"},
      {"arflex-program 1\nlin 1 2 3 0 0 0 0\n", "t:2: lin orientation quaternion is zero"},
      {"arflex-program 1\nptp 0 0 0 0 0 x\n", "t:2: 'x' is not a number"},
      {"arflex-program 1\nfly 1\n", "t:2: unknown statement 'fly'"},
      {"arflex-program 1\nptp 0 0 0 0 0 0 speed 2\n", "t:2: ptp speed must be in (0, 1]"},
      {"arflex-program 1\nwait -1\n", "t:2: wait duration"},
      {"arflex-program 1\n# nothing\n", "t:2: program has no motion"},
      {"", "t:0: empty program"},
  };
  for (const Bad& b : bad) {
    CHECK(!arflex::cellkin::ParseProgram(b.text, "t", m, &p, &err), "accepted: %s", b.text);
    CHECK(err.rfind(b.expect, 0) == 0, "message '%s' does not start with '%s'", err.c_str(),
          b.expect);
  }
  // Round trip through a file.
  char dir[] = "/tmp/arflex-cell-unit-XXXXXX";
  CHECK(mkdtemp(dir), "mkdtemp");
  Program w;
  w.origin = "test";
  w.has_start = true;
  w.start << 0.1, 0.2, 0.3, 0.4, 0.5, 0.6;
  arflex::cellkin::Motion mo{};
  mo.kind = arflex::cellkin::Motion::kPtp;
  for (int j = 0; j < 6; ++j) mo.v[j] = 0.1 * j + 1.0 / 3.0;
  mo.speed = 0.5;
  w.motions.push_back(mo);
  const std::string path = arflex::cellkin::ProgramPath(dir, 7);
  const bool wrote = arflex::cellkin::WriteProgramFile(path, w, &err);
  const bool read = wrote && arflex::cellkin::LoadProgramFile(path, m, &p, &err);
  unlink(path.c_str());
  rmdir(dir);
  CHECK(wrote && read, "%s", err.c_str());
  CHECK(p.has_start && (p.start - w.start).norm() == 0, "start lost");
  CHECK(p.motions.size() == 1 && p.motions[0].speed == 0.5 && p.motions[0].v[0] == mo.v[0],
        "motion lost");
}

// Runs the program cycle by cycle and checks every cycle against the limits.
struct RunStats {
  double max_v_ratio = 0;  // max |dq|/dt / vmax_j
  double max_a = 0;        // max |ddq| (rad/s^2)
  double max_plan_a = 0;
  uint64_t cycles = 0;
};

static bool Run(traj::Player* pl, const traj::Limits& lim, uint64_t max_cycles, RunStats* st,
                double (*rate)(uint64_t) = nullptr) {
  Q prev = pl->q_out(), prev_v = Q::Zero();
  const double dt = 0.001;
  for (uint64_t k = 0; k < max_cycles && !pl->done(); ++k) {
    pl->Step(lim, rate ? rate(k) : 1.0, false);
    const Q v = (pl->q_out() - prev) / dt;
    for (int j = 0; j < 6; ++j) {
      st->max_v_ratio = std::max(st->max_v_ratio, std::fabs(v[j]) / lim.vmax[j]);
      st->max_a = std::max(st->max_a, std::fabs(v[j] - prev_v[j]) / dt);
    }
    prev = pl->q_out();
    prev_v = v;
    st->cycles++;
  }
  return pl->done();
}

static void TestTrajectoryLimits() {
  Model m;
  Program p;
  std::string err;
  const char* text =
      "arflex-program 1\nstart 0 0 0 0 0 0\n"
      "ptp 0.5 0.3 0.6 -0.4 0.8 0.3\n"
      "ptp -0.4 0.1 0.9 0.5 -0.6 -0.2 speed 0.5\n"
      "ptp 0 0.2 0.5 0 0.6 0\n";
  CHECK(arflex::cellkin::ParseProgram(text, "three", m, &p, &err), "%s", err.c_str());
  for (int prof = 0; prof < 2; ++prof) {
    traj::Limits lim = traj::DefaultLimits();
    lim.profile = prof ? traj::kTrapezoid : traj::kQuintic;
    traj::Player pl;
    pl.Begin(&m, &p, 0.001);
    pl.Init(p.start);
    RunStats st;
    const bool done = Run(&pl, lim, 60000, &st);
    CHECK(done, "profile %d did not finish in %llu cycles", prof, (unsigned long long)st.cycles);
    for (int j = 0; j < 6; ++j)
      CHECK(std::fabs(pl.q_out()[j] - p.motions[2].v[j]) < 1e-9, "final joint %d off by %g",
            j + 1, pl.q_out()[j] - p.motions[2].v[j]);
    // Velocity within the limits; acceleration within the planning limit (+ rounding of the
    // finite differences), so the limiter never had to act on a clean program.
    CHECK(st.max_v_ratio <= 1.0 + 1e-9, "profile %d speed ratio %g", prof, st.max_v_ratio);
    CHECK(st.max_a <= lim.accel * 1.02 + 1e-6, "profile %d accel %g > %g", prof, st.max_a,
          lim.accel);
    CHECK(pl.limited_cycles() == 0, "profile %d limiter acted %llu times", prof,
          (unsigned long long)pl.limited_cycles());
    printf("profile %s: %llu cycles, max speed %.3f of vmax, max accel %.3f rad/s^2\n",
           prof ? "trapezoid" : "quintic", (unsigned long long)st.cycles, st.max_v_ratio,
           st.max_a);
  }
}


// Distance from point p to the segment [a, b] (joint space, Euclidean).
static double SegDist(const Q& p, const Q& a, const Q& b) {
  const Q ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0 ? std::min(1.0, std::max(0.0, (p - a).dot(ab) / l2)) : 0.0;
  return (a + t * ab - p).norm();
}

static void TestTrajectoryVia() {
  // 40 via points on a joint-space curve and the closing ptp: one smooth motion through every
  // point, every cycle within the limits, faster than stopping at each point.
  Model m;
  std::string text = "arflex-program 1\nstart 0 0.2 0.5 0 0.6 0\n";
  std::vector<Q> pts;
  for (int i = 1; i <= 41; ++i) {
    const double a = i * 0.05;
    Q q;
    q << 0.4 * std::sin(a), 0.2 + 0.15 * (1 - std::cos(a)), 0.5 + 0.1 * std::sin(2 * a), 0.3 * a / 2,
        0.6 - 0.2 * std::sin(a), 0.1 * a;
    pts.push_back(q);
    char line[256];
    snprintf(line, sizeof(line), "%s %.12f %.12f %.12f %.12f %.12f %.12f\n", i < 41 ? "via" : "ptp",
             q[0], q[1], q[2], q[3], q[4], q[5]);
    text += line;
  }
  Program p, chain;
  std::string err;
  CHECK(arflex::cellkin::ParseProgram(text, "via", m, &p, &err), "%s", err.c_str());
  std::string ptext = text;
  for (size_t k = 0; (k = ptext.find("via", k)) != std::string::npos;) ptext.replace(k, 3, "ptp");
  CHECK(arflex::cellkin::ParseProgram(ptext, "chain", m, &chain, &err), "%s", err.c_str());
  for (int prof = 0; prof < 2; ++prof) {
    traj::Limits lim = traj::DefaultLimits();
    lim.profile = prof ? traj::kTrapezoid : traj::kQuintic;
    traj::Player pl;
    pl.Begin(&m, &p, 0.001);
    pl.Init(p.start);
    RunStats st;
    std::vector<Q> out;
    Q prev = pl.q_out(), prev_v = Q::Zero();
    while (!pl.done() && st.cycles < 100000) {
      pl.Step(lim, 1.0, false);
      const Q v = (pl.q_out() - prev) / 0.001;
      for (int j = 0; j < 6; ++j) {
        st.max_v_ratio = std::max(st.max_v_ratio, std::fabs(v[j]) / lim.vmax[j]);
        st.max_a = std::max(st.max_a, std::fabs(v[j] - prev_v[j]) / 0.001);
      }
      prev = pl.q_out();
      prev_v = v;
      out.push_back(pl.q_out());
      st.cycles++;
    }
    CHECK(pl.done(), "via path did not finish");
    double worst = 0;
    for (const Q& w : pts) {
      double best = 1e9;
      for (size_t i = 1; i < out.size(); ++i) best = std::min(best, SegDist(w, out[i - 1], out[i]));
      worst = std::max(worst, best);
    }
    traj::Player pc;
    pc.Begin(&m, &chain, 0.001);
    pc.Init(chain.start);
    RunStats sc;
    Run(&pc, lim, 200000, &sc);
    printf("via (%s): %llu cycles (ptp chain %llu), through every point within %.2e rad, "
           "max speed %.3f of vmax, max accel %.3f\n",
           prof ? "trapezoid" : "quintic", (unsigned long long)st.cycles,
           (unsigned long long)sc.cycles, worst, st.max_v_ratio, st.max_a);
    CHECK(worst < 1e-6, "missed a via point by %g rad", worst);
    CHECK(st.max_v_ratio <= 1 + 1e-9, "speed %g", st.max_v_ratio);
    CHECK(st.max_a <= lim.accel * 1.05, "accel %g > %g", st.max_a, lim.accel);
    CHECK(pl.limited_cycles() == 0, "limiter acted %llu times", (unsigned long long)pl.limited_cycles());
    CHECK(st.cycles * 2 < sc.cycles, "via path not faster than stopping at each point");
    CHECK((pl.q_out() - pts.back()).norm() < 1e-12, "end");
  }
  // A via run must be closed by a ptp.
  CHECK(!arflex::cellkin::ParseProgram("arflex-program 1\nvia 0 0 0 0 0 0\nwait 1\n", "v", m, &p,
                                       &err) &&
            err.rfind("v:2: via points must be followed by a ptp", 0) == 0,
        "unclosed via accepted or bad message: %s", err.c_str());
}


static void TestTrajectoryLoop() {
  // loop: the program starts again from wherever it ended, without a jump.
  Model m;
  Program p;
  std::string err;
  CHECK(arflex::cellkin::ParseProgram(
            "arflex-program 1\nstart 0 0 0 0 0 0\nptp 0.3 0.2 0.4 0 0.5 0\nptp -0.2 0.1 0.6 0.2 0.4 0.3\n",
            "loop", m, &p, &err),
        "%s", err.c_str());
  traj::Limits lim = traj::DefaultLimits();
  traj::Player pl;
  pl.Begin(&m, &p, 0.001);
  pl.Init(p.start);
  Q prev = pl.q_out(), prev_v = Q::Zero();
  double max_a = 0, max_v = 0;
  uint64_t k = 0;
  for (; k < 100000 && pl.completed() < 3; ++k) {
    pl.Step(lim, 1.0, true);
    const Q v = (pl.q_out() - prev) / 0.001;
    for (int j = 0; j < 6; ++j) {
      max_v = std::max(max_v, std::fabs(v[j]) / lim.vmax[j]);
      max_a = std::max(max_a, std::fabs(v[j] - prev_v[j]) / 0.001);
    }
    prev = pl.q_out();
    prev_v = v;
  }
  CHECK(pl.completed() == 3 && !pl.done(), "completed %llu done %d",
        (unsigned long long)pl.completed(), pl.done());
  CHECK(max_v <= 1 + 1e-9 && max_a <= lim.accel * 1.02, "limits v %g a %g", max_v, max_a);
  printf("loop: 3 passes in %llu cycles, max accel %.3f\n", (unsigned long long)k, max_a);
}

static double PauseRate(uint64_t k) { return (k > 700 && k < 2500) ? 0.0 : 1.0; }

static void TestTrajectoryPause() {
  Model m;
  Program p;
  std::string err;
  CHECK(arflex::cellkin::ParseProgram("arflex-program 1\nptp 1.0 0.4 0.6 0 0 0\n", "p", m, &p,
                                      &err),
        "%s", err.c_str());
  traj::Limits lim = traj::DefaultLimits();
  traj::Player pl;
  pl.Begin(&m, &p, 0.001);
  pl.Init(Q::Zero());
  RunStats st;
  // Paused in the middle of the motion: must stop smoothly (accel within accel_max), hold,
  // then resume and finish on the target.
  Q held;
  for (uint64_t k = 0; k < 2400; ++k) pl.Step(lim, PauseRate(k), false);
  held = pl.q_out();
  pl.Step(lim, 0.0, false);
  CHECK((pl.q_out() - held).norm() == 0, "moving while paused");
  CHECK(!pl.done() && held[0] > 0.01 && held[0] < 0.99, "paused at %g", held[0]);
  traj::Player pl2;
  pl2.Begin(&m, &p, 0.001);
  pl2.Init(Q::Zero());
  const bool done = Run(&pl2, lim, 20000, &st, PauseRate);
  CHECK(done, "did not finish after the pause");
  CHECK(st.max_v_ratio <= 1.0 + 1e-9 && st.max_a <= lim.accel_max * (1 + 1e-6),
        "limits: v %g a %g", st.max_v_ratio, st.max_a);
  CHECK(std::fabs(pl2.q_out()[0] - 1.0) < 1e-9, "final %g", pl2.q_out()[0]);
}

static void TestBuiltin() {
  // The built-in program of the trajectory component must run through with IK converging
  // on every lin cycle. (Same text as trajectory.cc's kBuiltin: read from the source file
  // would be nicer; the component's own test cell.trajectory runs it as a process.)
  Model m;
  Program p;
  std::string err;
  const char* text =
      "arflex-program 1\nstart 0 0 0 0 0 0\nptp 0 0.2 0.5 0 0.6 0\n"
      "lin 2.0 0.3 1.2 0.70710678 0 0.70710678 0 speed 0.4\n"
      "lin 2.0 -0.3 1.2 0.70710678 0 0.70710678 0 speed 0.4\n"
      "lin 1.7 -0.3 0.9 0.70710678 0 0.70710678 0 speed 0.4\n"
      "ptp 0.4 0.3 0.4 0 0.8 0.2 speed 0.5\nwait 0.5\nptp 0 0.2 0.5 0 0.6 0\n";
  CHECK(arflex::cellkin::ParseProgram(text, "builtin", m, &p, &err), "%s", err.c_str());
  printf("TCP at ptp 0 0.2 0.5 0 0.6 0: %s\n", "");
  Q q;
  q << 0, 0.2, 0.5, 0, 0.6, 0;
  const Eigen::Isometry3d t = m.Tcp(q);
  const Eigen::Quaterniond r(t.linear());
  printf("  p = %.4f %.4f %.4f  quat = %.6f %.6f %.6f %.6f\n", t.translation().x(),
         t.translation().y(), t.translation().z(), r.w(), r.x(), r.y(), r.z());
  traj::Limits lim = traj::DefaultLimits();
  traj::Player pl;
  pl.Begin(&m, &p, 0.001);
  pl.Init(p.start);
  RunStats st;
  CHECK(Run(&pl, lim, 200000, &st), "builtin did not finish");
  CHECK(pl.ik_warnings() == 0, "%llu IK warnings", (unsigned long long)pl.ik_warnings());
  CHECK(st.max_v_ratio <= 1 + 1e-9 && st.max_a <= lim.accel_max * (1 + 1e-6), "limits");
  printf("builtin: %llu cycles, limiter active %llu cycles, max accel %.2f\n",
         (unsigned long long)st.cycles, (unsigned long long)pl.limited_cycles(), st.max_a);
}

// Tool-aware kinematics and lin motions: TcpOf with the nominal tool equals Tcp; IkTool
// converges for a 0.35 m tool and for the flange; a lin motion planned for a tool moves that
// tool's centre point on the straight line; a tool change in the middle of a lin motion does
// not change that motion (it applies from the next one), so the reference never jumps.
static void TestTool() {
  Model m;
  Q q;
  q << 0.3, 0.2, 0.5, -0.4, 0.7, 0.1;
  CHECK((m.TcpOf(q, m.NominalTool()).matrix() - m.Tcp(q).matrix()).cwiseAbs().maxCoeff() < 1e-12,
        "TcpOf(nominal) != Tcp");
  Eigen::Isometry3d spindle = Eigen::Isometry3d::Identity();
  spindle.translation() = Eigen::Vector3d(0.35, 0, 0);
  for (const Eigen::Isometry3d& tool : {spindle, Eigen::Isometry3d(Eigen::Isometry3d::Identity())}) {
    // Jacobian against finite differences of the TCP position
    const arflex::cellmodel::Jacobian6 j = m.JacobianOf(q, tool);
    for (int k = 0; k < 6; ++k) {
      Q a = q, b = q;
      a[k] += 1e-7;
      b[k] -= 1e-7;
      const Eigen::Vector3d fd = (m.TcpOf(a, tool).translation() - m.TcpOf(b, tool).translation()) / 2e-7;
      CHECK((fd - j.col(k).head<3>()).norm() < 1e-5, "JacobianOf column %d off by %g", k,
            (fd - j.col(k).head<3>()).norm());
    }
    const Eigen::Isometry3d target = m.TcpOf(q, tool);
    Q q2 = q + Q::Constant(0.05);
    const double err = m.IkTool(target, tool, &q2, 20);
    CHECK(err < 1e-9, "IkTool error %g", err);
  }
  // A lin motion for the spindle: its TCP (not the nominal one) ends on the target and stays
  // on the line; the tool set mid-motion (flange) changes nothing until the next motion.
  Program p;
  std::string err;
  const char* text =
      "arflex-program 1\nstart 0 0.2 0.5 0 0.6 0\n"
      "lin 2.0 0.3 1.2 0.70710678 0 0.70710678 0 speed 0.4\n"
      "lin 2.0 -0.3 1.2 0.70710678 0 0.70710678 0 speed 0.4\n";
  CHECK(arflex::cellkin::ParseProgram(text, "tool", m, &p, &err), "%s", err.c_str());
  traj::Limits lim = traj::DefaultLimits();
  traj::Player pl;
  pl.Begin(&m, &p, 0.001);
  pl.Init(p.start);
  pl.SetTool(spindle);
  const Eigen::Vector3d a(2.0, 0.3, 1.2), b(2.0, -0.3, 1.2);
  const Eigen::Vector3d s0 = m.TcpOf(p.start, spindle).translation();
  double off_line = 0, max_dq = 0;
  Q prev = pl.q_out();
  bool switched = false, at_a = false;
  int cycles = 0;
  while (!pl.done() && cycles < 100000) {
    pl.Step(lim, 1.0, false);
    ++cycles;
    max_dq = std::max(max_dq, (pl.q_out() - prev).cwiseAbs().maxCoeff());
    prev = pl.q_out();
    if (pl.index() == 0) {  // first lin, planned for the spindle: its TCP on s0 -> a
      const Eigen::Vector3d x = m.TcpOf(pl.q_plan(), spindle).translation();
      const Eigen::Vector3d d = (a - s0).normalized();
      off_line = std::max(off_line, ((x - s0) - d.dot(x - s0) * d).norm());
      if (cycles == 500) {
        pl.SetTool(Eigen::Isometry3d::Identity());  // tool swap in the middle of the motion
        switched = true;
      }
    } else if (!at_a) {  // the first lin ended with the spindle's TCP on a
      at_a = true;
      CHECK((m.TcpOf(pl.q_plan(), spindle).translation() - a).norm() < 1e-6,
            "spindle TCP ended %g m off a", (m.TcpOf(pl.q_plan(), spindle).translation() - a).norm());
    }
  }
  CHECK(pl.done(), "program did not finish in %d cycles", cycles);
  CHECK(switched && at_a, "the swap or the end of the first lin was not reached");
  CHECK(off_line < 1e-6, "spindle TCP left the line by %g m", off_line);
  // The second lin began after the swap: planned for the flange, which ends on b.
  CHECK((m.Flange(pl.q_plan()).translation() - b).norm() < 1e-6, "flange ended %g m off b",
        (m.Flange(pl.q_plan()).translation() - b).norm());
  CHECK(pl.lin_tool().translation().norm() == 0, "the second lin did not take the new tool");
  CHECK(pl.ik_warnings() == 0, "%llu IK warnings", (unsigned long long)pl.ik_warnings());
  CHECK(pl.limited_cycles() == 0, "limiter acted %llu cycles", (unsigned long long)pl.limited_cycles());
  printf("tool: spindle lin off the line %.2e m, largest step %.2e rad, %d cycles\n", off_line, max_dq,
         cycles);
}

// InverseDynamics against independent derivations: at rest it is GravityTorque; its inertial
// part (the mass matrix, column by column) is symmetric and positive definite; its velocity
// terms match Lagrange's equations with the kinetic energy 1/2 qd' M(q) qd differentiated
// numerically; the tool's acceleration matches the Jacobian of the tool's centre of mass.
static Eigen::Matrix<double, 6, 6> MassMatrix(const Model& m, const Q& q, double payload) {
  Eigen::Matrix<double, 6, 6> mm;
  const Q g = m.GravityTorque(q, payload);
  for (int j = 0; j < 6; ++j) mm.col(j) = m.InverseDynamics(q, Q::Zero(), Q::Unit(j), payload) - g;
  return mm;
}

static void TestDynamics() {
  Model m;
  const double payload = 40;
  Q q, qd, qdd;
  q << 0.3, -0.4, 0.9, -0.6, 0.7, 0.2;
  qd << 0.5, -0.3, 0.8, 1.1, -0.9, 1.5;
  qdd << 2.0, -1.5, 3.0, -4.0, 5.0, -6.0;
  const Q g = m.GravityTorque(q, payload);
  const double rest = (m.InverseDynamics(q, Q::Zero(), Q::Zero(), payload) - g).cwiseAbs().maxCoeff();
  CHECK(rest < 1e-9, "at rest: inverse dynamics differs from GravityTorque by %g N m", rest);
  const Eigen::Matrix<double, 6, 6> mm = MassMatrix(m, q, payload);
  const double asym = (mm - mm.transpose()).cwiseAbs().maxCoeff();
  CHECK(asym < 1e-9 * mm.cwiseAbs().maxCoeff(), "mass matrix not symmetric: %g", asym);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(mm);
  CHECK(eig.eigenvalues().minCoeff() > 0, "mass matrix not positive definite: %g",
        eig.eigenvalues().minCoeff());
  for (int j = 0; j < 6; ++j)
    CHECK(mm(j, j) > m.arm().links[j].armature, "M(%d,%d) %.1f does not hold the armature", j, j,
          mm(j, j));
  // Lagrange: tau = M qdd + dM/dt qd - dT/dq + g, with T = 1/2 qd' M qd.
  const double h = 1e-6;
  auto kinetic = [&](const Q& qq) { return 0.5 * qd.dot(MassMatrix(m, qq, payload) * qd); };
  const Eigen::Matrix<double, 6, 6> mdot =
      (MassMatrix(m, q + h * qd, payload) - MassMatrix(m, q - h * qd, payload)) / (2 * h);
  Q dtdq;
  for (int i = 0; i < 6; ++i)
    dtdq[i] = (kinetic(q + h * Q::Unit(i)) - kinetic(q - h * Q::Unit(i))) / (2 * h);
  Q friction;
  for (int i = 0; i < 6; ++i) friction[i] = m.arm().links[i].damping * qd[i];
  const Q lagrange = mm * qdd + mdot * qd - dtdq + g + friction;
  Eigen::Vector3d a_tool;
  const Q rne = m.InverseDynamics(q, qd, qdd, payload, &a_tool);
  const double err = (rne - lagrange).cwiseAbs().maxCoeff();
  CHECK(err < 1e-4 * lagrange.cwiseAbs().maxCoeff(),
        "Newton-Euler and Lagrange differ by %g N m (torques up to %.0f N m)", err,
        lagrange.cwiseAbs().maxCoeff());
  // The tool's centre of mass: a = J qdd + dJ/dt qd (numerically along the motion).
  Eigen::Isometry3d com = Eigen::Isometry3d::Identity();
  com.translation() = Eigen::Vector3d(m.arm().tool_com[0], m.arm().tool_com[1], m.arm().tool_com[2]);
  auto lin = [&](const Q& qq) { return Eigen::Matrix<double, 3, 6>(m.JacobianOf(qq, com).topRows<3>()); };
  const Eigen::Matrix<double, 3, 6> jdot = (lin(q + h * qd) - lin(q - h * qd)) / (2 * h);
  const Eigen::Vector3d want = lin(q) * qdd + jdot * qd;
  CHECK((a_tool - want).norm() < 1e-4 * want.norm(), "tool acceleration (%.3f %.3f %.3f) want (%.3f %.3f %.3f)",
        a_tool.x(), a_tool.y(), a_tool.z(), want.x(), want.y(), want.z());
  printf("dynamics: M diag %.0f..%.0f kg m^2, Newton-Euler vs Lagrange %.2e N m, tool accel %.2e m/s^2\n",
         mm.diagonal().minCoeff(), mm.diagonal().maxCoeff(), err, (a_tool - want).norm());
}

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: %s <kinematics|dynamics|program|trajectory_limits|trajectory_pause|trajectory_via|trajectory_loop|builtin|tool>\n",
            argv[0]);
    return 2;
  }
  const std::string c = argv[1];
  if (c == "kinematics") TestKinematics();
  else if (c == "dynamics") TestDynamics();
  else if (c == "program") TestProgram();
  else if (c == "trajectory_limits") TestTrajectoryLimits();
  else if (c == "trajectory_pause") TestTrajectoryPause();
  else if (c == "trajectory_via") TestTrajectoryVia();
  else if (c == "trajectory_loop") TestTrajectoryLoop();
  else if (c == "builtin") TestBuiltin();
  else if (c == "tool") TestTool();
  else {
    fprintf(stderr, "unknown case '%s'\n", argv[1]);
    return 2;
  }
  if (failures) return 1;
  printf("ok %s\n", argv[1]);
  return 0;
}
