// trajectory - RT half of the trajectory component (README.md): plays a program of joint
// (ptp) and Cartesian straight-line (lin) motions and writes the joint reference every period.
//
// Ports: out joint_ref (arflex.JointRef, state); in safety (arflex.SafetyState, optional),
// in joint_state (arflex.JointState, optional: the first reference starts at the measured
// position; a robot bound later somewhere else restarts the program from there), in tool
// (arflex.ToolState, optional: lin motions move the mounted tool's centre point, the flange
// when none is mounted); out tool_id (arflex.Sample: the id of the tool lin
// motions are planned for, 0 = the flange). Parameters: see the contract (src/main/resources/OSGI-INF/arflex/trajectory.xml).
//
// Validated data (docs/safety.md): every value read from joint_state and tool is checked before
// use (the type's generated arflex_<type>_valid, then what this component needs of it). A
// rejected value is not used and is counted (update returns -EINVAL: stats.update_errors): a
// joint state neither starts nor restarts the program from the arm nor moves the idle output
// to it; a tool state leaves the last valid tool in use. The output is the player's as before.
//
// Threads: configure loads every program (main thread, file I/O); start/update/safe/stop run
// on the RT thread and only read the loaded programs: no allocation, I/O or printing there.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "arflex/component.h"
#include "arflex/safety_gate.h"
#include "arflex_types/joint_ref.h"
#include "arflex_types/joint_state.h"
#include "arflex_types/safety_state.h"
#include "arflex_types/sample.h"
#include "arflex_types/tool_state.h"
#include "arflex_types/trajectory_state.h"
#include "cellkin.h"
#include "trajectory_plan.h"

