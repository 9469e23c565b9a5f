// cellkin - what the cell's motion components know about the robot: the NOMINAL arm only.
//
// The arm and its kinematics come from the cell model (cellmodel/: DefaultArm and
// NominalKinematics, a product of exponentials; no MuJoCo, so this library also builds in the
// sanitizer build). Added here: damped-least-squares IK, the nominal static
// gravity torques (link masses, tool, payload), the tool's weight as the wrist sensor sees it,
// and the program file format shared by trajectory (reader) and teach (writer).
//
// Threads: every function is pure computation on caller-owned data except LoadProgramFile /
// WriteProgramFile (file I/O; never call them on the RT thread). No function allocates except
// ParseProgram (into a Program whose capacity is fixed at construction) and the file helpers.
#ifndef ARFLEX_CELLKIN_H_
#define ARFLEX_CELLKIN_H_

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "arflex_cellmodel/kinematics.h"
#include "arflex_cellmodel/arm.h"

namespace arflex {
namespace cellkin {

using Q = Eigen::Matrix<double, 6, 1>;
constexpr double kGravity = 9.81;

class Model {
 public:
  Model();  // the default (nominal) arm of the cell: cellmodel::DefaultArm()

  Eigen::Isometry3d Tcp(const Q& q) const;
  Eigen::Isometry3d Flange(const Q& q) const;
  cellmodel::Jacobian6 Jacobian(const Q& q) const;

  // Moves *q towards the joint angles whose TCP pose is `target` by at most `iters` damped
  // least-squares Newton steps (starting from *q: pass the previous solution for continuity).
  // Returns the remaining error: position error (m) + rotation error (rad). Never allocates.
  double Ik(const Eigen::Isometry3d& target, Q* q, int iters) const;

  // The same for any tool: `tool` is the tool centre point frame in the flange frame (from an
  // arflex.ToolState: tcp_p, tcp_quat; Identity = the flange itself). TcpOf is the TCP pose,
  // JacobianOf its geometric Jacobian (world: linear velocity of the TCP point, angular).
  Eigen::Isometry3d TcpOf(const Q& q, const Eigen::Isometry3d& tool) const;
  cellmodel::Jacobian6 JacobianOf(const Q& q, const Eigen::Isometry3d& tool) const;
  double IkTool(const Eigen::Isometry3d& target, const Eigen::Isometry3d& tool, Q* q,
                int iters) const;
  // The nominal model's own tool (tcp_offset, orientation of the flange): TcpOf(q,
  // NominalTool()) equals Tcp(q).
  Eigen::Isometry3d NominalTool() const;

  // Joint torques (N m) the drives must deliver to hold the arm still at q: link masses,
  // the tool (cellmodel::ArmParams::tool_mass at tool_com) and a payload of `payload_kg` at
  // payload_com. Same sign convention as the measured drive torques of arflex.JointState.
  Q GravityTorque(const Q& q, double payload_kg) const;

  // Joint torques (N m) the drives deliver to move the arm with velocities qd (rad/s) and
  // accelerations qdd (rad/s^2) at q, with nothing touching it: the nominal rigid-body
  // inverse dynamics (recursive Newton-Euler in the world frame: link inertias, tool and
  // payload as point masses as in GravityTorque, Coriolis and centripetal terms, gravity)
  // plus each drive's reflected rotor inertia (armature * qdd) and viscous friction
  // (damping * qd). Equals GravityTorque when qd and qdd are zero. When `tool_accel` is not null it receives the acceleration (m/s^2,
  // world, gravity not included) of the tool's centre of mass.
  Q InverseDynamics(const Q& q, const Q& qd, const Q& qdd, double payload_kg,
                    Eigen::Vector3d* tool_accel = nullptr) const;

  // Force (N) and torque (N m) in the flange frame that the wrist sensor reads with the tool
  // and a payload at rest and nothing else touching them (the arm holds them up).
  void ToolWeightWrench(const Q& q, double payload_kg, Eigen::Vector3d* f,
                        Eigen::Vector3d* t) const;

