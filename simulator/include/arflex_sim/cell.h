// The simulated robot cell: the TRUE arm in MuJoCo driven by the conventional controller (a
// joint position servo with gravity compensation from the NOMINAL model), sensors, scripted
// disturbances and a lock-step stepping API.
//
// Threading: a Cell is used by one thread (the physics/RT thread). Rendering happens
// elsewhere from a copy of qpos (see render.h); Step() never waits for it.
// Allocation: everything is allocated in Create(); Step() and the accessors do not allocate.
#ifndef ARFLEX_SIM_CELL_H_
#define ARFLEX_SIM_CELL_H_

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <string>

#include "arflex_sim/kinematics.h"
#include "arflex_sim/params.h"

namespace arflex {
namespace sim {

// Motor-side joint state as the robot's own controller reports it.
struct JointState {
  JointVector q{};    // motor (encoder) angles (rad)
  JointVector dq{};   // motor velocities (rad/s)
  JointVector tau{};  // drive torque delivered to the joint (N m), incl. the servo's damping
};

// Wrist force/torque sensor reading in the sensor frame (the flange frame), MuJoCo's
// convention: the force and torque that the arm exerts on the tool (tool + payload +
// anything pushing on them), measured at the flange.
struct Wrench {
  Vec3 force{};
  Vec3 torque{};
};

class Cell {
 public:
  // Builds the TRUE and NOMINAL models from `config`, the tag textures, and puts the arm at
  // rest at q = `initial_q` (reference = initial_q). Returns nullptr and sets `*error` to a
  // message naming the problem on failure.
  static std::unique_ptr<Cell> Create(const CellConfig& config, const JointVector& initial_q,
                                      std::string* error);
  ~Cell();
  Cell(const Cell&) = delete;
  Cell& operator=(const Cell&) = delete;

  // The joint reference the servo follows, and the correction added to it (the only way a
  // correction component acts on the arm). Both in rad, motor side.
  void SetJointReference(const JointVector& q_ref) { q_ref_ = q_ref; }
  const JointVector& joint_reference() const { return q_ref_; }
  void SetCorrection(const JointVector& dq) { correction_ = dq; }
  // Power limit of the drives (a safety controller's reduced-power mode): the servo's
  // corrective torque (the P term, gravity compensation excluded, so a limited arm does not
  // sag) is saturated at `fraction` x the drive's max torque on every joint. 1 = full power
  // (the default); values outside [0, 1] are clamped, a non-finite one counts as 0.
  void SetPowerScale(double fraction);
  double power_scale() const { return power_scale_; }

  // A controlled stop (docs/safety.md, "How the arm stops"): from its present speed each
  // joint decelerates along one smooth profile (speed v0 (1 - 3u^2 + 2u^3), u = t / T, T the
  // same for all joints: kStopTime, longer when a drive's torque needs it) and the servo holds
  // where the profile ends. The servo's reference is fed forward with the loop's damping and
  // the joint's inertia, so the arm follows the profile instead of swinging back for 100 ms
  // (the PD loop's own decay). Braking uses the drives' full torque (the power limit applies
  // again at standstill). References set while braking are ignored. An arm at rest stays where
  // it is.
  static constexpr double kStopTime = 0.02;  // s
  void Stop();
  bool braking() const { return braking_; }
  // Where the last stop's profile ends (the servo's reference once it has).
  JointVector StopTarget() const;

  // Advances exactly `n` physics steps of config.timestep; each runs the servo once. No
  // sleeping: real-time pacing is the caller's business.
  void Step(int n);

  // Puts the arm at motor angles `q` with zero velocity, the compliance joints at their
  // static deflection, reference = q, time and counters unchanged.
  void ResetTo(const JointVector& q);

  uint64_t step_count() const { return steps_; }
  double time() const { return data_->time; }
  double timestep() const { return model_->opt.timestep; }

