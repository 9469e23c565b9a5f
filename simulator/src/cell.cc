#include "arflex_sim/cell.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "arflex_sim/mjcf.h"
#include "arflex_sim/tags.h"

namespace arflex {
namespace sim {

mjModel* LoadMjcf(const std::string& xml, const std::string& name, std::string* error) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const std::string file = name + ".xml";
  if (mj_makeEmptyFileVFS(vfs.get(), file.c_str(), static_cast<int>(xml.size())) != 0) {
    *error = "cannot create virtual file for model " + file;
    return nullptr;
  }
  const int index = mj_findFileVFS(vfs.get(), file.c_str());
  std::memcpy(vfs->filedata[index], xml.data(), xml.size());
  char buffer[1024] = {0};
  mjModel* model = mj_loadXML(file.c_str(), vfs.get(), buffer, sizeof(buffer));
  mj_deleteVFS(vfs.get());
  if (!model) *error = std::string("MuJoCo rejected generated model ") + file + ": " + buffer;
  return model;
}

namespace {

int FindId(const mjModel* m, mjtObj type, const std::string& name, std::string* error) {
  const int id = mj_name2id(m, type, name.c_str());
  if (id < 0 && error->empty()) *error = "generated model lacks '" + name + "'";
  return id;
}

void SetPayloadInertia(mjModel* m, int body, double mass) {
  m->body_mass[body] = mass;
  const double i = 0.4 * mass * 0.01;  // solid sphere of radius 0.1 m
  for (int k = 0; k < 3; ++k) m->body_inertia[3 * body + k] = i;
}

}  // namespace

Cell::Cell(const CellConfig& config)
    : config_(config),
      errors_(DrawErrorSet(config.error_seed, config.error_model)),
      kinematics_(config.arm) {}

Cell::~Cell() {
  if (data_) mj_deleteData(data_);
  if (model_) mj_deleteModel(model_);
  if (nominal_data_) mj_deleteData(nominal_data_);
  if (nominal_model_) mj_deleteModel(nominal_model_);
}

std::unique_ptr<Cell> Cell::Create(const CellConfig& config, const JointVector& initial_q,
                                   std::string* error) {
  error->clear();
  if (!(config.timestep > 0.0 && config.timestep <= 0.01)) {
    *error = "CellConfig.timestep must be in (0, 0.01] s, got " +
             std::to_string(config.timestep);
    return nullptr;
  }
  if (config.payload_mass < 0.0 || config.nominal_payload_mass < 0.0) {
    *error = "CellConfig payload masses must be >= 0";
    return nullptr;
  }
  std::unique_ptr<Cell> cell(new Cell(config));
  std::string true_xml, nominal_xml;
  try {
    true_xml = GenerateMjcf(config, ModelKind::kTrue);
    nominal_xml = GenerateMjcf(config, ModelKind::kNominal);
  } catch (const std::exception& e) {
    *error = std::string("invalid CellConfig: ") + e.what();
    return nullptr;
  }
  cell->model_ = LoadMjcf(true_xml, "arflex_cell_true", error);
  if (!cell->model_) return nullptr;
  cell->nominal_model_ = LoadMjcf(nominal_xml, "arflex_cell_nominal", error);
  if (!cell->nominal_model_) return nullptr;
  cell->data_ = mj_makeData(cell->model_);
  cell->nominal_data_ = mj_makeData(cell->nominal_model_);

  const mjModel* m = cell->model_;
  for (int i = 0; i < kNumJoints; ++i) {
    const int j = FindId(m, mjOBJ_JOINT, kJointNames[i], error);
    const int jn = FindId(cell->nominal_model_, mjOBJ_JOINT, kJointNames[i], error);
    if (j < 0 || jn < 0) return nullptr;
    if (cell->nominal_model_->jnt_qposadr[jn] != i) {
      *error = "nominal model joint order differs from j1..j6";
      return nullptr;
    }
    cell->motor_qadr_[i] = m->jnt_qposadr[j];
    cell->motor_dadr_[i] = m->jnt_dofadr[j];
    const int c = mj_name2id(m, mjOBJ_JOINT, kComplianceJointNames[i]);
    cell->compliance_qadr_[i] = c >= 0 ? m->jnt_qposadr[c] : -1;
    cell->compliance_dadr_[i] = c >= 0 ? m->jnt_dofadr[c] : -1;
  }
  cell->tcp_site_ = FindId(m, mjOBJ_SITE, "tcp", error);
  cell->tool_body_ = FindId(m, mjOBJ_BODY, "tool", error);
  cell->payload_body_ = FindId(m, mjOBJ_BODY, "payload", error);
  cell->nominal_payload_body_ = FindId(cell->nominal_model_, mjOBJ_BODY, "payload", error);
  const int obstacle_body = FindId(m, mjOBJ_BODY, "obstacle", error);
  cell->obstacle_geom_ = FindId(m, mjOBJ_GEOM, "obstacle", error);
  const int ft_force = FindId(m, mjOBJ_SENSOR, "ft_force", error);
  const int ft_torque = FindId(m, mjOBJ_SENSOR, "ft_torque", error);
  if (!error->empty()) return nullptr;
  cell->obstacle_mocap_ = m->body_mocapid[obstacle_body];
  cell->ft_force_adr_ = m->sensor_adr[ft_force];
  cell->ft_torque_adr_ = m->sensor_adr[ft_torque];

  // Tag textures: the tag36h11 pattern, replicated into RGB. MuJoCo's texture row 0 is the
  // bottom of the image as seen on a box face (OpenGL's t = 0), so rows are flipped.
  for (const TagSpec& tag : config.tags) {
    const std::string name = "tag" + std::to_string(tag.id);
    const int tex = FindId(m, mjOBJ_TEXTURE, name, error);
    if (tex < 0) return nullptr;
    const int width = m->tex_width[tex];
    const int height = m->tex_height[tex];
    std::vector<uint8_t> image;
    const int modules = Tag36h11TotalModules();
    if (width != height || width % modules != 0 ||
        !Tag36h11Image(tag.id, width / modules, &image)) {
      *error = "cannot make texture for tag " + std::to_string(tag.id);
      return nullptr;
    }
    uint8_t* rgb = cell->model_->tex_rgb + cell->model_->tex_adr[tex];
    for (int y = 0; y < height; ++y) {
      const uint8_t* row = &image[static_cast<size_t>(y) * width];
      for (int x = 0; x < width; ++x) {
        for (int k = 0; k < 3; ++k) rgb[3 * (y * width + x) + k] = row[x];
      }
    }
  }

  cell->pushes_ = config.pushes;
  cell->push_capacity_ = std::max<size_t>(config.pushes.size(), 8);
  cell->pushes_.reserve(cell->push_capacity_);
  cell->hand_ = config.hand;
  cell->payload_mass_ = config.payload_mass;
  for (int i = 0; i < kNumJoints; ++i) {
    const LinkParams& l = config.arm.links[i];
    if (initial_q[i] < l.lower || initial_q[i] > l.upper) {
      *error = "initial joint " + std::to_string(i + 1) + " angle outside its limits";
      return nullptr;
    }
  }
  cell->ResetTo(initial_q);
  return cell;
}

void Cell::SolveStaticCompliance() {
  // Fixed-point iteration k * qc = gravity torque carried by the spring; converges in a few
  // iterations because the deflections are tiny.
  mju_zero(data_->qvel, model_->nv);
  for (int iter = 0; iter < 20; ++iter) {
    mj_kinematics(model_, data_);
    mj_comPos(model_, data_);
    mj_comVel(model_, data_);
    mj_rne(model_, data_, 0, data_->qfrc_bias);
    double change = 0.0;
    for (int i = 0; i < kNumJoints; ++i) {
      if (compliance_qadr_[i] < 0) continue;
      const double k = config_.arm.links[i].stiffness;
      const double qc = -data_->qfrc_bias[compliance_dadr_[i]] / k;
      change = std::max(change, std::fabs(qc - data_->qpos[compliance_qadr_[i]]));
      data_->qpos[compliance_qadr_[i]] = qc;
    }
    if (change < 1e-14) break;
  }
}

void Cell::ResetTo(const JointVector& q) {
  mju_zero(data_->qvel, model_->nv);
  mju_zero(data_->qacc_warmstart, model_->nv);
  for (int i = 0; i < kNumJoints; ++i) data_->qpos[motor_qadr_[i]] = q[i];
  SolveStaticCompliance();
  braking_ = false;
  q_ref_ = q;
  correction_ = JointVector{};
  mj_forward(model_, data_);
}

JointVector Cell::NominalGravityTorque(const JointVector& q, double payload_mass) {
  mjModel* m = nominal_model_;
  mjData* d = nominal_data_;
  const double saved = m->body_mass[nominal_payload_body_];
  SetPayloadInertia(m, nominal_payload_body_, payload_mass);
  for (int i = 0; i < kNumJoints; ++i) d->qpos[i] = q[i];
  mju_zero(d->qvel, m->nv);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  mj_rne(m, d, 0, d->qfrc_bias);
  JointVector tau;
  for (int i = 0; i < kNumJoints; ++i) tau[i] = d->qfrc_bias[i];
  SetPayloadInertia(m, nominal_payload_body_, saved);
  return tau;
}

void Cell::Controller() {
  if (braking_) Brake();
  JointVector q;
  for (int i = 0; i < kNumJoints; ++i) q[i] = data_->qpos[motor_qadr_[i]];
  JointVector gravity{};
  if (config_.gravity_compensation) {
    gravity = NominalGravityTorque(q, nominal_model_->body_mass[nominal_payload_body_]);
  }
  // PD servo: the P term and the gravity feed-forward are applied here; the D term
  // (kd * -dq, reference velocity zero) is part of the joint damping in the model so that
  // MuJoCo integrates it implicitly (stable at 1 kHz with stiff gains).
  // Reduced power: the corrective term is saturated, the gravity feed-forward is not.
  for (int i = 0; i < kNumJoints; ++i) {
    const double target = q_ref_[i] + correction_[i];
    const double limit = (braking_ ? 1.0 : power_scale_) * config_.arm.links[i].max_torque;
    const double p_term = std::clamp(config_.gains.kp[i] * (target - q[i]), -limit, limit);
    data_->ctrl[i] = p_term + gravity[i];
  }
}

void Cell::Stop() {
  stop_t0_ = data_->time;
  stop_T_ = kStopTime;
  // The inertial torque of the deceleration on every joint, per unit of the profile's
  // acceleration: M v0, the full mass matrix at this pose (armature included), so a joint at
  // rest is not pushed by its neighbours' braking. Motor dofs only; no allocation.
  std::array<mjtNum, kMaxDofs> v{}, mv{};
  const bool coupled = model_->nv <= kMaxDofs;
  for (int i = 0; i < kNumJoints; ++i) v[motor_dadr_[i]] = data_->qvel[motor_dadr_[i]];
  if (coupled) mj_mulM(model_, data_, mv.data(), v.data());
  for (int i = 0; i < kNumJoints; ++i) {
    const int dof = motor_dadr_[i];
    const double kp = config_.gains.kp[i];
    const double inertia = data_->qM[model_->dof_Madr[dof]];
    stop_q0_[i] = data_->qpos[motor_qadr_[i]];
    stop_v0_[i] = data_->qvel[dof];
    stop_ff_c_[i] = model_->dof_damping[dof] * stop_v0_[i] / kp;
    stop_ff_j_[i] = (coupled ? mv[dof] : inertia * stop_v0_[i]) / kp;
    // The profile's peak deceleration is 1.5 v0 / T: within 80 % of the drive's torque.
    const double need = 1.5 * std::fabs(stop_v0_[i]) * inertia / (0.8 * config_.arm.links[i].max_torque);
    stop_T_ = std::max(stop_T_, need);
  }
  correction_ = JointVector{};
  braking_ = true;
}

JointVector Cell::StopTarget() const {
  JointVector q;
  for (int i = 0; i < kNumJoints; ++i) q[i] = stop_q0_[i] + 0.5 * stop_v0_[i] * stop_T_;  // profile's integral
  return q;
}

// One step of the stop: the profile's position, fed forward (see Stop).
void Cell::Brake() {
  const double u = std::min(1.0, (data_->time - stop_t0_) / stop_T_);
  const double pos = u - u * u * u + 0.5 * u * u * u * u;  // integral of 1 - 3u^2 + 2u^3
  const double vel = 1.0 - 3.0 * u * u + 2.0 * u * u * u;
  const double acc = (-6.0 * u + 6.0 * u * u) / stop_T_;
  for (int i = 0; i < kNumJoints; ++i) {
    const double v0 = stop_v0_[i];
    q_ref_[i] = stop_q0_[i] + v0 * stop_T_ * pos + stop_ff_c_[i] * vel + stop_ff_j_[i] * acc;
  }
  correction_ = JointVector{};
  if (u >= 1.0) braking_ = false;  // q_ref_ stays where the profile ended
}

void Cell::SetPowerScale(double fraction) {
  power_scale_ = std::isfinite(fraction) ? std::clamp(fraction, 0.0, 1.0) : 0.0;
}

void Cell::ApplyDisturbances() {
  double* xfrc = data_->xfrc_applied + 6 * tool_body_;
  mju_zero(xfrc, 6);
  Vec3 force{};
  const double t = data_->time;
  for (const PushSpec& p : pushes_) {
    if (t >= p.start && t < p.start + p.duration) {
      for (int k = 0; k < 3; ++k) force[k] += p.force[k];
    }
  }
  const double* tcp = data_->site_xpos + 3 * tcp_site_;
  if (hand_.enabled && t >= hand_.start && t < hand_.start + hand_.duration) {
    const double s = hand_.duration > 0.0 ? (t - hand_.start) / hand_.duration : 1.0;
    double vel[6];
    mj_objectVelocity(model_, data_, mjOBJ_SITE, tcp_site_, vel, 0);  // [angular, linear]
    double f[3];
    double norm2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double target = hand_.from[k] + s * (hand_.to[k] - hand_.from[k]);
      f[k] = hand_.stiffness * (target - tcp[k]) - hand_.damping * vel[3 + k];
      norm2 += f[k] * f[k];
    }
    const double norm = std::sqrt(norm2);
    const double scale = norm > hand_.max_force ? hand_.max_force / norm : 1.0;
    for (int k = 0; k < 3; ++k) force[k] += scale * f[k];
  }
  // xfrc_applied acts at the body's centre of mass: move the force to the TCP.
  const double* com = data_->xipos + 3 * tool_body_;
  const double arm[3] = {tcp[0] - com[0], tcp[1] - com[1], tcp[2] - com[2]};
  double torque[3];
  const double f3[3] = {force[0], force[1], force[2]};
  mju_cross(torque, arm, f3);
  for (int k = 0; k < 3; ++k) {
    xfrc[k] = force[k];
    xfrc[3 + k] = torque[k];
  }
  last_force_ = force;
}

