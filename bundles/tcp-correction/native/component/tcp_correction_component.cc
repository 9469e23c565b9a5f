// RT half of the `tcp-correction` component: the outer loop of the paper.
//
// Ports: inputs reference (state, arflex.JointRef: the trajectory's joint reference) and
// tcp_pose (state, arflex.Pose: the vision measurement); outputs corrected (state,
// arflex.JointRef) = reference + correction, error (state, arflex.Sample: the measured TCP
// position error |desired - measured| in mm, one value per valid measurement) and correction
// (state, arflex.Sample: the size of the applied joint correction, Euclidean norm in mrad,
// every cycle), the last two for plots and monitors. Parameters (defaults when absent from the
// contract): gain, max_step (rad per measurement), max_rate (rad/s), max_correction (rad),
// enable (bool), orientation (bool), max_sigma (m: a measurement whose largest position
// standard deviation is larger is held like an invalid one), track_tol (rad: with the optional
// input joint_state bound, a robot further than this from the last output holds the correction).
//
// Every cycle: read the reference (nothing is written until one arrived); on a new tcp_pose
// (its seq changed) update the correction law with the nominal Jacobian and the nominal TCP
// pose of the reference (the desired pose) against the measured pose: an invalid
// measurement holds the correction; then ramp the applied correction towards its target at
// max_rate and write reference + correction with the reference's time and a fresh seq.
// Disabling ramps the correction out. Fixed-size Eigen only: update() does not allocate.
//
// Validated data (docs/safety.md, README "Invalid input"): every value read is checked before
// use (the type's generated arflex_<type>_valid, then what this component needs of it); a
// rejected value is not used and is counted (update returns -EINVAL: stats.update_errors).
//   reference: not finite -> the output holds the last value written (the last valid
//     reference + the correction then applied; the correction does not move) and the hold word
//     says REFERENCE / ARFLEX_HOLD_REF_INVALID on this input until a valid reference comes.
//   tcp_pose: a measurement that claims validity with non-finite numbers, a negative variance,
//     a non-unit quaternion, or a validity flag other than 0/1 -> held like an invalid one (the
//     correction stays where it is, it is neither updated nor dropped).
//   joint_state: not finite -> the robot's position is unknown: measurements are held as by the
//     tracking interlock until a valid joint state comes.
//
// Bumpless transfer (docs/DECISIONS.md D35): when the reference input gets another provider
// (arflex_input_binding changes: a change set replaced the motion source, e.g. teach for
// trajectory on the moving arm), the first value from the new provider is not taken as a step.
// The difference between the reference written last (old provider, with any blend still in
// progress) and the new value is added to the new reference and faded out over blend_time (0.5 s)
// with a quintic (zero speed and acceleration at both ends), as sim-robot takes up an acquired
// reference (D9). A robot on a stiff servo turns a reference step into a torque step: the 6 mrad
// by which the moving arm lags trajectory's reference was read as 770 N by the force guard
// (ChangeSetIT). Only differences up to kBlendMaxOffset are faded; a larger one (a provider
// somewhere else entirely) is passed on as before, for the robot's own acquisition to judge.
#include <algorithm>
#include <cerrno>
#include <cstddef>
#include <cmath>
#include <cstring>

extern "C" {
#include "arflex/component.h"
}
#include "arflex_cellmodel/kinematics.h"
#include "arflex_tcpcorr/correction.h"
#include "arflex_types/joint_ref.h"
#include "arflex_types/joint_state.h"
#include "arflex_types/pose.h"
#include "arflex_types/sample.h"
#include "arflex_types/tcp_correction_state.h"
#include "arflex_types/tcp_correction_state2.h"

