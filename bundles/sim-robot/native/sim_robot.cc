// sim-robot: the RT half of the simulated robot (simulator/README.md, "As components").
//
// One period = steps_per_period physics steps of the TRUE arm (1 ms each), lock-step with the
// RT loop: the arm's own joint position servo follows the joint reference read from
// `joint_ref` (arflex.JointRef); a correction is added upstream, never here. Outputs:
// `joint_state` (arflex.JointState: motor angles, velocities, measured drive torques) and
// `wrench` (arflex.Wrench: wrist F/T in the flange frame). Evaluation runs also get the
// ground truth in `truth` (eval.GroundTruth, not a contract port; see ground_truth.h).
//
// Safety input `safety` (arflex.SafetyState, role=safety: the force guard) permits motion
// (SPEC §5.3 safety inputs, docs/safety.md): the servo follows joint_ref only while the
// guard is bound, has spoken since it was bound, is fresh (safety_max_age_ms) and valid and
// not in a protective stop (arflex/safety_gate.h). Otherwise the arm stops (a controlled
// 20 ms stop, Cell::Stop) and holds where it stopped (a protective stop); losing a guard that had permitted motion also latches an operator
// reset. Its power_scale limits the drives (Cell::SetPowerScale: the servo's corrective
// torque saturates at that fraction of each drive's max torque). The fraction applied is
// published on `servo_power` (arflex.Sample) every period.
//
// Validated data (docs/safety.md): every joint_ref value is checked before use, with the
// type's generated arflex_joint_ref_valid (q finite) and against the arm's joint limits. A
// rejected value never reaches the servo: the last valid reference (or, before one was
// acquired, the held measured pose) stays, the value is counted as an update error (-EINVAL
// non-finite, -ERANGE outside the limits), and until a valid value comes the hold word says
// REFERENCE / ARFLEX_HOLD_REF_INVALID with the input's index (the DRCR names the provider).
//
// Scripted disturbances come from parameters (see the contract, sim-robot.xml). The safe hook
// stops the arm the same way and holds it.
//
// A cycle after a stall stands for every whole period elapsed since the world was last
// simulated, by the clock at its start (PeriodClock, D77): the physics steps steps_per_period
// for each of them (at most kMaxCatchUpPeriods), with the servo's
// reference moved from the one it had to the new one in equal parts, because the world does not
// stop while the host does not run this half: a real arm's servo goes on, and the motion sources
// (other processes) went on moving the reference. Stepping one period instead made the arm follow
// a reference several periods ahead at once, and the step read as contact force (D75).
//
// Everything is allocated in configure; update/safe only step the Cell (no allocation, no
// printing, no blocking).
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <arflex/component.h>
#include <arflex/safety_gate.h>
#include <arflex_types/joint_ref.h>
#include <arflex_types/joint_state.h>
#include <arflex_types/safety_state.h>
#include <arflex_types/sample.h>
#include <arflex_types/wrench.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "arflex_sim/cell.h"
#include "arflex_sim/ground_truth.h"
#include "arflex_sim/params.h"
#include "period_clock.h"