void Cell::Step(int n) {
  for (int s = 0; s < n; ++s) {
    Controller();
    ApplyDisturbances();
    mj_step(model_, data_);
    ++steps_;
  }
}

JointState Cell::ReadJointState() const {
  JointState state;
  for (int i = 0; i < kNumJoints; ++i) {
    state.q[i] = data_->qpos[motor_qadr_[i]];
    state.dq[i] = data_->qvel[motor_dadr_[i]];
    state.tau[i] = data_->actuator_force[i] - config_.gains.kd[i] * state.dq[i];
  }
  return state;
}

Wrench Cell::ReadWrench() const {
  Wrench w;
  for (int k = 0; k < 3; ++k) {
    w.force[k] = data_->sensordata[ft_force_adr_ + k];
    w.torque[k] = data_->sensordata[ft_torque_adr_ + k];
  }
  return w;
}

Eigen::Isometry3d Cell::TrueTcp() const {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  const double* p = data_->site_xpos + 3 * tcp_site_;
  const double* r = data_->site_xmat + 9 * tcp_site_;
  t.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) t.linear()(a, b) = r[3 * a + b];
  }
  return t;
}

JointVector Cell::ComplianceDeflection() const {
  JointVector qc{};
  for (int i = 0; i < kNumJoints; ++i) {
    if (compliance_qadr_[i] >= 0) qc[i] = data_->qpos[compliance_qadr_[i]];
  }
  return qc;
}