namespace {

constexpr double kBlendSeconds = 0.5;  // blend_time's default; 1.0 faded over exactly this
constexpr double kBlendMaxOffset = 0.05;  // rad, any joint: sim-robot's ref_acquire_tol default

using arflex::tcpcorr::CorrectionLaw;
using arflex::tcpcorr::CorrectionOptions;

struct TcpCorrection {
  arflex_input* reference = nullptr;
  arflex_input* pose = nullptr;
  arflex_input* robot = nullptr;  // optional: the robot's measured joints (tracking interlock)
  arflex_port* out = nullptr;
  arflex_port* error = nullptr;
  arflex_port* size = nullptr;
  int p_gain = -1, p_step = -1, p_rate = -1, p_max = -1, p_enable = -1, p_orientation = -1, p_sigma = -1,
      p_track = -1, p_blend = -1;
  double blend_time = kBlendSeconds;  // s: the parameter, for the next provider change
  double track_tol = 2e-3;  // rad: a robot further than this from our output is not following
  double max_sigma = 2e-4;  // m: a measurement less certain than this is treated as invalid
  arflex::cellmodel::NominalKinematics kinematics{arflex::cellmodel::DefaultArm()};
  CorrectionLaw law{CorrectionOptions{}};
  arflex_joint_ref ref{};
  bool have_ref = false;
  uint64_t pose_seq = 0;
  uint64_t out_seq = 0;
  uint64_t error_seq = 0;
  double last_out[6] = {0, 0, 0, 0, 0, 0};  // the corrected reference written last
  arflex_joint_state js{};                   // the robot's newest joint state (seq 0: none)
  uint32_t ref_binding = 0;  // binding of the reference input the last value came through
  double blend_offset[6] = {0, 0, 0, 0, 0, 0};  // faded out after a provider change
  double blend_duration = kBlendSeconds;        // s: the fade in progress lasts this long
  double blend_t = kBlendSeconds;               // s since that change; >= blend_duration: none
  bool ref_invalid = false;  // the newest reference was rejected: the output holds
  bool js_invalid = false;   // the newest joint state was rejected: measurements are held
  double dt = 0.001;
  // The state block published every cycle (D41): arflex.TcpCorrectionState2 (this version's,
  // D52), or its 1.0 prefix when the manager made a 1.0 block (a contract declaring the older
  // state, e.g. a 1.0.x version made of this executable).
  arflex_tcp_correction_state2 state{};
  bool state_v1 = false;
};

TcpCorrection g;

// What is left of a blend's offset now: 1 - s(u), s the quintic 10u^3 - 15u^4 + 6u^5.
double BlendRest() {
  if (g.blend_t >= g.blend_duration) return 0.0;
  const double u = g.blend_t / g.blend_duration;
  return 1.0 - u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
}

const arflex_port_type kRefType = {ARFLEX_TYPE_JOINT_REF_NAME, 1, 0, ARFLEX_TYPE_JOINT_REF_SIZE};
const arflex_port_type kPoseType = {ARFLEX_TYPE_POSE_NAME, 1, 0, ARFLEX_TYPE_POSE_SIZE};
const arflex_port_type kStateType = {ARFLEX_TYPE_JOINT_STATE_NAME, 1, 0, ARFLEX_TYPE_JOINT_STATE_SIZE};
const arflex_port_type kSampleType = {ARFLEX_TYPE_SAMPLE_NAME, 1, 0, ARFLEX_TYPE_SAMPLE_SIZE};

double F64(arflex_component* c, int idx, double def) { return idx >= 0 ? arflex_param_f64(c, idx) : def; }
bool Bool(arflex_component* c, int idx, bool def) { return idx >= 0 ? arflex_param_bool(c, idx) : def; }

// Reads the parameters in force into the law (between cycles they cannot change).
void ApplyParams(arflex_component* c) {
  CorrectionOptions o = g.law.options();
  o.gain = F64(c, g.p_gain, 0.6);
  o.max_step = F64(c, g.p_step, 2e-3);
  o.max_rate = F64(c, g.p_rate, 1e-2);
  o.max_correction = F64(c, g.p_max, 2e-2);
  o.orientation = Bool(c, g.p_orientation, false);
  g.law.SetOptions(o);  // invalid values (outside the contract's ranges) keep the old ones
  g.max_sigma = F64(c, g.p_sigma, 2e-4);
  g.track_tol = F64(c, g.p_track, 2e-3);
  g.blend_time = F64(c, g.p_blend, kBlendSeconds);  // 1.1.0; absent (a 1.0 contract): 1.0's 0.5 s
  const bool enable = Bool(c, g.p_enable, true);
  if (enable != g.law.enabled()) g.law.SetEnabled(enable);
}

// A measurement tcp-correction may interpret: the contract's check; valid is 0 or 1; one that
// claims validity has finite numbers, variances >= 0 and a unit quaternion. (valid = 0, "no
// estimate", is a correct value whatever its other fields hold: it is held, not counted.)
bool PoseWellFormed(const arflex_pose& m) {
  if (!arflex_pose_valid(&m) || m.valid > 1) return false;
  if (m.valid == 0) return true;
  double n2 = 0;
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(m.quat[i])) return false;
    n2 += m.quat[i] * m.quat[i];
  }
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(m.p[i])) return false;
  for (int i = 0; i < 6; ++i)
    if (!(m.cov[i] >= 0 && std::isfinite(m.cov[i]))) return false;
  return std::fabs(std::sqrt(n2) - 1.0) < 1e-3;
}

