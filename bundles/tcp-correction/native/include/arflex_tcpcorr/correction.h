// The outer loop of the paper: a joint correction from the measured and the desired tool
// pose through the nominal model's Jacobian, added to the trajectory's reference.
//
//   target = applied + gain * J_nominal^+ (desired - measured)  (once per valid measurement)
//   applied -> target at no more than max_rate                  (every servo tick)
//
// The step starts from the applied correction (what the measured arm was doing), not from a
// target the rate limit is still ramping to, so a measurement taken mid-ramp does not wind
// the correction up.
//
// The target moves by at most `max_step` per joint per measurement and never beyond
// `max_correction`; an invalid measurement, or one whose error exceeds `max_error`, holds
// the target (the last correction stays applied). Disabling ramps the applied correction back
// to zero at the rate limit, so the reference never jumps. Fixed-size Eigen only: nothing
// here allocates.
#ifndef ARFLEX_TCPCORR_CORRECTION_H_
#define ARFLEX_TCPCORR_CORRECTION_H_

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace arflex {
namespace tcpcorr {

inline constexpr int kJoints = 6;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct CorrectionOptions {
  double gain = 0.6;             // fraction of the measured error corrected per measurement
  double max_step = 2e-3;        // rad: largest change of a joint's target per measurement
  double max_rate = 1e-2;        // rad/s: largest rate of change of an applied correction
  double max_correction = 2e-2;  // rad: largest |correction| of a joint
  double max_error = 0.02;       // m: a larger position error is not trusted (held)
  double damping = 1e-2;         // lambda of the damped pseudo-inverse (tames wrist singularities)
  bool orientation = true;       // correct the orientation error too
};

// Returns whether `options` is usable; otherwise false with `*what` naming the bad field.
bool ValidateOptions(const CorrectionOptions& options, const char** what);

// The 6-D pose error desired - measured in the world frame: position difference (m) and the
// rotation vector of R_desired R_measured^T (rad), matching a geometric Jacobian's rows.
Vector6d PoseError(const Eigen::Isometry3d& desired, const Eigen::Isometry3d& measured);

// Damped least-squares solution dq = J^T (J J^T + lambda^2 I)^-1 e.
Vector6d DampedSolve(const Matrix6d& jacobian, const Vector6d& error, double lambda);

enum class UpdateResult {
  kApplied,   // the target moved (possibly limited)
  kLimited,   // the target moved, clipped by max_step or max_correction
  kHeld,      // invalid measurement: target held
  kRejected,  // error larger than max_error: target held
  kDisabled,  // correction disabled: target is zero
};

class CorrectionLaw {
 public:
  explicit CorrectionLaw(const CorrectionOptions& options) : options_(options) {}

  // One measurement. `jacobian` is the nominal TCP Jacobian at the reference the correction
  // is added to; `desired` the nominal pose of that reference; `measured` the vision pose;
  // `valid` its validity flag.
  UpdateResult Update(const Matrix6d& jacobian, const Eigen::Isometry3d& desired,
                      const Eigen::Isometry3d& measured, bool valid);

  // Advances the applied correction towards the target by at most max_rate * dt per joint
  // (dt in s, at the servo rate). Returns the applied correction.
  const Vector6d& Tick(double dt);

  void SetEnabled(bool enabled);
  bool enabled() const { return enabled_; }
  // New limits; the current target is clipped to the new max_correction. Returns false (and
  // changes nothing) if the options are invalid.
  bool SetOptions(const CorrectionOptions& options);
  const CorrectionOptions& options() const { return options_; }

  // Continues from a state another instance had (state transfer, docs/DECISIONS.md D41): its
  // target and applied correction, last error and counters. The target is clipped to this
  // law's max_correction, the applied
  // correction ramps there at max_rate (it is not clipped: that would be a jump). False (nothing changed) when a value
  // is not finite.
  bool Restore(const Vector6d& target, const Vector6d& applied, const Vector6d& last_error,
               long updates, long holds, bool enabled);

  const Vector6d& target() const { return target_; }
  const Vector6d& applied() const { return applied_; }
  const Vector6d& last_error() const { return last_error_; }
  long updates() const { return updates_; }
  long holds() const { return holds_; }

 private:
  CorrectionOptions options_;
  bool enabled_ = true;
  Vector6d target_ = Vector6d::Zero();
  Vector6d applied_ = Vector6d::Zero();
  Vector6d last_error_ = Vector6d::Zero();
  long updates_ = 0;
  long holds_ = 0;
};

}  // namespace tcpcorr
}  // namespace arflex

#endif  // ARFLEX_TCPCORR_CORRECTION_H_
