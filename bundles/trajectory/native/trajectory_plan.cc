#include "trajectory_plan.h"

#include <algorithm>
#include <cmath>

namespace arflex {
namespace traj {

namespace {
constexpr double kQuinticV = 1.875;               // peak s' * T
constexpr double kQuinticA = 5.773502691896258;   // peak s'' * T^2 (10 / sqrt(3))
constexpr double kCornerRad = 30.0 * 3.14159265358979323846 / 180.0;
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

Snapshot Player::Save() const {
  Snapshot s;
  s.initialized = initialized_;
  s.done = done_;
  s.active = active_;
  s.path = path_;
  s.index = idx_;
  s.run_begin = run_begin_;
  s.run_n = run_n_;
  s.cursor = cursor_;
  s.completed = completed_;
  s.profile = shape_.profile;
  s.rate = rate_;
  s.tau = tau_;
  s.shape_t = shape_.T;
  s.shape_ta = shape_.ta;
  s.path_len = path_len_;
  s.cursor_sigma = cursor_sigma_;
  s.q0 = q0_;
  s.dq = dq_;
  s.ik_q = ik_q_;
  s.p0 = p0_;
  s.p1 = p1_;
  s.r0 = r0_;
  s.r1 = r1_;
  s.tool = tool_;
  s.q_plan = q_plan_;
  s.q_plan_prev = q_plan_prev_;
  s.q_out = q_out_;
  s.v_out = v_out_;
  return s;
}

bool Player::Restore(const Snapshot& s, const cellkin::Model* model, const cellkin::Program* program,
                     double dt) {
  const size_t n = program ? program->motions.size() : 0;
  if (!program || s.index > n || (s.path && (s.run_n == 0 || s.run_begin + s.run_n > n || s.cursor >= s.run_n)))
    return false;
  const bool finite = std::isfinite(s.rate) && std::isfinite(s.tau) && std::isfinite(s.shape_t) &&
                      std::isfinite(s.shape_ta) && std::isfinite(s.path_len) &&
                      std::isfinite(s.cursor_sigma) && s.q0.allFinite() && s.dq.allFinite() &&
                      s.ik_q.allFinite() && s.p0.allFinite() && s.p1.allFinite() &&
                      s.r0.coeffs().allFinite() && s.r1.coeffs().allFinite() &&
                      s.tool.matrix().allFinite() && s.q_plan.allFinite() &&
                      s.q_plan_prev.allFinite() && s.q_out.allFinite() && s.v_out.allFinite();
  if (!finite) return false;
  model_ = model;
  prog_ = program;
  dt_ = dt > 0 ? dt : 0.001;
  initialized_ = s.initialized;
  done_ = s.done;
  active_ = s.active;
  path_ = s.path;
  idx_ = s.index;
  run_begin_ = s.run_begin;
  run_n_ = s.run_n;
  cursor_ = s.cursor;
  completed_ = s.completed;
  shape_.profile = s.profile;
  shape_.T = s.shape_t;
  shape_.ta = s.shape_ta;
  rate_ = s.rate;
  tau_ = s.tau;
  path_len_ = s.path_len;
  cursor_sigma_ = s.cursor_sigma;
  q0_ = s.q0;
  dq_ = s.dq;
  ik_q_ = s.ik_q;
  p0_ = s.p0;
  p1_ = s.p1;
  r0_ = s.r0;
  r1_ = s.r1;
  tool_ = s.tool;
  q_plan_ = s.q_plan;
  q_plan_prev_ = s.q_plan_prev;
  q_out_ = s.q_out;
  v_out_ = s.v_out;
  return true;
}

void Player::Switch(const cellkin::Program* program) {
  prog_ = program;
  done_ = false;
  active_ = false;
  path_ = false;
  idx_ = 0;
  tau_ = 0;
  q_plan_prev_ = q_plan_;
}

void Player::Init(const Q& q0) {
  q_plan_ = q_plan_prev_ = q_out_ = ik_q_ = q0;
  v_out_.setZero();
  initialized_ = true;
}

Q Player::PathPoint(size_t i) const {
  if (i == 0) return q0_;
  const cellkin::Motion& m = prog_->motions[run_begin_ + i - 1];
  Q q;
  for (int j = 0; j < 6; ++j) q[j] = m.v[j];
  return q;
}

Q Player::Tangent(size_t i) const {
  const size_t n = run_n_;  // points 0..n
  if (i == 0) return (PathPoint(1) - PathPoint(0)) / std::max(Chord(0), 1e-12);
  if (i == n) return (PathPoint(n) - PathPoint(n - 1)) / std::max(Chord(n - 1), 1e-12);
  return (PathPoint(i + 1) - PathPoint(i - 1)) / std::max(Chord(i - 1) + Chord(i), 1e-12);
}

void Player::Hermite(size_t i, double u, Q* q, Q* d1, Q* d2) const {
  const Q a = PathPoint(i), b = PathPoint(i + 1);
  const double l = std::max(Chord(i), 1e-12);
  const Q ma = Tangent(i) * l, mb = Tangent(i + 1) * l;
  const double u2 = u * u, u3 = u2 * u;
  if (q)
    *q = (2 * u3 - 3 * u2 + 1) * a + (u3 - 2 * u2 + u) * ma + (-2 * u3 + 3 * u2) * b +
         (u3 - u2) * mb;
  if (d1)
    *d1 = ((6 * u2 - 6 * u) * a + (3 * u2 - 4 * u + 1) * ma + (-6 * u2 + 6 * u) * b +
           (3 * u2 - 2 * u) * mb) / l;
  if (d2)
    *d2 = ((12 * u - 6) * a + (6 * u - 4) * ma + (-12 * u + 6) * b + (6 * u - 2) * mb) / (l * l);
}

bool Player::StartSegment(const Limits& lim) {
  const size_t n = prog_->motions.size();
  for (size_t tries = 0; tries <= n; ++tries) {
    if (idx_ >= n) return false;
    const cellkin::Motion& m = prog_->motions[idx_];
    tau_ = 0;
    path_ = false;
    if (m.kind == cellkin::Motion::kVia) {
      // The run: via points up to and including the closing ptp (the parser guarantees it).
      run_begin_ = idx_;
      size_t k = idx_;
      q0_ = q_plan_;
      // The run ends at the closing ptp, or earlier at a sharp corner (a via point where the
      // path turns by more than kCornerRad): the arm stops there, and the straight stretches
      // are not slowed down by the corner's curvature.
      run_n_ = 1;
      while (prog_->motions[k].kind == cellkin::Motion::kVia) {
        run_n_ = k - idx_ + 1;
        const Q in = PathPoint(run_n_) - PathPoint(run_n_ - 1);
        Q out;
        for (int j = 0; j < 6; ++j) out[j] = prog_->motions[k + 1].v[j] - prog_->motions[k].v[j];
        const double c = in.norm() * out.norm();
        if (c > 0 && in.dot(out) < std::cos(kCornerRad) * c) break;
        ++k;
      }
      run_n_ = k - idx_ + 1;
      path_len_ = 0;
      double speed = 1.0;
      Q dmax = Q::Zero(), kmax = Q::Zero();
      for (size_t i = 0; i < run_n_; ++i) {
        path_len_ += Chord(i);
        speed = std::min(speed, prog_->motions[run_begin_ + i].speed);
        if (Chord(i) <= 0) continue;
        for (int s = 0; s <= 8; ++s) {
          Q d1, d2;
          Hermite(i, s / 8.0, nullptr, &d1, &d2);
          dmax = dmax.cwiseMax(d1.cwiseAbs());
          kmax = kmax.cwiseMax(d2.cwiseAbs());  // linear in u: the ends bound it exactly
        }
      }
      // |q'| sigma' <= v_j and |q''| sigma'^2 + |q'| sigma'' <= a_j (half each); 5 % margin
      // on the sampled first derivative.
      double sd_max = 1e9, sdd_max = 1e9;
      for (int j = 0; j < 6; ++j) {
        const double d = dmax[j] * 1.05, kk = kmax[j];
        if (d > 0) sd_max = std::min(sd_max, lim.vmax[j] * lim.speed * speed / d);
        if (kk > 0) sd_max = std::min(sd_max, std::sqrt(0.5 * lim.accel / kk));
        if (d > 0) sdd_max = std::min(sdd_max, 0.5 * lim.accel / d);
      }
      shape_ = path_len_ > 0 ? PlanShape(lim.profile, path_len_ / sd_max, path_len_ / sdd_max)
                             : Shape();
      path_ = true;
      cursor_ = 0;
      cursor_sigma_ = 0;
      if (shape_.T <= 0) {
        idx_ = run_begin_ + run_n_;  // already at every point
        continue;
      }
      active_ = true;
      return true;
    }
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
      tool_ = tool_next_;  // this motion's tool, kept to its end
      const Eigen::Isometry3d t = model_->TcpOf(q_plan_, tool_);
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
  if (path_) {
    if (tau_ >= shape_.T) {
      q_plan_ = PathPoint(run_n_);  // exactly on the end
      return;
    }
    const double sigma = s * path_len_;
    // sigma only grows within a motion: move the cursor forward.
    while (cursor_ + 1 < run_n_ && sigma > cursor_sigma_ + Chord(cursor_)) {
      cursor_sigma_ += Chord(cursor_);
      ++cursor_;
    }
    const double l = Chord(cursor_);
    const double u = l > 0 ? std::min(1.0, std::max(0.0, (sigma - cursor_sigma_) / l)) : 1.0;
    Hermite(cursor_, u, &q_plan_, nullptr, nullptr);
    return;
  }
  if (m.kind == cellkin::Motion::kPtp) {
    q_plan_ = q0_ + s * dq_;
    if (tau_ >= shape_.T)
      for (int j = 0; j < 6; ++j) q_plan_[j] = m.v[j];  // exactly on the target
  } else if (m.kind == cellkin::Motion::kLin) {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.translation() = p0_ + s * (p1_ - p0_);
    t.linear() = r0_.slerp(s, r1_).toRotationMatrix();
    Q q = ik_q_;
    const double err = model_->IkTool(t, tool_, &q, 4);
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
        idx_ = path_ ? run_begin_ + run_n_ : idx_ + 1;
        path_ = false;
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
