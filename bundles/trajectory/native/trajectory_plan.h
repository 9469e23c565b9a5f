// trajectory_plan - the motion player of the trajectory component, free of any process or
// port so that it can be tested cycle by cycle.
//
// Each motion is planned when it begins, from the current planned reference:
//  - ptp: synchronised joint motion; every joint follows the same normalised profile s(tau)
//    (quintic: s = 10u^3 - 15u^4 + 6u^5, or trapezoidal velocity) scaled by its distance; the
//    duration is the smallest one that keeps every joint within speed * vmax_j and accel.
//  - lin: the TCP moves on a straight line (orientation by slerp) with the same profile,
//    duration from lin_speed / lin_accel (and 1 rad/s, 2 rad/s^2 for the rotation); joint
//    angles from damped least-squares IK seeded with the previous cycle's solution.
//  - via ... ptp: one smooth motion through every via point to the ptp target: a C1 cubic
//    Hermite spline in joint space over the chord length sigma (Catmull-Rom-like tangents),
//    passing exactly through each point, traversed as sigma = L s(tau); the speed and
//    acceleration caps on sigma come from bounds of |dq/dsigma| and |d2q/dsigma2| computed when
//    the motion begins (no storage: the points are read from the program). A via point where
//    the path turns by more than 30 degrees ends the smooth stretch (the arm stops there), so
//    one sharp corner does not slow the whole path down.
//  - wait: holds.
// Pausing and safety stops scale the time of the profile (tau += rate * dt, the rate ramps
// to its target within stop_time), so a stop decelerates along the path instead of leaving
// it. A final limiter guarantees |dq| <= vmax_j * dt and |ddq| <= accel_max * dt^2 per cycle
// whatever happens upstream (IK near a singularity, a sudden stop): the output never jumps.
#ifndef ARFLEX_TRAJECTORY_PLAN_H_
#define ARFLEX_TRAJECTORY_PLAN_H_

#include <cstdint>

#include "cellkin.h"

namespace arflex {
namespace traj {

using cellkin::Q;

enum Profile { kQuintic = 0, kTrapezoid = 1 };

struct Limits {
  double vmax[6];     // hard joint speed limits (rad/s)
  double speed;       // override (0, 1] applied to vmax when planning
  double accel;       // planning joint acceleration (rad/s^2)
  double accel_max;   // hard joint acceleration limit of the output limiter (rad/s^2)
  double lin_speed;   // default TCP speed of lin motions (m/s)
  double lin_accel;   // TCP acceleration of lin motions (m/s^2)
  double rot_speed;   // TCP rotation speed (rad/s)
  double rot_accel;   // TCP rotation acceleration (rad/s^2)
  double stop_time;   // time to ramp the time rate from 1 to 0 (s)
  Profile profile;
};

// KR 210 R2700-class joint speeds (123, 115, 112, 179, 172, 219 deg/s), accel 3 rad/s^2,
// accel_max 20 rad/s^2, lin 0.25 m/s and 1 m/s^2, stop_time 0.3 s, quintic.
Limits DefaultLimits();

// Normalised profile: position s in [0, 1] at time tau of a motion of duration T.
struct Shape {
  Profile profile = kQuintic;
  double T = 0;   // duration (s)
  double ta = 0;  // trapezoid: acceleration time (s)
  double Eval(double tau) const;
};

// Smallest shape with |D_j s'| <= v_j and |D_j s''| <= a_j given r_v = max D_j / v_j and
// r_a = max D_j / a_j.
Shape PlanShape(Profile p, double r_v, double r_a);

// Everything a Player is in the middle of (state transfer, docs/DECISIONS.md D41): where it is
// in its program and its output limiter's state (the "filter" state: last output, speed and
// plan), so that a Player restored from it in another process continues cycle for cycle.
struct Snapshot {
  bool initialized = false, done = false, active = false, path = false;
  uint64_t index = 0, run_begin = 0, run_n = 0, cursor = 0, completed = 0;
  Profile profile = kQuintic;
  double rate = 0, tau = 0, shape_t = 0, shape_ta = 0, path_len = 0, cursor_sigma = 0;
  Q q0 = Q::Zero(), dq = Q::Zero(), ik_q = Q::Zero();
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero(), p1 = Eigen::Vector3d::Zero();
  Eigen::Quaterniond r0 = Eigen::Quaterniond::Identity(), r1 = Eigen::Quaterniond::Identity();
  Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();
  Q q_plan = Q::Zero(), q_plan_prev = Q::Zero(), q_out = Q::Zero(), v_out = Q::Zero();
};

class Player {
 public:
  // The state to hand over (D41).
  Snapshot Save() const;
  // Continues from `s` playing `program` (the one it was taken in). False, and nothing changed,
  // when `s` does not fit the program (a motion index or path run beyond its end) or holds a
  // non-finite number.
  bool Restore(const Snapshot& s, const cellkin::Model* model, const cellkin::Program* program,
               double dt);
  // Selects the program; keeps the current reference (the robot is where it was).
  void Begin(const cellkin::Model* model, const cellkin::Program* program, double dt);
  void Init(const Q& q0);  // first reference
  // The tool whose centre point lin motions move (TCP frame in the flange frame; Identity =
  // the flange). Default: the nominal model's tool. A lin motion takes the tool that is set
  // when it begins and keeps it to its end, so a tool change during a motion never makes the
  // reference jump: it applies from the next lin motion. ptp and via motions do not use it.
  void SetTool(const Eigen::Isometry3d& flange_to_tcp) { tool_next_ = flange_to_tcp; }
  // The tool of the current (or last) lin motion.
  const Eigen::Isometry3d& lin_tool() const { return tool_; }
  bool initialized() const { return initialized_; }
  // One period: ramps the time rate towards target_rate (0 = hold, 1 = full speed), advances
  // the program, runs the limiter.
  void Step(const Limits& lim, double target_rate, bool loop);