int Adopt(arflex_component*, void*, const arflex_adopted_state* a);

int Configure(arflex_component* c, void*) {
  int r = arflex_component_input(c, "reference", ARFLEX_PORT_STATE, &kRefType, &g.reference);
  if (r == 0) r = arflex_component_input(c, "tcp_pose", ARFLEX_PORT_STATE, &kPoseType, &g.pose);
  if (r == 0) r = arflex_component_input(c, "joint_state", ARFLEX_PORT_STATE, &kStateType, &g.robot);
  if (r == 0) r = arflex_component_output(c, "corrected", ARFLEX_PORT_STATE, &kRefType, &g.out);
  if (r == 0) r = arflex_component_output(c, "error", ARFLEX_PORT_STATE, &kSampleType, &g.error);
  if (r == 0) r = arflex_component_output(c, "correction", ARFLEX_PORT_STATE, &kSampleType, &g.size);
  if (r < 0) return r;
  // The state block (contract <state>, D41): without a state segment publishing is a no-op.
  // This version's block is arflex.TcpCorrectionState2 (D52); a contract that declares the
  // 1.0 block gets that one published (its prefix: the same fields at the same offsets).
  static const arflex_port_type kStateBlock = {
      ARFLEX_TYPE_TCP_CORRECTION_STATE2_NAME, ARFLEX_TYPE_TCP_CORRECTION_STATE2_VERSION_MAJOR,
      ARFLEX_TYPE_TCP_CORRECTION_STATE2_VERSION_MINOR, ARFLEX_TYPE_TCP_CORRECTION_STATE2_SIZE};
  static const arflex_port_type kStateBlockV1 = {
      ARFLEX_TYPE_TCP_CORRECTION_STATE_NAME, ARFLEX_TYPE_TCP_CORRECTION_STATE_VERSION_MAJOR,
      ARFLEX_TYPE_TCP_CORRECTION_STATE_VERSION_MINOR, ARFLEX_TYPE_TCP_CORRECTION_STATE_SIZE};
  r = arflex_component_state(c, &kStateBlock, nullptr);
  if (r == -EPROTOTYPE) {
    r = arflex_component_state(c, &kStateBlockV1, nullptr);
    g.state_v1 = r == 0;
  }
  if (r < 0 && r != -ENOENT) return r;
  // D61: Adopt runs between two updates as well (the law, the fade, the last reference and
  // output): at the switch of an update whose new half ran in shadow it takes the old state again
  if ((r = arflex_component_readopt(c, Adopt)) < 0) return r;
  g.p_gain = arflex_component_param(c, "gain");
  g.p_step = arflex_component_param(c, "max_step");
  g.p_rate = arflex_component_param(c, "max_rate");
  g.p_max = arflex_component_param(c, "max_correction");
  g.p_enable = arflex_component_param(c, "enable");
  g.p_orientation = arflex_component_param(c, "orientation");
  g.p_sigma = arflex_component_param(c, "max_sigma");
  g.p_track = arflex_component_param(c, "track_tol");
  g.p_blend = arflex_component_param(c, "blend_time");
  const uint64_t period = arflex_component_ctl(c)->config.period_ns;
  g.dt = period > 0 ? period * 1e-9 : 0.001;
  ApplyParams(c);
  const char* what = nullptr;
  if (!arflex::tcpcorr::ValidateOptions(g.law.options(), &what)) {
    fprintf(stderr, "tcp-correction: parameter default: %s\n", what);
    return -EINVAL;
  }
  return 0;
}

int Start(arflex_component* c, void*) {
  // A fresh run starts without a correction (the arm may have moved meanwhile).
  g.law = CorrectionLaw(g.law.options());
  ApplyParams(c);
  g.have_ref = false;
  g.ref_binding = 0;
  g.blend_duration = g.blend_time;
  g.blend_t = g.blend_duration;
  g.ref_invalid = false;
  g.js_invalid = false;
  g.js = arflex_joint_state{};
  arflex_component_hold(c, ARFLEX_HOLD_NONE, 0, 0);
  return 0;
}