void Cell::SetPayload(double mass, bool tell_controller) {
  if (!(mass >= 0.0)) {
    ++own_warnings_;
    return;
  }
  payload_mass_ = mass;
  SetPayloadInertia(model_, payload_body_, mass);
  if (tell_controller) SetPayloadInertia(nominal_model_, nominal_payload_body_, mass);
}

void Cell::SetObstacle(bool enabled, const Vec3& pos) {
  double* p = data_->mocap_pos + 3 * obstacle_mocap_;
  p[0] = enabled ? pos[0] : 0.0;
  p[1] = enabled ? pos[1] : 0.0;
  p[2] = enabled ? pos[2] : -50.0;
}

void Cell::SetPushes(const std::vector<PushSpec>& pushes) {
  pushes_.clear();
  for (const PushSpec& p : pushes) {
    if (pushes_.size() < push_capacity_) {
      pushes_.push_back(p);
    } else {
      ++own_warnings_;
    }
  }
}

int Cell::obstacle_contacts() const {
  int count = 0;
  for (int c = 0; c < data_->ncon; ++c) {
    if (data_->contact[c].geom1 == obstacle_geom_ || data_->contact[c].geom2 == obstacle_geom_) {
      ++count;
    }
  }
  return count;
}

int Cell::warning_count() const {
  int count = own_warnings_;
  for (int i = 0; i < mjNWARNING; ++i) count += data_->warning[i].number;
  return count;
}

}  // namespace sim
}  // namespace arflex
