#include "trajectory_plan.h"

#include <algorithm>
#include <cmath>

namespace arflex {
namespace traj {

namespace {
constexpr double kQuinticV = 1.875;               // peak s' * T
constexpr double kQuinticA = 5.773502691896258;   // peak s'' * T^2 (10 / sqrt(3))
}  // namespace

Limits DefaultLimits() {
  Limits l;
  const double deg = 3.14159265358979323846 / 180.0;
  const double v[6] = {123 * deg, 115 * deg, 112 * deg, 179 * deg, 172 * deg, 219 * deg};
  for (int j = 0; j < 6; ++j) l.vmax[j] = v[j];
  l.speed = 1.0;
  l.accel = 3.0;
  l.accel_max = 20.0;
  l.lin_speed = 0.25;
  l.lin_accel = 1.0;
  l.rot_speed = 1.0;
  l.rot_accel = 2.0;
  l.stop_time = 0.3;
  l.profile = kQuintic;
  return l;
}

double Shape::Eval(double tau) const {
  if (T <= 0 || tau >= T) return 1.0;
  if (tau <= 0) return 0.0;
  if (profile == kQuintic) {
    const double u = tau / T;
    return u * u * u * (10 - 15 * u + 6 * u * u);
  }
  const double vn = 1.0 / (T - ta), an = vn / ta;
  if (tau < ta) return 0.5 * an * tau * tau;
  if (tau < T - ta) return 0.5 * an * ta * ta + vn * (tau - ta);
  const double r = T - tau;
  return 1.0 - 0.5 * an * r * r;
}

Shape PlanShape(Profile p, double r_v, double r_a) {
  Shape s;
  s.profile = p;
  if (r_v <= 0 && r_a <= 0) return s;  // nothing to move
  if (p == kQuintic) {
    s.T = std::max(kQuinticV * r_v, std::sqrt(kQuinticA * r_a));
    return s;
  }
  // Trapezoid: peak s' = 1 / (T - ta), s'' = s' / ta; need T - ta >= r_v, ta (T - ta) >= r_a.
  if (r_v * r_v >= r_a && r_v > 0) {
    s.ta = r_a / r_v;
    s.T = r_v + s.ta;
  } else {
    s.ta = std::sqrt(r_a);
    s.T = 2 * s.ta;
  }
  return s;
}

void Player::Begin(const cellkin::Model* model, const cellkin::Program* program, double dt) {
  model_ = model;
  prog_ = program;
  dt_ = dt > 0 ? dt : 0.001;
  done_ = false;
  active_ = false;
  idx_ = 0;
  rate_ = 0;
  tau_ = 0;
  v_out_.setZero();
  q_plan_prev_ = q_plan_;
}

void Player::Init(const Q& q0) {
  q_plan_ = q_plan_prev_ = q_out_ = ik_q_ = q0;
  v_out_.setZero();
  initialized_ = true;
}

bool Player::StartSegment(const Limits& lim) {
  const size_t n = prog_->motions.size();
  for (size_t tries = 0; tries <= n; ++tries) {
    if (idx_ >= n) return false;
    const cellkin::Motion& m = prog_->motions[idx_];
    tau_ = 0;
    if (m.kind == cellkin::Motion::kPtp) {
      double rv = 0, ra = 0;
      q0_ = q_plan_;
      for (int j = 0; j < 6; ++j) {
        dq_[j] = m.v[j] - q0_[j];
        const double d = std::fabs(dq_[j]);
        rv = std::max(rv, d / (lim.vmax[j] * lim.speed * m.speed));
        ra = std::max(ra, d / lim.accel);
      }
      shape_ = PlanShape(lim.profile, rv, ra);
    } else if (m.kind == cellkin::Motion::kLin) {
      const Eigen::Isometry3d t = model_->Tcp(q_plan_);
      p0_ = t.translation();
      r0_ = Eigen::Quaterniond(t.linear());
      p1_ = Eigen::Vector3d(m.v[0], m.v[1], m.v[2]);
      r1_ = Eigen::Quaterniond(m.v[3], m.v[4], m.v[5], m.v[6]);
      if (r0_.dot(r1_) < 0) r1_.coeffs() = -r1_.coeffs();  // shortest rotation
      const double len = (p1_ - p0_).norm();
      const double ang = r0_.angularDistance(r1_);
      const double v = (m.speed > 0 ? m.speed : lim.lin_speed) * lim.speed;
      const double rv = std::max(len / v, ang / (lim.rot_speed * lim.speed));
      const double ra = std::max(len / lim.lin_accel, ang / lim.rot_accel);
      shape_ = PlanShape(lim.profile, rv, ra);
      ik_q_ = q_plan_;
    } else {
      shape_ = Shape();
      shape_.T = m.v[0];
    }
    if (shape_.T > 0) {
      active_ = true;
      return true;
    }
    ++idx_;  // nothing to do for this motion (already there)
  }
  return false;
}

void Player::Evaluate() {
  const cellkin::Motion& m = prog_->motions[idx_];
  const double s = shape_.Eval(tau_);
  if (m.kind == cellkin::Motion::kPtp) {
    q_plan_ = q0_ + s * dq_;
    if (tau_ >= shape_.T)
      for (int j = 0; j < 6; ++j) q_plan_[j] = m.v[j];  // exactly on the target
  } else if (m.kind == cellkin::Motion::kLin) {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.translation() = p0_ + s * (p1_ - p0_);
    t.linear() = r0_.slerp(s, r1_).toRotationMatrix();
    Q q = ik_q_;
    const double err = model_->Ik(t, &q, 4);
    if (err > 1e-6 || !q.allFinite()) {
      ++ik_warnings_;
      if (!q.allFinite()) q = ik_q_;
    }
    for (int j = 0; j < 6; ++j)
      q[j] = std::min(model_->upper(j), std::max(model_->lower(j), q[j]));
    ik_q_ = q;
    q_plan_ = q;
  }
}

void Player::Step(const Limits& lim, double target_rate, bool loop) {
  const double dr = dt_ / std::max(lim.stop_time, dt_);
  if (!active_)
    rate_ = target_rate;  // between motions the plan is at rest: no ramp needed
  else if (rate_ < target_rate)
    rate_ = std::min(target_rate, rate_ + dr);
  else
    rate_ = std::max(target_rate, rate_ - dr);
  q_plan_prev_ = q_plan_;
  if (!done_ && rate_ > 0) {
    if (!active_ && !StartSegment(lim)) {
      if (loop && !prog_->motions.empty()) {
        idx_ = 0;
        ++completed_;
        if (!StartSegment(lim)) done_ = true;
      } else {
        done_ = true;
        ++completed_;
      }
    }
    if (active_) {
      tau_ = std::min(shape_.T, tau_ + rate_ * dt_);
      Evaluate();
      if (tau_ >= shape_.T) {
        active_ = false;
        ++idx_;
      }
    }
  }
  Limit(lim);
}

void Player::Limit(const Limits& lim) {
  bool limited = false;
  const double a = lim.accel_max;
  for (int j = 0; j < 6; ++j) {
    // Feed-forward the plan's own velocity; close any lag without overshoot (stopping
    // distance), then clamp acceleration and speed.
    const double vff = (q_plan_[j] - q_plan_prev_[j]) / dt_;
    const double lag = q_plan_prev_[j] - q_out_[j];
    double vc = 0;
    if (lag != 0) {
      const double mag = std::min(std::fabs(lag) / dt_, std::sqrt(2 * a * std::fabs(lag)));
      vc = lag > 0 ? mag : -mag;
    }
    double v = vff + vc;
    const double lo = v_out_[j] - a * dt_, hi = v_out_[j] + a * dt_;
    if (v < lo || v > hi) limited = true;
    v = std::min(hi, std::max(lo, v));
    if (std::fabs(v) > lim.vmax[j]) {
      limited = true;
      v = v > 0 ? lim.vmax[j] : -lim.vmax[j];
    }
    q_out_[j] += v * dt_;
    v_out_[j] = v;
  }
  if (limited) ++limited_cycles_;
}

}  // namespace traj
}  // namespace arflex