// ---- the state block (D41) --------------------------------------------------------------

// The correction, the fade of a provider change and the reference last passed on.
void PublishState(arflex_component* c, uint64_t release_ns) {
  if (!arflex_component_state_open(c)) return;
  arflex_tcp_correction_state2& st = g.state;
  st.t_ns = (int64_t)release_ns;
  st.seq++;
  st.pose_seq = g.pose_seq;
  st.out_seq = g.out_seq;
  st.error_seq = g.error_seq;
  st.updates = (uint64_t)g.law.updates();
  st.holds = (uint64_t)g.law.holds();
  st.flags = (g.have_ref ? ARFLEX_TCP_CORRECTION_STATE_FLAG_HAVE_REF : 0u) |
             (g.law.enabled() ? ARFLEX_TCP_CORRECTION_STATE_FLAG_ENABLED : 0u);
  for (int i = 0; i < 6; ++i) {
    st.target[i] = g.law.target()(i);
    st.applied[i] = g.law.applied()(i);
    st.last_error[i] = g.law.last_error()(i);
    st.blend_offset[i] = g.blend_offset[i];
    st.ref_q[i] = g.ref.q[i];
    st.last_out[i] = g.last_out[i];
  }
  st.blend_t = std::min(g.blend_t, g.blend_duration);
  st.blend_duration = g.blend_duration;
  st.ref_t_ns = g.ref.t_ns;
  // a 1.0 block: the fields it has (the same offsets, checked below); its fade is always 0.5 s
  arflex_component_state_publish(c, &st, g.state_v1 ? sizeof(arflex_tcp_correction_state) : sizeof(st), release_ns);
}

// The adopt hook (D41): after Start, at the switch of a change set's update, the state the
// running version published last: the correction goes on where it was instead of restarting
// at zero (a jump of up to max_correction with vision), a fade in progress goes on over the
// duration it started with, and the reference last passed on is the one the next provider
// change is faded from. Takes arflex.TcpCorrectionState2 1.x, and converts
// arflex.TcpCorrectionState 1.x (the contract's <convertsFrom>, D52): the same fields, and the
// fade's duration that 1.0 did not record because it was always 0.5 s. Anything else refuses
// the START (-EPROTOTYPE); a value out of its type's bounds too (-EINVAL).
static_assert(sizeof(arflex_tcp_correction_state) == offsetof(arflex_tcp_correction_state2, blend_duration),
              "TcpCorrectionState2 is TcpCorrectionState 1.0 with blend_duration appended");
static_assert(offsetof(arflex_tcp_correction_state, last_out) == offsetof(arflex_tcp_correction_state2, last_out) &&
                  offsetof(arflex_tcp_correction_state, blend_t) == offsetof(arflex_tcp_correction_state2, blend_t) &&
                  offsetof(arflex_tcp_correction_state, target) == offsetof(arflex_tcp_correction_state2, target),
              "the 1.0 fields at the same offsets");