namespace {

using arflex::sim::Cell;
using arflex::sim::CellConfig;
using arflex::sim::HandGuideSpec;
using arflex::sim::JointVector;
using arflex::sim::kNumJoints;
using arflex::sim::PushSpec;
using arflex::sim::Vec3;

// Home pose: the arm in front of the cameras, tool tags visible (simulator/README.md).
constexpr JointVector kHome = {0.0, 0.5, 0.3, 0.0, 0.8, 0.0};

const arflex_port_type kJointRefType = {ARFLEX_TYPE_JOINT_REF_NAME,
                                        ARFLEX_TYPE_JOINT_REF_VERSION_MAJOR,
                                        ARFLEX_TYPE_JOINT_REF_VERSION_MINOR,
                                        ARFLEX_TYPE_JOINT_REF_SIZE};
const arflex_port_type kJointStateType = {ARFLEX_TYPE_JOINT_STATE_NAME,
                                          ARFLEX_TYPE_JOINT_STATE_VERSION_MAJOR,
                                          ARFLEX_TYPE_JOINT_STATE_VERSION_MINOR,
                                          ARFLEX_TYPE_JOINT_STATE_SIZE};
const arflex_port_type kWrenchType = {ARFLEX_TYPE_WRENCH_NAME, ARFLEX_TYPE_WRENCH_VERSION_MAJOR,
                                      ARFLEX_TYPE_WRENCH_VERSION_MINOR, ARFLEX_TYPE_WRENCH_SIZE};
const arflex_port_type kSafetyType = {ARFLEX_TYPE_SAFETY_STATE_NAME,
                                      ARFLEX_TYPE_SAFETY_STATE_VERSION_MAJOR,
                                      ARFLEX_TYPE_SAFETY_STATE_VERSION_MINOR,
                                      ARFLEX_TYPE_SAFETY_STATE_SIZE};
const arflex_port_type kSampleType = {ARFLEX_TYPE_SAMPLE_NAME, ARFLEX_TYPE_SAMPLE_VERSION_MAJOR,
                                      ARFLEX_TYPE_SAMPLE_VERSION_MINOR, ARFLEX_TYPE_SAMPLE_SIZE};
const arflex_port_type kTruthType = {ARFLEX_SIM_TRUTH_TYPE_NAME, ARFLEX_SIM_TRUTH_VERSION_MAJOR,
                                     ARFLEX_SIM_TRUTH_VERSION_MINOR, ARFLEX_SIM_TRUTH_SIZE};

// Parameter names (the contract's properties). A parameter missing from the control block
// takes the default given here, so the RT half also runs under a host that sets only some.
enum Param {
  kStepsPerPeriod, kSeed, kPayloadKg, kPayloadKnown,
  kPushForce, kPushDirX, kPushDirY, kPushDirZ, kPushDurationMs,
  kObstacleEnable, kObstacleX, kObstacleY, kObstacleZ,
  kGuideForce, kGuideDx, kGuideDy, kGuideDz, kGuideDurationMs,
  kRefAcquireTol, kSafetyMaxAgeMs,
  kParamCount
};
struct ParamInfo {
  const char* name;
  double def;  // default when absent (bool: 0/1, int: integral)
  char kind;   // 'd' double, 'i' int, 'b' bool
};
const ParamInfo kParams[kParamCount] = {
    {"steps_per_period", 1, 'i'}, {"seed", 1, 'i'},
    {"payload_kg", 0, 'd'},       {"payload_known", 1, 'b'},
    {"push_force_n", 0, 'd'},     {"push_dir_x", 0, 'd'},
    {"push_dir_y", 1, 'd'},       {"push_dir_z", 0, 'd'},
    {"push_duration_ms", 200, 'd'},
    {"obstacle_enable", 0, 'b'},  {"obstacle_x", 1.8, 'd'},
    {"obstacle_y", 0.0, 'd'},     {"obstacle_z", 1.0, 'd'},
    {"guide_force_n", 0, 'd'},    {"guide_dx", 0.0, 'd'},
    {"guide_dy", 0.2, 'd'},       {"guide_dz", 0.0, 'd'},
    {"guide_duration_ms", 2000, 'd'},
    {"ref_acquire_tol", 0.05, 'd'},
    {"safety_max_age_ms", 20, 'd'},
};

// A step of up to ref_acquire_tol (0.05 rad) taken by the servo at once puts hundreds of
// newtons on the tool (the force guard trips at 150 N); over 0.5 s with a quintic the peak
// acceleration is 5.77 * 0.05 / 0.25 = 1.15 rad/s^2 (about 60 N on the 25 kg tool at 2 m).
constexpr double kBlendSeconds = 0.5;
// After a stop: a reference is "at rest" when kRestValues values in a row stay within
// kRestTol of the first of them (a motion source decelerating from its stop moves far more; a
// vision correction's noise moves far less), and it "moves" (the fresh command) once it leaves
// kMoveTol of the value acquired.
constexpr int kRestValues = 50;
constexpr double kRestTol = 1e-4;  // rad, any joint
constexpr double kMoveTol = 5e-4;  // rad, any joint
// The most periods one release catches up after a stall (50 ms at 1 ms): a longer stall loses
// the rest of the world's time (PeriodClock::lost) rather than stepping without bound.
constexpr int kMaxCatchUpPeriods = 50;

struct Robot {
  std::unique_ptr<Cell> cell;
  arflex_port* joint_state = nullptr;
  arflex_port* wrench = nullptr;
  arflex_port* truth = nullptr;  // only in evaluation runs
  arflex_input* joint_ref = nullptr;
  arflex_input* safety = nullptr;
  arflex_port* servo_power = nullptr;
  arflex_safety_gate gate{};
  bool guard_hold = false;       // holding because the safety input does not permit motion
  bool guard_permitted = false;  // the safety input permitted motion since start
  bool loss_latched = false;     // the reset for this loss of the guard is latched
  int idx[kParamCount];
  // Change detection of the disturbance parameters (applied at the cycle they change).
  double push_sig[5];
  double obstacle_sig[4];
  double guide_sig[5];
  double payload_sig[2];
  bool first_cycle = true;
  std::vector<PushSpec> push_buf;  // one element, allocated in configure
  uint64_t cycles = 0;
  uint64_t seq = 0;
  PeriodClock clock{kMaxCatchUpPeriods};
  uint64_t periods = 0;  // periods simulated: one per cycle plus those caught up after stalls
  bool safe = false;
  JointVector q_ref = kHome;
  // Reference acquisition: the servo follows joint_ref only once a value from the current
  // binding came within ref_acquire_tol of the measured arm (see Update).
  uint32_t ref_binding = 0;
  bool acquired = false;
  bool refusing = false;  // refusals in this episode counted once
  bool ref_invalid = false;  // the newest joint_ref value was rejected: the last valid one holds
  // Blend-in after an acquisition: the servo follows ref - blend_offset * (1 - s(t)), s a
  // quintic from 0 to 1 over kBlendSeconds of simulated time, so the offset between the held
  // pose and the acquired reference is taken up smoothly instead of as a step.
  JointVector blend_offset{};
  double blend_t = kBlendSeconds;  // simulated seconds since the acquisition; >= kBlendSeconds: done
  // Reset permits, it does not start (SAFETY.md 2): after a stop (a safety hold or safe mode)
  // the held pose is kept, offset and all, while the acquired reference stays the same; the
  // blend starts when the reference moves (the motion source's fresh command), not at the reset.
  // After a stop, a reference is acquired only once it has been at rest for kRestValues
  // values: a motion source still decelerating from its own stop is not a reference to move
  // to. Counted in rest_values against rest_ref.
  bool after_stop = false;
  bool hold_stops_motion = false;
  bool blend_wait = false;
  JointVector wait_ref{};
  JointVector rest_ref{};
  int rest_values = 0;
};

Robot g_robot;

double P(const arflex_component* c, const Robot& r, Param p) {
  const int i = r.idx[p];
  if (i < 0) return kParams[p].def;
  switch (kParams[p].kind) {
    case 'i': return static_cast<double>(arflex_param_i64(c, i));
    case 'b': return arflex_param_bool(c, i) ? 1.0 : 0.0;
    default: return arflex_param_f64(c, i);
  }
}

bool Changed(double* sig, const double* now, int n) {
  bool changed = false;
  for (int k = 0; k < n; ++k) {
    if (sig[k] != now[k]) changed = true;
    sig[k] = now[k];
  }
  return changed;
}

// Applies parameters that changed since the last cycle (all of them on the first cycle).
void ApplyParams(const arflex_component* c, Robot& r) {
  Cell& cell = *r.cell;
  const bool all = r.first_cycle;
  r.first_cycle = false;

  const double payload[2] = {P(c, r, kPayloadKg), P(c, r, kPayloadKnown)};
  if (Changed(r.payload_sig, payload, 2) || all) cell.SetPayload(payload[0], payload[1] != 0.0);

  const double obstacle[4] = {P(c, r, kObstacleEnable), P(c, r, kObstacleX),
                              P(c, r, kObstacleY), P(c, r, kObstacleZ)};
  if (Changed(r.obstacle_sig, obstacle, 4) || all) {
    cell.SetObstacle(obstacle[0] != 0.0, {obstacle[1], obstacle[2], obstacle[3]});
  }

  // A push starts at the period in which its parameters change (force > 0); setting the
  // force to 0 ends it. The force is applied at the TCP along push_dir (normalised).
  const double push[5] = {P(c, r, kPushForce), P(c, r, kPushDirX), P(c, r, kPushDirY),
                          P(c, r, kPushDirZ), P(c, r, kPushDurationMs)};
  if (Changed(r.push_sig, push, 5) || all) {
    PushSpec& p = r.push_buf[0];
    const double n = std::sqrt(push[1] * push[1] + push[2] * push[2] + push[3] * push[3]);
    p.start = cell.time();
    p.duration = (push[0] > 0.0 && n > 0.0) ? push[4] * 1e-3 : 0.0;
    for (int k = 0; k < 3; ++k) p.force[k] = n > 0.0 ? push[0] * push[1 + k] / n : 0.0;
    cell.SetPushes(r.push_buf);
  }

  // A hand guides the TCP from where it is now by (guide_dx, dy, dz) over guide_duration_ms,
  // pulling with at most guide_force_n; 0 releases the arm.
  const double guide[5] = {P(c, r, kGuideForce), P(c, r, kGuideDx), P(c, r, kGuideDy),
                           P(c, r, kGuideDz), P(c, r, kGuideDurationMs)};
  if (Changed(r.guide_sig, guide, 5) || all) {
    HandGuideSpec h;
    h.enabled = guide[0] > 0.0;
    if (h.enabled) {
      const Eigen::Vector3d from = cell.TrueTcp().translation();
      h.start = cell.time();
      h.duration = guide[4] * 1e-3;
      h.from = {from.x(), from.y(), from.z()};
      h.to = {from.x() + guide[1], from.y() + guide[2], from.z() + guide[3]};
      h.max_force = guide[0];
    }
    cell.SetHandGuide(h);
  }
}

// Steps the physics for @periods periods (1, or every period a stall skipped: PeriodClock)
// and publishes the outputs once. With @to, the servo's reference goes from the one it had to
// @to in equal parts over those periods (as the motion source's did meanwhile); without it the
// cell keeps its own (a hold: the stop profile, then where it ended).
int StepAndPublish(const arflex_component* c, Robot& r, uint64_t release_ns, int periods,
                   const JointVector* to) {
  Cell& cell = *r.cell;
  const double spp = P(c, r, kStepsPerPeriod);
  const int steps = spp >= 1.0 ? static_cast<int>(spp) : 1;
  const JointVector from = cell.joint_reference();
  for (int p = 1; p <= periods; ++p) {
    if (to) {
      const double u = static_cast<double>(p) / periods;
      JointVector q;
      for (int i = 0; i < kNumJoints; ++i) q[i] = from[i] + u * ((*to)[i] - from[i]);
      cell.SetJointReference(q);
    }
    cell.Step(steps);
  }
  r.periods += static_cast<uint64_t>(periods);
  ++r.cycles;
  ++r.seq;

  const arflex::sim::JointState js = cell.ReadJointState();
  arflex_joint_state out;
  std::memset(&out, 0, sizeof(out));
  out.t_ns = static_cast<int64_t>(release_ns);
  out.seq = r.seq;
  for (int i = 0; i < kNumJoints; ++i) {
    out.q[i] = js.q[i];
    out.qd[i] = js.dq[i];
    out.tau[i] = js.tau[i];
  }
  int ret = arflex_state_write(r.joint_state, &out, sizeof(out));

  const arflex::sim::Wrench w = cell.ReadWrench();
  arflex_wrench wr;
  std::memset(&wr, 0, sizeof(wr));
  wr.t_ns = out.t_ns;
  wr.seq = r.seq;
  for (int k = 0; k < 3; ++k) {
    wr.force[k] = w.force[k];
    wr.torque[k] = w.torque[k];
  }
  if (ret == 0) ret = arflex_state_write(r.wrench, &wr, sizeof(wr));

  arflex_sample pw;
  std::memset(&pw, 0, sizeof(pw));
  pw.seq = r.seq;
  pw.t_ns = out.t_ns;
  pw.value = cell.power_scale();
  if (ret == 0) ret = arflex_state_write(r.servo_power, &pw, sizeof(pw));

  if (r.truth) {
    arflex_sim_ground_truth g;
    std::memset(&g, 0, sizeof(g));
    g.t_ns = out.t_ns;
    g.seq = r.seq;
    g.steps = cell.step_count();
    g.cycles = r.cycles;
    g.periods = r.periods;
    g.sim_time = cell.time();
    const Eigen::Isometry3d tcp = cell.TrueTcp();
    const Eigen::Quaterniond qt(tcp.linear());
    for (int k = 0; k < 3; ++k) g.p[k] = tcp.translation()[k];
    g.quat[0] = qt.w();
    g.quat[1] = qt.x();
    g.quat[2] = qt.y();
    g.quat[3] = qt.z();
    const JointVector d = cell.ComplianceDeflection();
    for (int i = 0; i < kNumJoints; ++i) g.deflection[i] = d[i];
    const Vec3 f = cell.last_external_force();
    for (int k = 0; k < 3; ++k) g.ext_force[k] = f[k];
    g.obstacle_contacts = static_cast<uint32_t>(cell.obstacle_contacts());
    g.safe = r.safe ? 1u : 0u;
    g.warnings = static_cast<uint32_t>(cell.warning_count());
    const int t = arflex_state_write(r.truth, &g, sizeof(g));
    if (ret == 0) ret = t;
  }
  return ret;
}

// Judges the safety input (every cycle, in update and in safe mode), applies its power limit
// and says why the arm holds (ctl hold word; rt-core refuses a RESET while it names a safety
// input). A guard that had permitted motion and is gone (not merely stopping: no provider,
// silent, stale, invalid, damaged) latches an operator reset: nothing tells this arm any more
// that moving is safe.
arflex_safety_verdict JudgeSafety(arflex_component* c, Robot& r, bool clear_hold) {
  r.gate.max_age_ns = static_cast<uint64_t>(P(c, r, kSafetyMaxAgeMs) * 1e6);
  const arflex_safety_verdict v = arflex_safety_gate_check(&r.gate, arflex_sys_now_ns());
  if (arflex_safety_permits(v)) {
    r.cell->SetPowerScale(arflex_safety_gate_scale(&r.gate));
    r.guard_permitted = true;
    r.loss_latched = false;
    if (clear_hold) arflex_component_hold(c, ARFLEX_HOLD_NONE, 0, 0);
    return v;
  }
  if (v == ARFLEX_SAFETY_STOP) r.cell->SetPowerScale(r.gate.state.power_scale);
  if (r.guard_permitted && v != ARFLEX_SAFETY_STOP && !r.loss_latched) {
    arflex_component_require_reset(c);
    r.loss_latched = true;
  }
  arflex_component_hold(c, ARFLEX_HOLD_SAFETY_INPUT, v, arflex_input_index(c, r.safety));
  return v;
}

// Counts the values of a reference that stay within kRestTol of the first; true once
// kRestValues did.
bool AtRest(Robot& r, const double* q) {
  bool same = r.rest_values > 0;
  for (int i = 0; i < kNumJoints; ++i) same = same && std::fabs(q[i] - r.rest_ref[i]) <= kRestTol;
  if (!same) {
    for (int i = 0; i < kNumJoints; ++i) r.rest_ref[i] = q[i];
    r.rest_values = 0;
  }
  return ++r.rest_values >= kRestValues;
}

// A controlled stop (Cell::Stop, docs/safety.md "How the arm stops"): the arm decelerates
// along a 20 ms profile and the servo holds where it ends; no blend. On an arm at rest it
// holds where the arm is.
void StopAndHold(Robot& r) {
  r.cell->Stop();
  r.q_ref = r.cell->StopTarget();
  r.blend_t = kBlendSeconds;  // holding: no blend in progress
  r.cell->SetCorrection(JointVector{});
}

// 0 when @ref may be used: the contract's check (arflex_joint_ref_valid: every q finite),
// then the arm's joint limits. -EINVAL for a non-finite value, -ERANGE outside the limits.
int CheckReference(const Cell& cell, const arflex_joint_ref& ref) {
  if (!arflex_joint_ref_valid(&ref)) return -EINVAL;
  for (int i = 0; i < kNumJoints; ++i) {
    const auto& link = cell.config().arm.links[i];
    if (!(ref.q[i] >= link.lower && ref.q[i] <= link.upper)) return -ERANGE;
  }
  return 0;
}

// True when @q is within @tol (rad) of the measured joints on every axis.
bool NearArm(const Cell& cell, const double* q, double tol) {
  const arflex::sim::JointState js = cell.ReadJointState();
  for (int i = 0; i < kNumJoints; ++i) {
    if (!(std::fabs(q[i] - js.q[i]) <= tol)) return false;
  }
  return true;
}

int Configure(arflex_component* c, void* user) {
  Robot& r = *static_cast<Robot*>(user);
  for (int p = 0; p < kParamCount; ++p) r.idx[p] = arflex_component_param(c, kParams[p].name);

  int ret = arflex_component_output(c, "joint_state", ARFLEX_PORT_STATE, &kJointStateType,
                                    &r.joint_state);
  if (ret == 0) {
    ret = arflex_component_output(c, "wrench", ARFLEX_PORT_STATE, &kWrenchType, &r.wrench);
  }
  if (ret == 0) {
    ret = arflex_component_output(c, "servo_power", ARFLEX_PORT_STATE, &kSampleType,
                                  &r.servo_power);
  }
  if (ret == 0) {
    ret = arflex_component_input(c, "joint_ref", ARFLEX_PORT_STATE, &kJointRefType,
                                 &r.joint_ref);
  }
  if (ret == 0) {
    ret = arflex_component_input(c, "safety", ARFLEX_PORT_STATE, &kSafetyType, &r.safety);
  }
  if (ret < 0) return ret;
  arflex_safety_gate_init(&r.gate, r.safety,
                          static_cast<uint64_t>(P(c, r, kSafetyMaxAgeMs) * 1e6));

  // The ground-truth segment exists only when the manager created it (evaluation run).
  char name[ARFLEX_OBJ_NAME_SIZE];
  ret = arflex_ctl_obj_name(name, sizeof(name), arflex_component_runtime(c),
                            arflex_component_instance(c), "out." ARFLEX_SIM_TRUTH_PORT);
  if (ret < 0) return ret;
  const int fd = shm_open(name, O_RDONLY, 0);
  if (fd >= 0) {
    close(fd);
    ret = arflex_component_output(c, ARFLEX_SIM_TRUTH_PORT, ARFLEX_PORT_STATE, &kTruthType,
                                  &r.truth);
    if (ret < 0) return ret;
  }

  const double spp = P(c, r, kStepsPerPeriod);
  const double seed = P(c, r, kSeed);
  if (spp < 1.0 || spp > 1000.0) {
    std::fprintf(stderr, "sim-robot: parameter steps_per_period = %g outside 1..1000\n", spp);
    return -ERANGE;
  }
  if (seed < 0.0) {
    std::fprintf(stderr, "sim-robot: parameter seed = %g must be >= 0\n", seed);
    return -ERANGE;
  }
  CellConfig config = arflex::sim::DefaultCellConfig();
  config.error_seed = static_cast<uint64_t>(seed);
  config.payload_mass = P(c, r, kPayloadKg);
  config.nominal_payload_mass = P(c, r, kPayloadKnown) != 0.0 ? config.payload_mass : 0.0;
  config.pushes.assign(1, PushSpec{});
  std::string error;
  r.cell = Cell::Create(config, kHome, &error);
  if (!r.cell) {
    std::fprintf(stderr, "sim-robot: cannot build the simulated cell: %s\n", error.c_str());
    return -EINVAL;
  }
  r.push_buf.assign(1, PushSpec{});
  r.q_ref = kHome;
  r.first_cycle = true;
  return 0;
}

int Start(arflex_component* c, void* user) {
  Robot& r = *static_cast<Robot*>(user);
  r.acquired = false;  // after STOP/START the reference must meet the arm again
  r.refusing = false;
  r.ref_invalid = false;
  r.after_stop = false;
  r.blend_wait = false;
  r.guard_hold = false;
  r.guard_permitted = false;
  r.loss_latched = false;
  r.clock.Restart();  // the time between two runs is not simulated
  arflex_safety_gate_init(&r.gate, r.safety,
                          static_cast<uint64_t>(P(c, r, kSafetyMaxAgeMs) * 1e6));
  ApplyParams(c, r);
  return 0;
}

int Update(arflex_component* c, void* user, uint64_t release_ns) {
  Robot& r = *static_cast<Robot*>(user);
  const int periods =
      r.clock.Periods(arflex_sys_now_ns(), arflex_component_ctl(c)->config.period_ns);
  if (r.safe) {  // the first cycle after safe mode (the reset): hold where the arm is now
    r.after_stop = true;
    r.rest_values = 0;
    StopAndHold(r);
  }
  r.safe = false;
  ApplyParams(c, r);
  // The safety input permits motion, or the arm holds (fail closed). Its power limit is
  // applied at once (this period's physics steps); a protective stop applies the reduced
  // power the guard publishes, so the held arm yields to a push.
  const arflex_safety_verdict verdict = JudgeSafety(c, r, false);
  if (!arflex_safety_permits(verdict)) {
    if (!r.guard_hold) {
      StopAndHold(r);
      r.guard_hold = true;
      r.hold_stops_motion = r.guard_permitted;  // not merely waiting for a first guard
    }
    return StepAndPublish(c, r, release_ns, periods, nullptr);
  }
  if (r.guard_hold) {  // the reference must meet the arm again (D9)
    r.guard_hold = false;
    r.after_stop = r.hold_stops_motion;
    r.rest_values = 0;
    StopAndHold(r);  // where the arm is now (a push under reduced power may have moved it)
    r.acquired = false;
    r.refusing = false;
  }
  arflex_joint_ref ref;
  const int got = arflex_input_state_read(r.joint_ref, &ref, sizeof(ref), nullptr);
  int ret = 0;
  // A new provider (or the same one restarted, or none) must first meet the arm: its
  // reference is followed once a value lies within ref_acquire_tol of the measured joints on
  // every axis. Until then the arm holds and the provider is expected to come to it (the
  // trajectory restarts its program from the measured pose when it gets a new robot). A real
  // controller refuses a reference that is not where the arm is in the same way: following it
  // would drive the arm there as fast as the servo can.
  const uint32_t binding = arflex_input_binding(r.joint_ref);
  if (binding != r.ref_binding) {
    r.ref_binding = binding;
    r.acquired = false;
    r.refusing = false;
    r.ref_invalid = false;
  }
  if (got == 1) {
    const int bad = CheckReference(*r.cell, ref);
    r.ref_invalid = bad < 0;
    if (bad < 0) {
      arflex_input_reject(r.joint_ref);  // counted on the input (the DRCR names its provider)
      ret = bad;  // rejected: never reaches the servo; the last valid reference is held
    } else if (!r.acquired && r.after_stop && !AtRest(r, ref.q)) {
      // after a stop: not yet a reference at rest (still decelerating): keep holding
    } else if (!r.acquired && !NearArm(*r.cell, ref.q, P(c, r, kRefAcquireTol))) {
      if (!r.refusing) ret = -ERANGE;  // counted once per episode, not every cycle
      r.refusing = true;
    } else {
      if (!r.acquired) {  // the offset from what the servo held to the acquired reference
        for (int i = 0; i < kNumJoints; ++i) r.blend_offset[i] = ref.q[i] - r.q_ref[i];
        r.blend_t = 0;
        r.blend_wait = r.after_stop;
        r.after_stop = false;
        for (int i = 0; i < kNumJoints; ++i) r.wait_ref[i] = ref.q[i];
      } else if (r.blend_wait) {
        for (int i = 0; i < kNumJoints; ++i)
          if (std::fabs(ref.q[i] - r.wait_ref[i]) > kMoveTol) r.blend_wait = false;  // it moves
      }
      r.acquired = true;
      r.refusing = false;
      for (int i = 0; i < kNumJoints; ++i) r.q_ref[i] = ref.q[i];
    }
  }
  // The arm holds on its own account while the newest reference was rejected as invalid, no
  // reference is acquired after a stop, or one is refused as too far from it: say so (a valid
  // reference that meets the arm is expected).
  if (r.ref_invalid)
    arflex_component_hold(c, ARFLEX_HOLD_REFERENCE, ARFLEX_HOLD_REF_INVALID,
                          arflex_input_index(c, r.joint_ref));
  else if (!r.acquired && (r.refusing || r.after_stop))
    arflex_component_hold(c, ARFLEX_HOLD_REFERENCE, ARFLEX_HOLD_REF_NOT_MET,
                          arflex_input_index(c, r.joint_ref));
  else
    arflex_component_hold(c, ARFLEX_HOLD_NONE, 0, 0);
  JointVector servo = r.q_ref;
  if (r.blend_t < kBlendSeconds) {
    // The blend where this cycle's last period starts (as one period per cycle had it), so that
    // a catch-up interpolates from the last cycle's value to this one's and the next cycle goes
    // on from there, instead of taking the stall's share of the blend in its one period.
    const double step = P(c, r, kStepsPerPeriod) * r.cell->timestep();
    const double t =
        r.blend_wait ? r.blend_t : std::min(kBlendSeconds, r.blend_t + (periods - 1) * step);
    const double u = t / kBlendSeconds;
    const double rest = 1.0 - u * u * u * (10.0 + u * (-15.0 + 6.0 * u));  // 1 - quintic
    for (int i = 0; i < kNumJoints; ++i) servo[i] -= r.blend_offset[i] * rest;
    if (!r.blend_wait) r.blend_t += periods * step;
  }
  const int pub = StepAndPublish(c, r, release_ns, periods, &servo);
  return ret < 0 ? ret : pub;
}

// Hold: a controlled stop, then the servo holds where it ended (no motion); the physics keeps
// running (the world does not stop) and the sensors keep publishing. Both safe modes hold:
// "zero" velocity is what holding a position means for a robot.
int Safe(arflex_component* c, void* user, arflex_safe_mode /*mode*/, bool first) {
  Robot& r = *static_cast<Robot*>(user);
  if (first) {
    StopAndHold(r);
    r.acquired = false;  // after the reset the reference must meet the arm again (D9)
    r.refusing = false;
  }
  JudgeSafety(c, r, true);
  r.safe = true;
  r.clock.Restart();  // safe cycles step one period each; update starts counting afresh
  return StepAndPublish(c, r, arflex_sys_now_ns(), 1, nullptr);
}

void Cleanup(arflex_component*, void* user) {
  Robot& r = *static_cast<Robot*>(user);
  r.cell.reset();
}

}  // namespace

int main(int argc, char** argv) {
  arflex_component_ops ops{};
  ops.name = "sim-robot";
  ops.user = &g_robot;
  ops.configure = Configure;
  ops.start = Start;
  ops.update = Update;
  ops.safe = Safe;
  ops.cleanup = Cleanup;
  return arflex_component_main(argc, argv, &ops);
}