  // Force (N, world frame) that something other than gravity and the arm exerts on the tool:
  // the wrist sensor force `f_sensor` (flange frame, what the arm exerts on the tool, as the
  // simulator's sensor reports it) minus the tool weight, rotated to the world, sign flipped.
  Eigen::Vector3d ContactForceWorld(const Q& q, const Eigen::Vector3d& f_sensor,
                                    double payload_kg) const;
  // The same for a tool that accelerates: `tool_accel` (m/s^2, world, from InverseDynamics)
  // is the acceleration of the tool's centre of mass; the force the arm spends on it,
  // (tool mass + payload) * tool_accel, is not contact either. Tool and payload are taken as
  // one rigid point mass at the tool's centre of mass for this term.
  Eigen::Vector3d ContactForceWorld(const Q& q, const Eigen::Vector3d& f_sensor,
                                    double payload_kg, const Eigen::Vector3d& tool_accel) const;

  const cellmodel::ArmParams& arm() const { return arm_; }
  double lower(int j) const { return arm_.links[j].lower; }
  double upper(int j) const { return arm_.links[j].upper; }

 private:
  cellmodel::ArmParams arm_;
  cellmodel::NominalKinematics kin_;
};

// ---- contact monitoring (force-guard) ------------------------------------------------------
//
// What a moving arm's drives and wrist sensor report beyond the nominal model: the external
// joint torques (measured minus InverseDynamics) and the contact force at the tool (wrist
// force minus the tool's weight and the force that accelerates it). The joint accelerations
// are differenced from the velocities of consecutive measurements.
//
// The nominal model is rigid; the real (and the simulated TRUE) arm has compliant gears. A
// fast deceleration (the 20 ms controlled stop) rings the gear springs, and for a few tens of
// milliseconds the residual is a large fraction of the inertial load itself (measured on the
// TRUE model, cell.sim.conventions). So the limits are widened by a share of the inertial
// load the model accounts for: allowance = kInertialShare * the peak of |inertial torque|
// (per joint) or of |tool mass * tool acceleration|, held and decaying with kHoldTau, the
// gear ringing's decay. At rest or at constant speed the allowance is zero and the limits
// are exactly the configured ones. Pure computation, no allocation.
class ContactMonitor {
 public:
  static constexpr double kInertialShare = 1.0;
  static constexpr double kHoldTau = 0.030;  // s
  static constexpr double kMaxGap = 0.020;   // s: a longer gap between samples restarts the
                                             // differencing (no acceleration estimate)

  explicit ContactMonitor(const Model* model) : model_(model) {}
  void Reset() { have_prev_ = false; hold_t_ = Q::Zero(); hold_f_ = 0; }

  // One joint measurement (t_ns: its time; a repeated t_ns is ignored and returns false).
  bool Update(int64_t t_ns, const Q& q, const Q& qd, const Q& tau, double payload_kg);

  // After Update: external joint torques and the torque allowance per joint (N m).
  const Q& external_torque() const { return ext_; }
  const Q& torque_allowance() const { return hold_t_; }
  // Contact force (N, world) from a wrist force `f_sensor` (flange frame) at the last
  // update's pose and acceleration, and the allowance for it (N).
  Eigen::Vector3d ContactForce(const Eigen::Vector3d& f_sensor, double payload_kg) const;
  double force_allowance() const { return hold_f_; }
  bool ready() const { return have_prev_; }

