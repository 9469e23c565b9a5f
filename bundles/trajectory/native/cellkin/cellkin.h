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

  // Force (N) and torque (N m) in the flange frame that the wrist sensor reads with the tool
  // and a payload at rest and nothing else touching them (the arm holds them up).
  void ToolWeightWrench(const Q& q, double payload_kg, Eigen::Vector3d* f,
                        Eigen::Vector3d* t) const;

  // Force (N, world frame) that something other than gravity and the arm exerts on the tool:
  // the wrist sensor force `f_sensor` (flange frame, what the arm exerts on the tool, as the
  // simulator's sensor reports it) minus the tool weight, rotated to the world, sign flipped.
  Eigen::Vector3d ContactForceWorld(const Q& q, const Eigen::Vector3d& f_sensor,
                                    double payload_kg) const;

  const cellmodel::ArmParams& arm() const { return arm_; }
  double lower(int j) const { return arm_.links[j].lower; }
  double upper(int j) const { return arm_.links[j].upper; }

 private:
  cellmodel::ArmParams arm_;
  cellmodel::NominalKinematics kin_;
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
