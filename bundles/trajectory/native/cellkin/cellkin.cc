#include "cellkin.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

namespace arflex {
namespace cellkin {
namespace {

cellmodel::JointVector ToArray(const Q& q) {
  cellmodel::JointVector a;
  for (int i = 0; i < 6; ++i) a[i] = q[i];
  return a;
}

Eigen::Vector3d V3(const cellmodel::Vec3& v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

// Rotation error as a rotation vector: the rotation that takes `have` to `want` (world).
Eigen::Vector3d RotError(const Eigen::Matrix3d& want, const Eigen::Matrix3d& have) {
  Eigen::AngleAxisd aa(want * have.transpose());
  return aa.axis() * aa.angle();
}

}  // namespace

Model::Model() : arm_(cellmodel::DefaultArm()), kin_(arm_) {}

Eigen::Isometry3d Model::Tcp(const Q& q) const { return kin_.Tcp(ToArray(q)); }
Eigen::Isometry3d Model::Flange(const Q& q) const { return kin_.Flange(ToArray(q)); }
cellmodel::Jacobian6 Model::Jacobian(const Q& q) const { return kin_.TcpJacobian(ToArray(q)); }

Eigen::Isometry3d Model::NominalTool() const {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = V3(arm_.tcp_offset);
  return t;
}

Eigen::Isometry3d Model::TcpOf(const Q& q, const Eigen::Isometry3d& tool) const {
  return Flange(q) * tool;
}

cellmodel::Jacobian6 Model::JacobianOf(const Q& q, const Eigen::Isometry3d& tool) const {
  // The nominal TCP Jacobian moved to another point of the same body: the angular rows stay,
  // the linear velocity of a point p is v_tcp + w x (p - p_tcp).
  cellmodel::Jacobian6 j = Jacobian(q);
  const Eigen::Vector3d d = TcpOf(q, tool).translation() - Tcp(q).translation();
  Eigen::Matrix3d skew;
  skew << 0, -d.z(), d.y(), d.z(), 0, -d.x(), -d.y(), d.x(), 0;
  j.topRows<3>() -= skew * j.bottomRows<3>();
  return j;
}

double Model::IkTool(const Eigen::Isometry3d& target, const Eigen::Isometry3d& tool, Q* q,
                     int iters) const {
  double err = 0;
  for (int it = 0; it <= iters; ++it) {
    const Eigen::Isometry3d t = TcpOf(*q, tool);
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = target.translation() - t.translation();
    e.tail<3>() = RotError(target.linear(), t.linear());
    err = e.head<3>().norm() + e.tail<3>().norm();
    if (it == iters || err < 1e-12) break;
    const cellmodel::Jacobian6 j = JacobianOf(*q, tool);
    // Damped least squares: dq = J^T (J J^T + l^2 I)^-1 e; the damping only matters near
    // singularities (l = 1e-3).
    Eigen::Matrix<double, 6, 6> a = j * j.transpose();
    a.diagonal().array() += 1e-6;
    const Q dq = j.transpose() * a.ldlt().solve(e);
    *q += dq;
  }
  return err;
}

double Model::Ik(const Eigen::Isometry3d& target, Q* q, int iters) const {
  return IkTool(target, NominalTool(), q, iters);
}

Q Model::GravityTorque(const Q& q, double payload_kg) const {
  // Body frames: body i = parent * Trans(offset_i) * Rot(axis_i, q_i), aligned with the
  // world at q = 0 (as cellmodel::DefaultArm() has them).
  Eigen::Isometry3d frame[6];
  Eigen::Vector3d axis[6], com[6];
  double mass[6];
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 6; ++i) {
    const cellmodel::LinkParams& l = arm_.links[i];
    const Eigen::Vector3d a = V3(l.axis).normalized();
    t = t * Eigen::Translation3d(V3(l.offset)) * Eigen::AngleAxisd(q[i], a);
    frame[i] = t;
    axis[i] = t.linear() * a;
    com[i] = t * V3(l.com);
    mass[i] = l.mass;
  }
  // Tool and payload ride on the last body: fold them into one extra point mass set.
  const Eigen::Vector3d tool_c = frame[5] * V3(arm_.tool_com);
  const Eigen::Vector3d pay_c = frame[5] * V3(arm_.payload_com);
  const Eigen::Vector3d g(0, 0, -kGravity);
  Q tau;
  for (int j = 0; j < 6; ++j) {
    const Eigen::Vector3d pj = frame[j].translation();
    Eigen::Vector3d m = Eigen::Vector3d::Zero();  // moment of gravity about joint j's origin
    for (int i = j; i < 6; ++i) m += (com[i] - pj).cross(mass[i] * g);
    m += (tool_c - pj).cross(arm_.tool_mass * g);
    m += (pay_c - pj).cross(payload_kg * g);
    tau[j] = -axis[j].dot(m);  // the drive holds against gravity
  }
  return tau;
}

Q Model::InverseDynamics(const Q& q, const Q& qd, const Q& qdd, double payload_kg,
                         Eigen::Vector3d* tool_accel) const {
  // Forward pass in the world frame. Body i turns about axis z[i] through its origin p[i];
  // the base "accelerates" upwards at g, which adds gravity to every body at once.
  Eigen::Vector3d z[6], p[6], c[6], w[6], al[6], ap[6], ac[6];
  Eigen::Matrix3d rot[6];
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  Eigen::Vector3d w_prev = Eigen::Vector3d::Zero(), al_prev = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_prev(0, 0, kGravity), p_prev = Eigen::Vector3d::Zero();
  for (int i = 0; i < 6; ++i) {
    const cellmodel::LinkParams& l = arm_.links[i];
    const Eigen::Vector3d a = V3(l.axis).normalized();
    t = t * Eigen::Translation3d(V3(l.offset)) * Eigen::AngleAxisd(q[i], a);
    rot[i] = t.linear();
    p[i] = t.translation();
    z[i] = rot[i] * a;
    c[i] = t * V3(l.com);
    const Eigen::Vector3d r = p[i] - p_prev;  // the joint's origin rides on the parent
    ap[i] = a_prev + al_prev.cross(r) + w_prev.cross(w_prev.cross(r));
    w[i] = w_prev + z[i] * qd[i];
    al[i] = al_prev + z[i] * qdd[i] + w_prev.cross(z[i] * qd[i]);
    const Eigen::Vector3d rc = c[i] - p[i];
    ac[i] = ap[i] + al[i].cross(rc) + w[i].cross(w[i].cross(rc));
    w_prev = w[i];
    al_prev = al[i];
    a_prev = ap[i];
    p_prev = p[i];
  }
  // The tool and the payload: point masses on the last body.
  const Eigen::Vector3d tool_c = t * V3(arm_.tool_com);
  const Eigen::Vector3d pay_c = t * V3(arm_.payload_com);
  auto point_accel = [&](const Eigen::Vector3d& pt) {
    const Eigen::Vector3d r = pt - p[5];
    return Eigen::Vector3d(ap[5] + al[5].cross(r) + w[5].cross(w[5].cross(r)));
  };
  const Eigen::Vector3d a_tool = point_accel(tool_c), a_pay = point_accel(pay_c);
  if (tool_accel) *tool_accel = a_tool - Eigen::Vector3d(0, 0, kGravity);
  // Backward pass: force f and moment n (about p[i]) that body i-1 exerts on body i.
  Eigen::Vector3d f_next = Eigen::Vector3d::Zero(), n_next = Eigen::Vector3d::Zero();
  Q tau;
  for (int i = 5; i >= 0; --i) {
    const cellmodel::LinkParams& l = arm_.links[i];
    const Eigen::Matrix3d inertia = rot[i] * V3(l.inertia).asDiagonal() * rot[i].transpose();
    Eigen::Vector3d f = l.mass * ac[i];
    Eigen::Vector3d n = inertia * al[i] + w[i].cross(inertia * w[i]) + (c[i] - p[i]).cross(f);
    if (i == 5) {
      const Eigen::Vector3d ft = arm_.tool_mass * a_tool, fp = payload_kg * a_pay;
      n += (tool_c - p[5]).cross(ft) + (pay_c - p[5]).cross(fp);
      f += ft + fp;
    } else {
      n += n_next + (p[i + 1] - p[i]).cross(f_next);
      f += f_next;
    }
    tau[i] = z[i].dot(n) + l.armature * qdd[i] + l.damping * qd[i];
    f_next = f;
    n_next = n;
  }
  return tau;
}

void Model::ToolWeightWrench(const Q& q, double payload_kg, Eigen::Vector3d* f,
                             Eigen::Vector3d* tq) const {
  const Eigen::Matrix3d r = Flange(q).linear();
  const Eigen::Vector3d up(0, 0, kGravity);
  // The arm pushes the tool and payload up with their weight; expressed in the flange frame.
  const Eigen::Vector3d ft = r.transpose() * (arm_.tool_mass * up);
  const Eigen::Vector3d fp = r.transpose() * (payload_kg * up);
  *f = ft + fp;
  // Torque about the flange origin the arm exerts to hold the coms: -(c x m g) = c x m up.
  *tq = V3(arm_.tool_com).cross(ft) + V3(arm_.payload_com).cross(fp);
}

Eigen::Vector3d Model::ContactForceWorld(const Q& q, const Eigen::Vector3d& f_sensor,
                                         double payload_kg) const {
  Eigen::Vector3d f0, t0;
  ToolWeightWrench(q, payload_kg, &f0, &t0);
  // Tool at rest: F_arm + F_contact + m g = 0 and F_arm(no contact) = -m g, so
  // F_contact = -(F_arm - F_arm(no contact)).
  return -(Flange(q).linear() * (f_sensor - f0));
}

Eigen::Vector3d Model::ContactForceWorld(const Q& q, const Eigen::Vector3d& f_sensor,
                                         double payload_kg,
                                         const Eigen::Vector3d& tool_accel) const {
  // F_arm + F_contact + m g = m a, so F_contact = -(F_arm - m (a - g)): the static case
  // above plus the force that accelerates the tool.
  return ContactForceWorld(q, f_sensor, payload_kg) +
         (arm_.tool_mass + payload_kg) * tool_accel;
}

bool ContactMonitor::Update(int64_t t_ns, const Q& q, const Q& qd, const Q& tau,
                            double payload_kg) {
  if (have_prev_ && t_ns == t_prev_) return false;
  const double dt = have_prev_ ? (t_ns - t_prev_) * 1e-9 : 0.0;
  const bool diff = have_prev_ && dt > 0 && dt <= kMaxGap;
  const Q qdd = diff ? Q((qd - qd_prev_) / dt) : Q::Zero();
  const double decay = dt > 0 ? std::exp(-dt / kHoldTau) : 1.0;
  const Q moving = model_->InverseDynamics(q, qd, Q::Zero(), payload_kg);
  const Q full = model_->InverseDynamics(q, qd, qdd, payload_kg, &a_tool_);
  if (!diff) a_tool_.setZero();
  ext_ = tau - full;
  const Q inertial = (full - moving).cwiseAbs() * kInertialShare;
  hold_t_ = (hold_t_ * decay).cwiseMax(inertial);
  const double m = model_->arm().tool_mass + payload_kg;
  hold_f_ = std::max(hold_f_ * decay, kInertialShare * m * a_tool_.norm());
  q_ = q;
  qd_prev_ = qd;
  t_prev_ = t_ns;
  have_prev_ = true;
  return true;
}

Eigen::Vector3d ContactMonitor::ContactForce(const Eigen::Vector3d& f_sensor,
                                             double payload_kg) const {
  return model_->ContactForceWorld(q_, f_sensor, payload_kg, a_tool_);
}

// ---- programs -----------------------------------------------------------------------------

namespace {

bool Fail(std::string* err, const std::string& origin, int line, const std::string& what) {
  *err = origin + ":" + std::to_string(line) + ": " + what;
  return false;
}

bool ParseDouble(const std::string& s, double* v) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  *v = std::strtod(s.c_str(), &end);
  return errno == 0 && end && *end == '\0' && std::isfinite(*v);
}

}  // namespace

bool ParseProgram(const std::string& text, const std::string& origin, const Model& model,
                  Program* out, std::string* err) {
  out->has_start = false;
  out->start = Q::Zero();
  out->motions.clear();
  out->origin = origin;
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  bool header = false;
  while (std::getline(in, raw)) {
    ++line;
    if (raw.size() > 4096) return Fail(err, origin, line, "line longer than 4096 characters");
    const size_t hash = raw.find('#');
    if (hash != std::string::npos) raw.resize(hash);
    std::istringstream ls(raw);
    std::vector<std::string> tok;
    std::string w;
    while (ls >> w) tok.push_back(w);
    if (tok.empty()) continue;
    if (!header) {
      if (tok.size() != 2 || tok[0] != "arflex-program" || tok[1] != "1")
        return Fail(err, origin, line, "expected the header 'arflex-program 1', found '" +
                                           tok[0] + "'");
      header = true;
      continue;
    }
    const std::string& kw = tok[0];
    std::vector<double> num;
    double speed = 0;
    bool has_speed = false;
    for (size_t i = 1; i < tok.size(); ++i) {
      if (tok[i] == "speed") {
        if (i + 2 != tok.size() || !ParseDouble(tok[i + 1], &speed))
          return Fail(err, origin, line, "'speed' needs one number at the end of the line");
        has_speed = true;
        break;
      }
      double v;
      if (!ParseDouble(tok[i], &v))
        return Fail(err, origin, line, "'" + tok[i] + "' is not a number (" + kw + ")");
      num.push_back(v);
    }
    if (out->motions.size() >= kMaxMotions)
      return Fail(err, origin, line, "more than " + std::to_string(kMaxMotions) + " motions");
    Motion m{};
    m.line = line;
    if (kw == "start" || kw == "ptp" || kw == "via") {
      if (num.size() != 6)
        return Fail(err, origin, line, kw + " needs 6 joint angles (rad), got " +
                                           std::to_string(num.size()));
      for (int j = 0; j < 6; ++j) {
        if (num[j] < model.lower(j) || num[j] > model.upper(j))
          return Fail(err, origin, line,
                      "joint " + std::to_string(j + 1) + " target " + std::to_string(num[j]) +
                          " rad outside the limits [" + std::to_string(model.lower(j)) + ", " +
                          std::to_string(model.upper(j)) + "]");
      }
      if (kw == "start") {
        if (has_speed) return Fail(err, origin, line, "'start' takes no speed");
        if (out->has_start) return Fail(err, origin, line, "second 'start'");
        out->has_start = true;
        for (int j = 0; j < 6; ++j) out->start[j] = num[j];
        continue;
      }
      if (has_speed && !(speed > 0 && speed <= 1))
        return Fail(err, origin, line, kw + " speed must be in (0, 1]");
      m.kind = kw == "via" ? Motion::kVia : Motion::kPtp;
      for (int j = 0; j < 6; ++j) m.v[j] = num[j];
      m.speed = has_speed ? speed : 1.0;
    } else if (kw == "lin") {
      if (num.size() != 7)
        return Fail(err, origin, line, "lin needs x y z qw qx qy qz, got " +
                                           std::to_string(num.size()) + " numbers");
      const double n = std::sqrt(num[3] * num[3] + num[4] * num[4] + num[5] * num[5] +
                                 num[6] * num[6]);
      if (n < 1e-6) return Fail(err, origin, line, "lin orientation quaternion is zero");
      if (has_speed && !(speed > 0 && speed <= 10))
        return Fail(err, origin, line, "lin speed must be in (0, 10] m/s");
      m.kind = Motion::kLin;
      for (int k = 0; k < 3; ++k) m.v[k] = num[k];
      for (int k = 3; k < 7; ++k) m.v[k] = num[k] / n;
      m.speed = has_speed ? speed : 0.0;
    } else if (kw == "wait") {
      if (num.size() != 1 || has_speed)
        return Fail(err, origin, line, "wait needs one duration in seconds");
      if (!(num[0] > 0 && num[0] <= 3600))
        return Fail(err, origin, line, "wait duration must be in (0, 3600] s");
      m.kind = Motion::kWait;
      m.v[0] = num[0];
    } else {
      return Fail(err, origin, line, "unknown statement '" + kw +
                                         "' (expected start, ptp, via, lin or wait)");
    }
    out->motions.push_back(m);
  }
  if (!header) return Fail(err, origin, line, "empty program (no 'arflex-program 1' header)");
  if (out->motions.empty()) return Fail(err, origin, line, "program has no motion");
  for (size_t i = 0; i < out->motions.size(); ++i) {
    if (out->motions[i].kind != Motion::kVia) continue;
    size_t k = i;
    while (k < out->motions.size() && out->motions[k].kind == Motion::kVia) ++k;
    if (k == out->motions.size() || out->motions[k].kind != Motion::kPtp)
      return Fail(err, origin, out->motions[i].line,
                  "via points must be followed by a ptp (the end of the path)");
    i = k;
  }
  return true;
}

bool LoadProgramFile(const std::string& path, const Model& model, Program* out,
                     std::string* err) {
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    *err = path + ": cannot open: " + std::strerror(errno);
    return false;
  }
  std::ostringstream ss;
  ss << f.rdbuf();
  if (ss.str().size() > (64u << 20)) {
    *err = path + ": larger than 64 MiB";
    return false;
  }
  return ParseProgram(ss.str(), path, model, out, err);
}