  JointState ReadJointState() const;
  Wrench ReadWrench() const;
  // Ground truth: the TCP pose of the TRUE arm (for evaluation only).
  Eigen::Isometry3d TrueTcp() const;
  // Current deflection of the series compliance joints (0 where a joint is rigid).
  JointVector ComplianceDeflection() const;
  // Gravity (+payload) torque at the joints computed on the NOMINAL model at `q`, the
  // payload being `payload_mass`. What the compliance model says the springs carry.
  JointVector NominalGravityTorque(const JointVector& q, double payload_mass);

  // The actual payload, and whether the controller's gravity compensation is told of it.
  void SetPayload(double mass, bool tell_controller);
  double payload() const { return payload_mass_; }

  // Moves the obstacle (a mocap box) to `pos`, or far away when `enabled` is false.
  void SetObstacle(bool enabled, const Vec3& pos);
  // Replaces the scripted pushes (at most the number given in the config at Create(); extra
  // entries are ignored and counted as warnings) and the hand guiding script.
  void SetPushes(const std::vector<PushSpec>& pushes);
  void SetHandGuide(const HandGuideSpec& hand) { hand_ = hand; }
  // External force applied at the TCP in the last step (world frame), for inspection.
  Vec3 last_external_force() const { return last_force_; }
  // Number of contacts between the arm and the obstacle in the last step.
  int obstacle_contacts() const;

  // Independent nominal kinematics (the arm the controller knows).
  const NominalKinematics& nominal() const { return kinematics_; }
  const CellConfig& config() const { return config_; }
  const ErrorSet& errors() const { return errors_; }

  // Read-only access for renderers and tests. qpos() is the full TRUE-model state vector
  // (copy model()->nq values to render elsewhere).
  const mjModel* model() const { return model_; }
  const mjData* data() const { return data_; }
  const double* qpos() const { return data_->qpos; }

  // Warnings counted instead of printed (MuJoCo's d->warning plus ours).
  int warning_count() const;

  // qpos address of motor joint i and of its compliance joint (-1 if rigid) in model().
  int motor_qpos(int i) const { return motor_qadr_[i]; }
  int compliance_qpos(int i) const { return compliance_qadr_[i]; }

 private:
  Cell(const CellConfig& config);
  void Controller();
  void Brake();
  void ApplyDisturbances();
  void SolveStaticCompliance();

  CellConfig config_;
  ErrorSet errors_;
  NominalKinematics kinematics_;
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  mjModel* nominal_model_ = nullptr;
  mjData* nominal_data_ = nullptr;
  int motor_qadr_[kNumJoints]{};
  int motor_dadr_[kNumJoints]{};
  int compliance_qadr_[kNumJoints]{};
  int compliance_dadr_[kNumJoints]{};
  int tcp_site_ = -1;
  int tool_body_ = -1;
  int payload_body_ = -1;
  int nominal_payload_body_ = -1;
  int obstacle_mocap_ = -1;
  int obstacle_geom_ = -1;
  int ft_force_adr_ = -1;
  int ft_torque_adr_ = -1;
  JointVector q_ref_{};
  JointVector correction_{};
  double power_scale_ = 1.0;
  bool braking_ = false;
  double stop_t0_ = 0, stop_T_ = 0;  // the stop's start (sim time) and duration (s)
  // Per joint: start, speed, and the feed-forward of the damping (c v0 / kp) and of the inertia
  // (M v0 / kp), scaled by the profile's speed and acceleration.
  JointVector stop_q0_{}, stop_v0_{}, stop_ff_c_{}, stop_ff_j_{};
  static constexpr int kMaxDofs = 64;
  double payload_mass_ = 0.0;
  std::vector<PushSpec> pushes_;  // capacity fixed at Create()
  size_t push_capacity_ = 0;
  HandGuideSpec hand_;
  Vec3 last_force_{};
  uint64_t steps_ = 0;
  int own_warnings_ = 0;
};

}  // namespace sim
}  // namespace arflex

#endif  // ARFLEX_SIM_CELL_H_