namespace {

using arflex::cellkin::Model;
using arflex::cellkin::Motion;
using arflex::cellkin::Program;
using arflex::cellkin::Q;
namespace traj = arflex::traj;

constexpr int kMaxPrograms = 100;  // program indices 0 (built-in) .. 99

// The built-in demonstration program (index 0): a loop through the work space in front of
// the robot, joint and Cartesian motions mixed. The lin targets are reachable from the
// preceding poses (checked by the cell.trajectory.builtin test). Slow on purpose: the
// simulated arm's drives move joint 2 at about 0.19 rad/s at most (its damping); a faster
// reference makes the arm lag and then stop abruptly, which the wrist reads as 170-410 N
// and the force guard (150 N) rightly takes for contact. 0.08 of the joint speed limits and
// 0.1 m/s keep the arm on the reference.
const char kBuiltin[] =
    "arflex-program 1\n"
    "# built-in demonstration program (trajectory, index 0)\n"
    "start 0 0 0 0 0 0\n"
    "ptp 0 0.2 0.5 0 0.6 0 speed 0.08\n"
    "lin 2.0 0.3 1.2 0.70710678 0 0.70710678 0 speed 0.1\n"
    "lin 2.0 -0.3 1.2 0.70710678 0 0.70710678 0 speed 0.1\n"
    "lin 1.7 -0.3 0.9 0.70710678 0 0.70710678 0 speed 0.1\n"
    "ptp 0.4 0.3 0.4 0 0.8 0.2 speed 0.08\n"
    "wait 0.5\n"
    "ptp 0 0.2 0.5 0 0.6 0 speed 0.08\n";

struct State {
  Model model;
  std::vector<Program> programs;  // index = program number; empty motions = not loaded
  struct arflex_port* out = nullptr;
  struct arflex_input* in_safety = nullptr;
  struct arflex_input* in_state = nullptr;
  struct arflex_input* in_tool = nullptr;
  struct arflex_port* out_tool = nullptr;
  struct arflex_tool_state tool{};
  bool tool_seen = false;
  int p_program = -1, p_run, p_loop, p_profile, p_speed, p_accel, p_accel_max, p_lin_speed,
      p_lin_accel, p_stop_time, p_safety_max_age = -1;
  traj::Player player;
  struct arflex_safety_gate gate{};
  bool permitted = false;    // the safety input permitted motion since start
  // Reset permits, it does not start (SAFETY.md 2): after a stop (a protective stop or loss
  // of the guard that had permitted motion, rt-core safe mode, a restart that needs a reset)
  // the output holds until a fresh command: a write of `run` (true) or `program` taken after
  // the stop's causes are gone. cmd_seq is CommandSeq (arflex_param_writes) as last seen
  // while the stop held, so commands sent before the reset are discarded.
  bool await_command = false;
  uint64_t cmd_seq = 0;
  uint64_t seq = 0;
  uint64_t tool_seq = 0;
  int64_t playing = 0;  // the program the player plays
  uint32_t state_binding = 0;  // joint_state binding the output last met the arm on
  uint64_t away_since = 0;     // release time since which the idle output is away from the arm
  struct arflex_trajectory_state state{};  // the state block published every cycle (D41)
  uint64_t state_seq = 0;
} g;

// A robot measured further than this from the output when it is (re)bound makes the program
// start over from the measured pose. Below sim-robot's ref_acquire_tol (0.05 rad), so that a
// robot which refuses the output as too far always gets a trajectory that comes to it.
constexpr double kResyncTol = 0.005;  // rad, any joint
// The arm measured at rest further than this from the output for kAwayNs is not following
// (its robot has no reference input yet, or refuses this one; sim-robot's ref_acquire_tol is
// the same 0.05 rad) and the trajectory comes to it (Step). A following arm settles well
// inside it, and tcp-correction's correction (arm = output + correction) is clamped at 0.02 rad.
constexpr double kAwayTol = 0.05;        // rad, any joint
constexpr uint64_t kAwayNs = 1000000000;  // 1 s
constexpr double kRestSpeed = 1e-3;       // rad/s, every joint: the arm is at rest
// A safety value older than this (in the trajectory's own cycles for half as long) is stale.
constexpr uint64_t kSafetyMaxAgeNs = 20000000;  // 20 ms

int Param(struct arflex_component* c, const char* name, int* idx) {
  *idx = arflex_component_param(c, name);
  if (*idx < 0) fprintf(stderr, "trajectory: parameter '%s' missing from the control block\n", name);
  return *idx;
}

int Adopt(struct arflex_component* c, void*, const struct arflex_adopted_state* a);

int Configure(struct arflex_component* c, void*) {
  static const struct arflex_port_type ref_t = {ARFLEX_TYPE_JOINT_REF_NAME, 1, 0,
                                                sizeof(struct arflex_joint_ref)};
  static const struct arflex_port_type safety_t = {ARFLEX_TYPE_SAFETY_STATE_NAME, 1, 0,
                                                   sizeof(struct arflex_safety_state)};
  static const struct arflex_port_type state_t = {ARFLEX_TYPE_JOINT_STATE_NAME, 1, 0,
                                                  sizeof(struct arflex_joint_state)};
  int r = arflex_component_output(c, "joint_ref", ARFLEX_PORT_STATE, &ref_t, &g.out);
  if (r < 0) {
    fprintf(stderr, "trajectory: output joint_ref: %s\n", strerror(-r));
    return r;
  }
  static const struct arflex_port_type tool_t = {ARFLEX_TYPE_TOOL_STATE_NAME, 1, 0,
                                                 sizeof(struct arflex_tool_state)};
  static const struct arflex_port_type sample_t = {ARFLEX_TYPE_SAMPLE_NAME, 1, 0,
                                                   sizeof(struct arflex_sample)};
  if ((r = arflex_component_output(c, "tool_id", ARFLEX_PORT_STATE, &sample_t, &g.out_tool)) < 0) {
    fprintf(stderr, "trajectory: output tool_id: %s\n", strerror(-r));
    return r;
  }
  // The state block (contract <state>, D41): handed to a new version at a change set's switch.
  // Without a state segment (a host test that makes none) publishing is a no-op.
  static const struct arflex_port_type traj_state_t = {
      ARFLEX_TYPE_TRAJECTORY_STATE_NAME, ARFLEX_TYPE_TRAJECTORY_STATE_VERSION_MAJOR,
      ARFLEX_TYPE_TRAJECTORY_STATE_VERSION_MINOR, sizeof(struct arflex_trajectory_state)};
  if ((r = arflex_component_state(c, &traj_state_t, nullptr)) < 0 && r != -ENOENT) {
    fprintf(stderr, "trajectory: state block: %s\n", strerror(-r));
    return r;
  }
  // D61: Adopt runs between two updates as well (it restores the player and the seqs only): at
  // the switch of an update whose new half ran in shadow it takes the old half's state again
  if ((r = arflex_component_readopt(c, Adopt)) < 0) return r;
  if ((r = arflex_component_input(c, "safety", ARFLEX_PORT_STATE, &safety_t, &g.in_safety)) < 0 ||
      (r = arflex_component_input(c, "joint_state", ARFLEX_PORT_STATE, &state_t, &g.in_state)) < 0 ||
      (r = arflex_component_input(c, "tool", ARFLEX_PORT_STATE, &tool_t, &g.in_tool)) < 0)
    return r;
  if (Param(c, "program", &g.p_program) < 0 || Param(c, "run", &g.p_run) < 0 ||
      Param(c, "loop", &g.p_loop) < 0 || Param(c, "profile", &g.p_profile) < 0 ||
      Param(c, "speed", &g.p_speed) < 0 || Param(c, "accel", &g.p_accel) < 0 ||
      Param(c, "accel_max", &g.p_accel_max) < 0 || Param(c, "lin_speed", &g.p_lin_speed) < 0 ||
      Param(c, "lin_accel", &g.p_lin_accel) < 0 || Param(c, "stop_time", &g.p_stop_time) < 0)
    return -ENOENT;
  g.p_safety_max_age = arflex_component_param(c, "safety_max_age_ms");  // optional

  g.programs.resize(kMaxPrograms);
  std::string err;
  if (!arflex::cellkin::ParseProgram(kBuiltin, "built-in program 0", g.model, &g.programs[0],
                                     &err)) {
    fprintf(stderr, "trajectory: %s\n", err.c_str());
    return -EINVAL;
  }
  const std::string dir = arflex::cellkin::DataDir();
  int loaded = 1;
  for (int n = 1; n < kMaxPrograms; ++n) {
    const std::string path = arflex::cellkin::ProgramPath(dir, n);
    FILE* f = fopen(path.c_str(), "r");
    if (!f) continue;
    fclose(f);
    if (!arflex::cellkin::LoadProgramFile(path, g.model, &g.programs[n], &err)) {
      fprintf(stderr, "trajectory: bad program file: %s\n", err.c_str());
      return -EINVAL;
    }
    ++loaded;
  }
  const int64_t sel = arflex_param_i64(c, g.p_program);
  fprintf(stderr, "trajectory: %d program(s) loaded (data dir %s); program %lld %s\n", loaded,
          dir.c_str(), (long long)sel,
          sel >= 0 && sel < kMaxPrograms && !g.programs[sel].motions.empty() ? "present"
                                                                            : "NOT present");
  return 0;
}

traj::Limits CurrentLimits(struct arflex_component* c) {
  traj::Limits l = traj::DefaultLimits();
  l.speed = arflex_param_f64(c, g.p_speed);
  l.accel = arflex_param_f64(c, g.p_accel);
  l.accel_max = arflex_param_f64(c, g.p_accel_max);
  l.lin_speed = arflex_param_f64(c, g.p_lin_speed);
  l.lin_accel = arflex_param_f64(c, g.p_lin_accel);
  l.stop_time = arflex_param_f64(c, g.p_stop_time);
  l.profile = arflex_param_i64(c, g.p_profile) == 1 ? traj::kTrapezoid : traj::kQuintic;
  return l;
}

// The safety input's freshness limit: the safety_max_age_ms parameter, 20 ms without it.
uint64_t SafetyMaxAgeNs(struct arflex_component* c) {
  return g.p_safety_max_age >= 0
             ? static_cast<uint64_t>(arflex_param_f64(c, g.p_safety_max_age) * 1e6)
             : kSafetyMaxAgeNs;
}

// Changes with every write of a command parameter (run, program).
uint64_t CommandSeq(struct arflex_component* c) {
  return arflex_param_writes(c, g.p_run) + arflex_param_writes(c, g.p_program);
}

int Start(struct arflex_component* c, void*) {
  const int64_t n = arflex_param_i64(c, g.p_program);
  if (n < 0 || n >= kMaxPrograms || g.programs[n].motions.empty()) return -ENOENT;
  const struct arflex_ctl* ctl = arflex_component_ctl(c);
  g.player.Begin(&g.model, &g.programs[n], ctl->config.period_ns * 1e-9);
  g.playing = n;
  g.tool_seen = false;
  g.permitted = false;
  arflex_safety_gate_init(&g.gate, g.in_safety, SafetyMaxAgeNs(c));
  // A restart of a component that moves hardware comes with a reset to take (the runtime
  // sets RESET_REQUIRED before the spawn): after it, wait for a fresh command too.
  g.await_command = (arflex_ctl_flags(ctl) & ARFLEX_FLAG_RESET_REQUIRED) != 0;
  g.cmd_seq = CommandSeq(c);
  return 0;
}

// True when a tool state value may be used: the contract's check, a known status, and for a
// mounted tool (id != 0, status not NONE) a finite TCP within 2 m of the flange with a unit
// quaternion. A value that says no tool is mounted is valid whatever its TCP fields hold.
bool ToolValid(const struct arflex_tool_state& t) {
  if (!arflex_tool_state_valid(&t) || t.status > ARFLEX_TOOL_STATE_STATUS_FAULT) return false;
  if (t.tool_id == 0 || t.status == ARFLEX_TOOL_STATE_STATUS_NONE) return true;
  const Eigen::Vector3d p(t.tcp_p[0], t.tcp_p[1], t.tcp_p[2]);
  const Eigen::Vector4d r(t.tcp_quat[0], t.tcp_quat[1], t.tcp_quat[2], t.tcp_quat[3]);
  return p.allFinite() && r.allFinite() && std::fabs(r.norm() - 1.0) < 1e-3 && p.norm() < 2.0;
}

// The mounted tool: its TCP for the lin motions that begin from now on. No tool component
// bound, none written yet, or one that reports no tool (id 0, STATUS_NONE) is the flange. An
// invalid value (ToolValid) is not used: the last valid one stays in use and *err is set to
// -EINVAL (counted). Returns the id of the tool in use (0 = the flange).
uint32_t TrackTool(int* err) {
  struct arflex_tool_state t;
  if (!arflex_input_bound(g.in_tool)) {
    g.tool_seen = false;
  } else if (arflex_input_state_read(g.in_tool, &t, sizeof(t), nullptr) == 1) {
    if (ToolValid(t)) {
      g.tool = t;
      g.tool_seen = true;
    } else {
      arflex_input_reject(g.in_tool);
      *err = -EINVAL;
    }
  }
  Eigen::Isometry3d tcp = Eigen::Isometry3d::Identity();
  uint32_t id = 0;
  if (g.tool_seen && g.tool.tool_id != 0 && g.tool.status != ARFLEX_TOOL_STATE_STATUS_NONE) {
    const Eigen::Vector3d p(g.tool.tcp_p[0], g.tool.tcp_p[1], g.tool.tcp_p[2]);
    const Eigen::Quaterniond r(g.tool.tcp_quat[0], g.tool.tcp_quat[1], g.tool.tcp_quat[2],
                               g.tool.tcp_quat[3]);
    tcp.translation() = p;
    tcp.linear() = r.normalized().toRotationMatrix();
    id = g.tool.tool_id;
  }
  g.player.SetTool(tcp);
  return id;
}

// ---- the state block (D41) --------------------------------------------------------------

template <int N, typename V>
void Put(double (&dst)[N], const V& v) {
  for (int i = 0; i < N; ++i) dst[i] = v[i];
}

// Writes where the player is and the component's own command state into the state block.
void PublishState(struct arflex_component* c, uint64_t release_ns) {
  if (!arflex_component_state_open(c)) return;
  const traj::Snapshot s = g.player.Save();
  struct arflex_trajectory_state& st = g.state;
  st.t_ns = (int64_t)release_ns;
  st.seq = ++g.state_seq;
  st.program = g.playing;
  st.index = s.index;
  st.run_begin = s.run_begin;
  st.run_n = s.run_n;
  st.cursor = s.cursor;
  st.out_seq = g.seq;
  st.tool_seq = g.tool_seq;
  st.completed = s.completed;
  st.flags = (s.initialized ? ARFLEX_TRAJECTORY_STATE_FLAG_INITIALIZED : 0u) |
             (s.done ? ARFLEX_TRAJECTORY_STATE_FLAG_DONE : 0u) |
             (s.active ? ARFLEX_TRAJECTORY_STATE_FLAG_ACTIVE : 0u) |
             (s.path ? ARFLEX_TRAJECTORY_STATE_FLAG_PATH : 0u) |
             (g.permitted ? ARFLEX_TRAJECTORY_STATE_FLAG_PERMITTED : 0u) |
             (g.await_command ? ARFLEX_TRAJECTORY_STATE_FLAG_AWAIT_COMMAND : 0u);
  st.profile = (uint32_t)s.profile;
  st.rate = s.rate;
  st.tau = s.tau;
  st.shape_t = s.shape_t;
  st.shape_ta = s.shape_ta;
  st.path_len = s.path_len;
  st.cursor_sigma = s.cursor_sigma;
  Put(st.q0, s.q0);
  Put(st.dq, s.dq);
  Put(st.p0, s.p0);
  Put(st.p1, s.p1);
  const double r0[4] = {s.r0.w(), s.r0.x(), s.r0.y(), s.r0.z()};
  const double r1[4] = {s.r1.w(), s.r1.x(), s.r1.y(), s.r1.z()};
  Put(st.r0, r0);
  Put(st.r1, r1);
  Put(st.ik_q, s.ik_q);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) st.tool[3 * i + j] = s.tool.linear()(i, j);
  for (int i = 0; i < 3; ++i) st.tool[9 + i] = s.tool.translation()[i];
  Put(st.q_plan, s.q_plan);
  Put(st.q_plan_prev, s.q_plan_prev);
  Put(st.q_out, s.q_out);
  Put(st.v_out, s.v_out);
  arflex_component_state_publish(c, &st, sizeof(st), release_ns);
}