int Adopt(arflex_component*, void*, const arflex_adopted_state* a) {
  arflex_tcp_correction_state2 st;
  std::memset(&st, 0, sizeof(st));
  if (std::strcmp(a->type_name, ARFLEX_TYPE_TCP_CORRECTION_STATE2_NAME) == 0 &&
      a->major == ARFLEX_TYPE_TCP_CORRECTION_STATE2_VERSION_MAJOR && a->length >= sizeof(st)) {
    std::memcpy(&st, a->data, sizeof(st));
  } else if (std::strcmp(a->type_name, ARFLEX_TYPE_TCP_CORRECTION_STATE_NAME) == 0 &&
             a->major == ARFLEX_TYPE_TCP_CORRECTION_STATE_VERSION_MAJOR &&
             a->length >= sizeof(arflex_tcp_correction_state)) {
    arflex_tcp_correction_state v1;
    std::memcpy(&v1, a->data, sizeof(v1));
    if (!arflex_tcp_correction_state_valid(&v1)) return -EINVAL;
    std::memcpy(&st, &v1, sizeof(v1));  // the 1.0 fields, the same layout (asserted above)
    st.blend_duration = kBlendSeconds;  // the conversion: 1.0 faded over a fixed 0.5 s
  } else {
    return -EPROTOTYPE;
  }
  if (!arflex_tcp_correction_state2_valid(&st)) return -EINVAL;
  arflex::tcpcorr::Vector6d target, applied, last_error;
  for (int i = 0; i < 6; ++i) {
    target(i) = st.target[i];
    applied(i) = st.applied[i];
    last_error(i) = st.last_error[i];
  }
  // enabled is this version's parameter (ApplyParams runs first in every update)
  if (!g.law.Restore(target, applied, last_error, (long)st.updates, (long)st.holds, g.law.enabled()))
    return -EINVAL;
  g.have_ref = (st.flags & ARFLEX_TCP_CORRECTION_STATE2_FLAG_HAVE_REF) != 0;
  for (int i = 0; i < 6; ++i) {
    g.ref.q[i] = st.ref_q[i];
    g.last_out[i] = st.last_out[i];
    g.blend_offset[i] = st.blend_offset[i];
  }
  g.ref.t_ns = st.ref_t_ns;
  g.ref.seq = 0;
  g.blend_duration = st.blend_duration;
  g.blend_t = std::min(st.blend_t, st.blend_duration);
  g.pose_seq = st.pose_seq;
  g.out_seq = st.out_seq;
  g.error_seq = st.error_seq;
  g.state = st;
  // the same provider, through this half's own binding: its first value is no provider change
  g.ref_binding = 0;
  return 0;
}