  // The filter's state, for handing it to another process (force-guard's state block,
  // docs/DECISIONS.md D52): the previous sample, the external torques, the tool acceleration and
  // the decaying allowances. Restore refuses (false, nothing changed) non-finite numbers and
  // negative allowances.
  struct Snapshot {
    bool have_prev = false;
    int64_t t_prev = 0;
    Q qd_prev = Q::Zero(), q = Q::Zero(), ext = Q::Zero(), hold_t = Q::Zero();
    Eigen::Vector3d a_tool = Eigen::Vector3d::Zero();
    double hold_f = 0;
  };
  Snapshot Save() const { return {have_prev_, t_prev_, qd_prev_, q_, ext_, hold_t_, a_tool_, hold_f_}; }
  bool Restore(const Snapshot& s) {
    const bool finite = s.qd_prev.allFinite() && s.q.allFinite() && s.ext.allFinite() && s.hold_t.allFinite() &&
                        s.a_tool.allFinite() && std::isfinite(s.hold_f);
    if (!finite || s.hold_t.minCoeff() < 0 || s.hold_f < 0) return false;
    have_prev_ = s.have_prev;
    t_prev_ = s.t_prev;
    qd_prev_ = s.qd_prev;
    q_ = s.q;
    ext_ = s.ext;
    hold_t_ = s.hold_t;
    a_tool_ = s.a_tool;
    hold_f_ = s.hold_f;
    return true;
  }

 private:
  const Model* model_;
  bool have_prev_ = false;
  int64_t t_prev_ = 0;
  Q qd_prev_ = Q::Zero(), q_ = Q::Zero(), ext_ = Q::Zero(), hold_t_ = Q::Zero();
  Eigen::Vector3d a_tool_ = Eigen::Vector3d::Zero();
  double hold_f_ = 0;
};

// ---- program files ----------------------------------------------------------------------
//
// Text, one statement per line, '#' starts a comment, blank lines ignored. The first
// statement must be `arflex-program 1`. Then, in any number:
//   start q1 .. q6                  initial reference when no joint_state is bound (rad; once)
//   ptp q1 .. q6 [speed f]          joint motion to the joint target (rad); f in (0, 1] scales
//                                   the joint velocity limits for this motion (default 1)
//   via q1 .. q6 [speed f]          a joint-space point the path passes through without
//                                   stopping; a run of via points ends with a ptp (the path's
//                                   end), and the whole run is one smooth motion
//   lin x y z qw qx qy qz [speed v] Cartesian straight line of the TCP to the pose (m, unit
//                                   quaternion w x y z, normalised on load); v (m/s) caps the
//                                   linear speed (default: the component's lin_speed)
//   wait s                          hold still for s seconds (0 < s <= 3600)
// Joint targets must lie within the nominal joint limits. Errors name file:line and what is
// wrong.

struct Motion {
  enum Kind { kPtp, kLin, kWait, kVia } kind;
  double v[7];   // ptp, via: q[6]; lin: x y z qw qx qy qz; wait: v[0] seconds
  double speed;  // ptp, via: fraction (0, 1]; lin: m/s (0 = component default)
  int line;      // source line
};

struct Program {
  bool has_start = false;
  Q start = Q::Zero();
  std::vector<Motion> motions;  // filled at load time; RT code only reads it
  std::string origin;           // file name or "built-in"
};

constexpr size_t kMaxMotions = 20000;

// Parses `text`; `origin` names it in messages. Returns true, or false with *err set
// ("<origin>:<line>: <what>").
bool ParseProgram(const std::string& text, const std::string& origin, const Model& model,
                  Program* out, std::string* err);
bool LoadProgramFile(const std::string& path, const Model& model, Program* out,
                     std::string* err);
// Writes `p` to `path` atomically (temporary file in the same directory, fsync, rename),
// mode 0600. Returns true or false with *err.
bool WriteProgramFile(const std::string& path, const Program& p, std::string* err);
// Where program files live: $ARFLEX_DATA_DIR when set and not empty, else <working
// directory>/data (an RT half started by the DRCR runs in the runtime's directory, so that is
// <runtime>/data), as an absolute path. Not for the RT thread (getcwd).
std::string DataDir();
// "<dir>/program-<n>.arp"
std::string ProgramPath(const std::string& dir, long n);

}  // namespace cellkin
}  // namespace arflex

#endif  // ARFLEX_CELLKIN_H_