template <typename V, int N>
void Get(V* dst, const double (&src)[N]) {
  for (int i = 0; i < N; ++i) (*dst)[i] = src[i];
}

// The adopt hook (D41): right after Start at the switch of a change set's update, the state
// the running version published last. arflex.TrajectoryState 1.x is taken as it is; anything
// else is refused (-EPROTOTYPE: the START is refused), as is a state that does not fit the
// loaded programs (-ENOENT, -EINVAL). The reference then goes on from the old half's last one.
int Adopt(struct arflex_component* c, void*, const struct arflex_adopted_state* a) {
  struct arflex_trajectory_state st;
  if (std::strcmp(a->type_name, ARFLEX_TYPE_TRAJECTORY_STATE_NAME) != 0 ||
      a->major != ARFLEX_TYPE_TRAJECTORY_STATE_VERSION_MAJOR || a->length < sizeof(st))
    return -EPROTOTYPE;
  std::memcpy(&st, a->data, sizeof(st));
  if (!arflex_trajectory_state_valid(&st) || st.profile > traj::kTrapezoid) return -EINVAL;
  if (st.program < 0 || st.program >= kMaxPrograms || g.programs[st.program].motions.empty())
    return -ENOENT;
  traj::Snapshot s;
  s.initialized = (st.flags & ARFLEX_TRAJECTORY_STATE_FLAG_INITIALIZED) != 0;
  s.done = (st.flags & ARFLEX_TRAJECTORY_STATE_FLAG_DONE) != 0;
  s.active = (st.flags & ARFLEX_TRAJECTORY_STATE_FLAG_ACTIVE) != 0;
  s.path = (st.flags & ARFLEX_TRAJECTORY_STATE_FLAG_PATH) != 0;
  s.index = st.index;
  s.run_begin = st.run_begin;
  s.run_n = st.run_n;
  s.cursor = st.cursor;
  s.completed = st.completed;
  s.profile = st.profile == 1 ? traj::kTrapezoid : traj::kQuintic;
  s.rate = st.rate;
  s.tau = st.tau;
  s.shape_t = st.shape_t;
  s.shape_ta = st.shape_ta;
  s.path_len = st.path_len;
  s.cursor_sigma = st.cursor_sigma;
  Get(&s.q0, st.q0);
  Get(&s.dq, st.dq);
  Get(&s.p0, st.p0);
  Get(&s.p1, st.p1);
  s.r0 = Eigen::Quaterniond(st.r0[0], st.r0[1], st.r0[2], st.r0[3]);
  s.r1 = Eigen::Quaterniond(st.r1[0], st.r1[1], st.r1[2], st.r1[3]);
  Get(&s.ik_q, st.ik_q);
  s.tool = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s.tool.linear()(i, j) = st.tool[3 * i + j];
  for (int i = 0; i < 3; ++i) s.tool.translation()[i] = st.tool[9 + i];
  Get(&s.q_plan, st.q_plan);
  Get(&s.q_plan_prev, st.q_plan_prev);
  Get(&s.q_out, st.q_out);
  Get(&s.v_out, st.v_out);
  const struct arflex_ctl* ctl = arflex_component_ctl(c);
  if (!g.player.Restore(s, &g.model, &g.programs[st.program], ctl->config.period_ns * 1e-9))
    return -EINVAL;
  g.playing = st.program;
  g.seq = st.out_seq;
  g.tool_seq = st.tool_seq;
  g.state_seq = st.seq;
  g.permitted = (st.flags & ARFLEX_TRAJECTORY_STATE_FLAG_PERMITTED) != 0;
  // a stop the old half was holding on holds here too (and a reset this half needs, from Start)
  g.await_command = g.await_command || (st.flags & ARFLEX_TRAJECTORY_STATE_FLAG_AWAIT_COMMAND) != 0;
  g.cmd_seq = CommandSeq(c);  // this process's own write counters
  // the arm was met through the old half's joint_state binding: this binding is no new robot
  g.state_binding = arflex_input_binding(g.in_state);
  g.away_since = 0;
  return 0;
}

