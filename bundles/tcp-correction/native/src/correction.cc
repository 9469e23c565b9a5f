#include "arflex_tcpcorr/correction.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace arflex {
namespace tcpcorr {

bool ValidateOptions(const CorrectionOptions& o, const char** what) {
  const char* bad = nullptr;
  if (!(o.gain > 0.0 && o.gain <= 1.0)) bad = "gain must be in (0, 1]";
  else if (!(o.max_step > 0.0 && std::isfinite(o.max_step))) bad = "max_step must be > 0";
  else if (!(o.max_rate > 0.0 && std::isfinite(o.max_rate))) bad = "max_rate must be > 0";
  else if (!(o.max_correction > 0.0 && std::isfinite(o.max_correction))) bad = "max_correction must be > 0";
  else if (!(o.max_error > 0.0)) bad = "max_error must be > 0";
  else if (!(o.damping >= 0.0 && std::isfinite(o.damping))) bad = "damping must be >= 0";
  if (what != nullptr) *what = bad;
  return bad == nullptr;
}

Vector6d PoseError(const Eigen::Isometry3d& desired, const Eigen::Isometry3d& measured) {
  Vector6d e;
  e.head<3>() = desired.translation() - measured.translation();
  const Eigen::AngleAxisd aa(desired.linear() * measured.linear().transpose());
  e.tail<3>() = aa.angle() * aa.axis();
  return e;
}

Vector6d DampedSolve(const Matrix6d& j, const Vector6d& e, double lambda) {
  const Matrix6d a = j * j.transpose() + lambda * lambda * Matrix6d::Identity();
  return j.transpose() * a.ldlt().solve(e);
}

UpdateResult CorrectionLaw::Update(const Matrix6d& jacobian, const Eigen::Isometry3d& desired,
                                   const Eigen::Isometry3d& measured, bool valid) {
  if (!enabled_) return UpdateResult::kDisabled;
  if (!valid || !measured.matrix().allFinite() || !jacobian.allFinite()) {
    ++holds_;
    return UpdateResult::kHeld;
  }
  Vector6d e = PoseError(desired, measured);
  if (!(e.head<3>().norm() <= options_.max_error)) {
    ++holds_;
    return UpdateResult::kRejected;
  }
  last_error_ = e;
  Matrix6d j = jacobian;
  if (!options_.orientation) {
    j.bottomRows<3>().setZero();
    e.tail<3>().setZero();
  }
  Vector6d step = options_.gain * DampedSolve(j, e, options_.damping);
  bool limited = false;
  const double biggest = step.cwiseAbs().maxCoeff();
  if (biggest > options_.max_step) {
    step *= options_.max_step / biggest;  // keep the direction
    limited = true;
  }
  // The measurement shows the arm with the correction applied so far, not the target the
  // rate limit is still ramping to: the step is taken from there (no wind-up while ramping).
  for (int i = 0; i < kJoints; ++i) {
    const double t = applied_(i) + step(i);
    const double c = std::clamp(t, -options_.max_correction, options_.max_correction);
    limited = limited || c != t;
    target_(i) = c;
  }
  ++updates_;
  return limited ? UpdateResult::kLimited : UpdateResult::kApplied;
}

const Vector6d& CorrectionLaw::Tick(double dt) {
  const double d = options_.max_rate * std::max(0.0, dt);
  for (int i = 0; i < kJoints; ++i) {
    applied_(i) += std::clamp(target_(i) - applied_(i), -d, d);
  }
  return applied_;
}

void CorrectionLaw::SetEnabled(bool enabled) {
  enabled_ = enabled;
  if (!enabled) target_.setZero();  // the applied correction ramps down in Tick()
}

bool CorrectionLaw::SetOptions(const CorrectionOptions& options) {
  if (!ValidateOptions(options, nullptr)) return false;
  options_ = options;
  for (int i = 0; i < kJoints; ++i) {
    target_(i) = std::clamp(target_(i), -options_.max_correction, options_.max_correction);
  }
  return true;
}

bool CorrectionLaw::Restore(const Vector6d& target, const Vector6d& applied, const Vector6d& last_error,
                            long updates, long holds, bool enabled) {
  if (!target.allFinite() || !applied.allFinite() || !last_error.allFinite()) return false;
  const double m = options_.max_correction;
  target_ = target.cwiseMax(-m).cwiseMin(m);
  applied_ = applied;  // not clipped: Tick ramps it to the clipped target, never a jump
  last_error_ = last_error;
  updates_ = updates;
  holds_ = holds;
  enabled_ = enabled;
  return true;
}

}  // namespace tcpcorr
}  // namespace arflex