bool WriteProgramFile(const std::string& path, const Program& p, std::string* err) {
  std::ostringstream s;
  s.precision(17);
  s << "arflex-program 1\n# written by " << p.origin << "\n";
  if (p.has_start) {
    s << "start";
    for (int j = 0; j < 6; ++j) s << ' ' << p.start[j];
    s << '\n';
  }
  for (const Motion& m : p.motions) {
    switch (m.kind) {
      case Motion::kPtp:
      case Motion::kVia:
        s << (m.kind == Motion::kVia ? "via" : "ptp");
        for (int j = 0; j < 6; ++j) s << ' ' << m.v[j];
        if (m.speed != 1.0) s << " speed " << m.speed;
        break;
      case Motion::kLin:
        s << "lin";
        for (int k = 0; k < 7; ++k) s << ' ' << m.v[k];
        if (m.speed > 0) s << " speed " << m.speed;
        break;
      case Motion::kWait:
        s << "wait " << m.v[0];
        break;
    }
    s << '\n';
  }
  const std::string data = s.str();
  const std::string tmp = path + ".tmp." + std::to_string(getpid());
  int fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    *err = tmp + ": cannot create: " + std::strerror(errno);
    return false;
  }
  size_t off = 0;
  while (off < data.size()) {
    ssize_t n = write(fd, data.data() + off, data.size() - off);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      *err = tmp + ": write failed: " + std::strerror(errno);
      close(fd);
      unlink(tmp.c_str());
      return false;
    }
    off += static_cast<size_t>(n);
  }
  if (fsync(fd) != 0 || close(fd) != 0) {
    *err = tmp + ": fsync/close failed: " + std::strerror(errno);
    unlink(tmp.c_str());
    return false;
  }
  if (rename(tmp.c_str(), path.c_str()) != 0) {
    *err = path + ": rename failed: " + std::strerror(errno);
    unlink(tmp.c_str());
    return false;
  }
  return true;
}

std::string DataDir() {
  const char* d = getenv("ARFLEX_DATA_DIR");
  if (d && *d) return d;
  // Absolute, so that messages name the file unambiguously.
  char cwd[4096];
  if (getcwd(cwd, sizeof(cwd))) return std::string(cwd) + "/data";
  return "data";
}

std::string ProgramPath(const std::string& dir, long n) {
  return dir + "/program-" + std::to_string(n) + ".arp";
}

}  // namespace cellkin
}  // namespace arflex