  const Q& q_out() const { return q_out_; }
  const Q& v_out() const { return v_out_; }
  const Q& q_plan() const { return q_plan_; }
  const cellkin::Program* program() const { return prog_; }
  bool done() const { return done_; }
  // At a standstill of the plan: between two motions or at the end of the program (every
  // motion ends at rest), or paused (time rate 0) with the output at rest. A program switch
  // waits for this.
  bool at_rest() const {
    return !active_ || done_ || (rate_ == 0 && v_out_.cwiseAbs().maxCoeff() < 1e-9);
  }
  // Not in a motion: the program has ended, or is held between two motions (run = false).
  // Init() then moves the output without cutting a motion short.
  bool idle() const { return !active_ || done_; }
  // Plays another program from the current plan position; unlike Begin it keeps the output
  // and its velocity, so the limiter goes on smoothly. Call it only at_rest().
  void Switch(const cellkin::Program* program);
  size_t index() const { return idx_; }
  uint64_t ik_warnings() const { return ik_warnings_; }
  uint64_t limited_cycles() const { return limited_cycles_; }
  uint64_t completed() const { return completed_; }

 private:
  bool StartSegment(const Limits& lim);
  // Path mode (a run of via points ending with a ptp): point i of the path, 0 = start.
  Q PathPoint(size_t i) const;
  double Chord(size_t i) const { return (PathPoint(i + 1) - PathPoint(i)).norm(); }
  Q Tangent(size_t i) const;
  // Position, first and second derivative (by sigma) on segment i at u in [0, 1].
  void Hermite(size_t i, double u, Q* q, Q* d1, Q* d2) const;
  void Evaluate();
  void Limit(const Limits& lim);

  const cellkin::Model* model_ = nullptr;
  const cellkin::Program* prog_ = nullptr;
  double dt_ = 0.001;
  bool initialized_ = false;
  bool done_ = false;
  bool active_ = false;
  size_t idx_ = 0;
  double rate_ = 0;
  double tau_ = 0;
  Shape shape_;
  Q q0_ = Q::Zero(), dq_ = Q::Zero();  // ptp
  Eigen::Vector3d p0_ = Eigen::Vector3d::Zero(), p1_ = Eigen::Vector3d::Zero();  // lin
  Eigen::Quaterniond r0_ = Eigen::Quaterniond::Identity(), r1_ = Eigen::Quaterniond::Identity();
  Q ik_q_ = Q::Zero();
  Eigen::Isometry3d tool_next_ = cellkin::Model().NominalTool();
  Eigen::Isometry3d tool_ = tool_next_;
  bool path_ = false;
  size_t run_begin_ = 0, run_n_ = 0;  // motions [run_begin_, run_begin_ + run_n_) ; last = ptp
  double path_len_ = 0, cursor_sigma_ = 0;
  size_t cursor_ = 0;
  Q q_plan_ = Q::Zero(), q_plan_prev_ = Q::Zero(), q_out_ = Q::Zero(), v_out_ = Q::Zero();
  uint64_t ik_warnings_ = 0, limited_cycles_ = 0, completed_ = 0;
};

}  // namespace traj
}  // namespace arflex

#endif  // ARFLEX_TRAJECTORY_PLAN_H_