int Update(arflex_component* c, void*, uint64_t release_ns) {
  ApplyParams(c);
  // A state read returns 1 only for a value newer than the last one it returned (0: none new,
  // the buffer untouched), so only a 1 may be used.
  int err = 0;  // a rejected input value this cycle (-EINVAL), returned at the end
  arflex_joint_ref ref{};
  if (arflex_input_state_read(g.reference, &ref, sizeof(ref), nullptr) == 1 && ref.seq != 0) {
    g.ref_invalid = !arflex_joint_ref_valid(&ref);
    if (g.ref_invalid) {
      arflex_input_reject(g.reference);
      err = -EINVAL;  // never passed on: the output holds (below)
    } else {
      const uint32_t binding = arflex_input_binding(g.reference);
      if (g.have_ref && g.ref_binding != 0 && binding != g.ref_binding) {
        // Another provider: fade the difference out (see the file comment).
        const double rest = BlendRest();
        double offset[6], biggest = 0;
        for (int i = 0; i < 6; ++i) {
          offset[i] = g.ref.q[i] + g.blend_offset[i] * rest - ref.q[i];
          biggest = std::max(biggest, std::abs(offset[i]));
        }
        if (std::isfinite(biggest) && biggest <= kBlendMaxOffset) {
          for (int i = 0; i < 6; ++i) g.blend_offset[i] = offset[i];
          g.blend_duration = g.blend_time;  // a new fade takes the parameter in force
          g.blend_t = 0;
        } else {
          g.blend_t = g.blend_duration;
        }
      }
      g.ref_binding = binding;
      g.ref = ref;
      g.have_ref = true;
    }
  }
  if (!arflex_input_bound(g.reference)) g.ref_invalid = false;  // nothing to hold against
  if (g.ref_invalid)
    arflex_component_hold(c, ARFLEX_HOLD_REFERENCE, ARFLEX_HOLD_REF_INVALID, arflex_input_index(c, g.reference));
  else
    arflex_component_hold(c, ARFLEX_HOLD_NONE, 0, 0);
  if (!g.have_ref) return err;
  if (g.ref_invalid && g.out_seq != 0) {
    // The reference is invalid: the last output again (fresh seq), the correction frozen.
    arflex_joint_ref out = g.ref;
    for (int i = 0; i < 6; ++i) out.q[i] = g.last_out[i];
    out.seq = ++g.out_seq;
    const int w = arflex_state_write(g.out, &out, sizeof(out));
    PublishState(c, release_ns);
    return w < 0 ? w : err;
  }
  // The reference part of the output: the newest reference plus what is left of a blend.
  const double rest = BlendRest();
  if (g.blend_t < g.blend_duration) g.blend_t += g.dt;
  arflex::cellmodel::JointVector q;
  for (int i = 0; i < 6; ++i) q[i] = g.ref.q[i] + g.blend_offset[i] * rest;
  arflex_joint_state js{};
  if (arflex_input_state_read(g.robot, &js, sizeof(js), nullptr) == 1 && js.seq != 0) {
    g.js_invalid = !arflex_joint_state_valid(&js);
    if (g.js_invalid) {
      arflex_input_reject(g.robot);
      err = -EINVAL;
    } else {
      g.js = js;
    }
  }
  if (!arflex_input_bound(g.robot)) {  // no robot: no interlock
    g.js.seq = 0;
    g.js_invalid = false;
  }
  arflex_pose m{};
  uint64_t seq = 0;
  const bool fresh =
      arflex_input_state_read(g.pose, &m, sizeof(m), &seq) == 1 && m.seq != 0 && m.seq != g.pose_seq;
  if (fresh && !PoseWellFormed(m)) {
    g.pose_seq = m.seq;  // a malformed measurement: held (the correction stays), counted
    arflex_input_reject(g.pose);
    err = -EINVAL;
  } else if (fresh) {
    g.pose_seq = m.seq;
    Eigen::Isometry3d measured = Eigen::Isometry3d::Identity();
    measured.linear() = Eigen::Quaterniond(m.quat[0], m.quat[1], m.quat[2], m.quat[3]).normalized().toRotationMatrix();
    measured.translation() = Eigen::Vector3d(m.p[0], m.p[1], m.p[2]);
    // A measurement is used only when vision says it is valid and its position is certain
    // enough: the largest position variance against max_sigma (a single camera view gives
    // millimetres along its line of sight; several views give hundredths).
    const double var = std::max(m.cov[0], std::max(m.cov[1], m.cov[2]));
    const bool certain = std::isfinite(var) && var <= g.max_sigma * g.max_sigma;
    // Tracking interlock: when the robot's measured joints are bound and it is not where our
    // last output asked it to be (safe mode, a hold, a protective stop, still moving), a
    // measurement says nothing about the correction: holding it avoids winding the correction
    // up against a robot that does not move (it would jump when the robot follows again).
    // A rejected joint state leaves the robot's position unknown: not tracking.
    bool tracking = !g.js_invalid;
    if (tracking && g.out_seq != 0 && g.js.seq != 0) {
      for (int i = 0; i < 6; ++i) tracking = tracking && std::abs(g.js.q[i] - g.last_out[i]) <= g.track_tol;
    }
    const bool valid = m.valid != 0 && certain && tracking;
    const Eigen::Isometry3d desired = g.kinematics.Tcp(q);
    g.law.Update(g.kinematics.TcpJacobian(q), desired, measured, valid);
    const double err_mm = 1e3 * (desired.translation() - measured.translation()).norm();
    if (valid && std::isfinite(err_mm)) {
      // What vision sees of the TCP's distance from where the reference wants it (mm).
      arflex_sample e{};
      e.seq = ++g.error_seq;
      e.t_ns = m.t_ns;
      e.value = err_mm;
      arflex_state_write(g.error, &e, sizeof(e));
    }
  }
  const arflex::tcpcorr::Vector6d& dq = g.law.Tick(g.dt);
  arflex_joint_ref out = g.ref;
  for (int i = 0; i < 6; ++i) out.q[i] = q[i] + dq(i);
  out.seq = ++g.out_seq;
  arflex_sample size{};
  size.seq = out.seq;
  size.t_ns = out.t_ns;
  size.value = 1e3 * dq.norm();
  arflex_state_write(g.size, &size, sizeof(size));
  for (int i = 0; i < 6; ++i) g.last_out[i] = out.q[i];
  const int w = arflex_state_write(g.out, &out, sizeof(out));
  PublishState(c, release_ns);
  return w < 0 ? w : err;
}

// Safe mode, either mode: the last output is held. Dropping the correction at once would make
// the reference jump, which this component must never do.
int Safe(arflex_component*, void*, enum arflex_safe_mode, bool) { return 0; }

}  // namespace

int main(int argc, char** argv) {
  arflex_component_ops ops{};
  ops.name = "tcp-correction";
  ops.configure = Configure;
  ops.start = Start;
  ops.update = Update;
  ops.safe = Safe;
  ops.adopt = Adopt;
  return arflex_component_main(argc, argv, &ops);
}