int Step(struct arflex_component* c, uint64_t release_ns, bool force_stop) {
  int input_err = 0;  // an input value rejected this cycle (-EINVAL), returned at the end
  struct arflex_sample tool_id;
  tool_id.seq = ++g.tool_seq;
  tool_id.t_ns = (int64_t)release_ns;
  tool_id.value = (double)TrackTool(&input_err);
  int r = arflex_state_write(g.out_tool, &tool_id, sizeof(tool_id));
  if (r < 0) return r;
  // The arm: the first reference starts where it is; and a robot that appears later, or is
  // replaced or restarted (another joint_state binding), somewhere else than the output, makes
  // the program start over from where that arm is (from its first motion, at rest), instead
  // of the reference pulling the arm across to where the program had got to.
  // A joint state that fails its contract (a non-finite q, qd or tau) is not used (counted).
  struct arflex_joint_state js;
  bool measured = arflex_input_state_read(g.in_state, &js, sizeof(js), nullptr) == 1;
  if (measured && !arflex_joint_state_valid(&js)) {
    arflex_input_reject(g.in_state);
    measured = false;
    input_err = -EINVAL;
  }
  Q qm;
  for (int j = 0; j < 6; ++j) qm[j] = measured ? js.q[j] : 0.0;
  const bool arm = measured;
  const uint32_t binding = arflex_input_binding(g.in_state);
  if (arm && binding != 0 && binding != g.state_binding) {
    g.state_binding = binding;
    if (!g.player.initialized()) {
      g.player.Init(qm);
    } else if ((qm - g.player.q_out()).cwiseAbs().maxCoeff() > kResyncTol) {
      g.player.Begin(&g.model, &g.programs[g.playing], arflex_component_ctl(c)->config.period_ns * 1e-9);
      g.player.Init(qm);
    }
  }
  if (!g.player.initialized()) {
    if (arflex_input_bound(g.in_state)) return input_err;  // wait for the first valid measurement
    g.player.Init(g.player.program()->has_start ? g.player.program()->start : Q::Zero());
  }
  // The safety input: bound, it must permit (fresh, valid, not stopped). Unbound from the
  // start the trajectory plays (the robot, which moves the hardware, holds without a guard);
  // a guard that had permitted motion and is gone stops it like a protective stop.
  g.gate.max_age_ns = SafetyMaxAgeNs(c);
  const arflex_safety_verdict verdict = arflex_safety_gate_check(&g.gate, arflex_sys_now_ns());
  // Before the guard first permitted, a bound one that has not spoken holds (no stop: nothing
  // moved yet); a stop once it had permitted, or rt-core safe mode, needs the fresh command.
  const bool permits = arflex_safety_permits(verdict) ||
                       (verdict == ARFLEX_SAFETY_NO_PROVIDER && !g.permitted);
  const bool stop_cause = force_stop || !permits;
  if (force_stop || (g.permitted && !permits)) g.await_command = true;
  if (arflex_safety_permits(verdict)) g.permitted = true;
  if (g.await_command) {
    const uint64_t cmd = CommandSeq(c);
    if (stop_cause) {
      g.cmd_seq = cmd;  // commands while the cause holds are discarded
    } else if (cmd != g.cmd_seq && arflex_param_bool(c, g.p_run)) {
      g.await_command = false;  // the fresh command after the reset
    }
  }
  if (!permits) {
    arflex_component_hold(c, ARFLEX_HOLD_SAFETY_INPUT, verdict, arflex_input_index(c, g.in_safety));
  } else if (g.await_command && !force_stop) {
    arflex_component_hold(c, ARFLEX_HOLD_AWAIT_COMMAND, 0, 0);
  } else {
    arflex_component_hold(c, ARFLEX_HOLD_NONE, 0, 0);
  }
  const bool stopped_on_purpose = stop_cause || g.await_command;
  // The arm does not follow: measured at rest further than kAwayTol from the output for
  // kAwayNs (its robot has no reference input yet, or holds, or refuses this reference as too
  // far from it). The trajectory comes to the arm: idle, the output moves there and the next
  // motion starts there; in a motion, the program starts over from its first motion at the arm
  // (as for a robot that appears). Not while a protective stop or safe mode holds on purpose:
  // those resume where they stopped. Once the stop's causes are gone and only the fresh
  // command is awaited, the rule holds again: a robot that takes only a reference at rest near
  // the arm after a stop (sim-robot) and an arm pushed or stopped further away than that would
  // otherwise wait for each other for ever. Moving the held output to an arm at rest starts no
  // motion (the rate stays 0 until the command).
  bool at_rest = arm;
  for (int j = 0; at_rest && j < 6; ++j) at_rest = std::fabs(js.qd[j]) < kRestSpeed;
  if (!arflex_input_bound(g.in_state) || stop_cause) {
    g.away_since = 0;
  } else if (arm) {
    if ((qm - g.player.q_out()).cwiseAbs().maxCoeff() <= kAwayTol || !at_rest) {
      g.away_since = 0;
    } else if (g.away_since == 0) {
      g.away_since = release_ns;
    } else if (release_ns - g.away_since >= kAwayNs) {
      if (!g.player.idle()) {
        g.player.Begin(&g.model, &g.programs[g.playing], arflex_component_ctl(c)->config.period_ns * 1e-9);
      }
      g.player.Init(qm);
      g.away_since = 0;
    }
  }
  // Target time rate: 0 = hold (stopped, or waiting for the fresh command).
  double rate = arflex_param_bool(c, g.p_run) ? 1.0 : 0.0;
  if (stopped_on_purpose) rate = 0;
  if (verdict == ARFLEX_SAFETY_LIMITED) rate = std::min(rate, arflex_safety_gate_scale(&g.gate));
  // Another program selected while running: taken at the next standstill (between motions,
  // at the end, or paused), from where the arm is. One that was not loaded when the RT half
  // started is refused (-ENOENT, counted by rt-core as an update error) and the current one
  // goes on.
  const int64_t want = arflex_param_i64(c, g.p_program);
  int switch_err = 0;
  if (want != g.playing) {
    if (want < 0 || want >= kMaxPrograms || g.programs[want].motions.empty()) {
      switch_err = -ENOENT;
    } else if (g.player.at_rest()) {
      g.player.Switch(&g.programs[want]);
      g.playing = want;
    }
  }
  const traj::Limits lim = CurrentLimits(c);
  g.player.Step(lim, rate, arflex_param_bool(c, g.p_loop));
  struct arflex_joint_ref ref;
  ref.t_ns = (int64_t)release_ns;
  ref.seq = ++g.seq;
  for (int j = 0; j < 6; ++j) ref.q[j] = g.player.q_out()[j];
  r = arflex_state_write(g.out, &ref, sizeof(ref));
  if (r < 0) return r;
  PublishState(c, release_ns);
  return input_err < 0 ? input_err : switch_err;
}

int Update(struct arflex_component* c, void*, uint64_t release_ns) {
  return Step(c, release_ns, false);
}

// rt-core safe mode (runtime heartbeat lost): stop along the path as fast as the limits
// allow, then hold.
int Safe(struct arflex_component* c, void*, enum arflex_safe_mode, bool) {
  const uint64_t now = arflex_sys_now_ns();
  if (!g.player.initialized()) return 0;
  return Step(c, now, true);
}

const struct arflex_component_ops kOps = {
    "trajectory", nullptr, Configure, Start, Update, nullptr, nullptr, Safe, Adopt,
};

}  // namespace

int main(int argc, char** argv) { return arflex_component_main(argc, argv, &kOps); }
