#include "arflex_sim/mjcf.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace arflex {
namespace sim {
namespace {

// Writes numbers with full precision so that generated models round-trip exactly.
class Xml {
 public:
  Xml() { out_.precision(17); }
  Xml& operator<<(const std::string& s) {
    out_ << s;
    return *this;
  }
  Xml& operator<<(const char* s) {
    out_ << s;
    return *this;
  }
  Xml& operator<<(double v) {
    out_ << v;
    return *this;
  }
  Xml& operator<<(char c) {
    out_ << c;
    return *this;
  }
  Xml& operator<<(int v) {
    out_ << v;
    return *this;
  }
  Xml& operator<<(const Vec3& v) {
    out_ << v[0] << ' ' << v[1] << ' ' << v[2];
    return *this;
  }
  std::string str() const { return out_.str(); }

 private:
  std::ostringstream out_;
};

void Normalize(double v[3]) {
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (n < 1e-12) throw std::invalid_argument("zero-length vector in camera specification");
  for (int i = 0; i < 3; ++i) v[i] /= n;
}

void Cross(const double a[3], const double b[3], double out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

// Quaternion (w x y z) of a rotation by `angle` about unit `axis`.
std::array<double, 4> AxisAngleQuat(const Vec3& axis, double angle) {
  const double s = std::sin(0.5 * angle);
  return {std::cos(0.5 * angle), axis[0] * s, axis[1] * s, axis[2] * s};
}

void WriteTagGeom(Xml& x, const TagSpec& tag) {
  const double half = 0.5 * tag.size * 10.0 / 8.0;  // white quiet zone included
  x << "<geom name=\"tag" << tag.id << "\" type=\"box\" size=\"" << half << ' ' << half
    << " 0.0005\" pos=\"" << tag.pos << "\" quat=\"" << tag.quat[0] << ' ' << tag.quat[1]
    << ' ' << tag.quat[2] << ' ' << tag.quat[3] << "\" material=\"tag" << tag.id
    << "\" contype=\"0\" conaffinity=\"0\" group=\"1\" mass=\"0\"/>\n";
}

void WriteTagsOn(Xml& x, const CellConfig& config, const std::string& body) {
  for (const TagSpec& tag : config.tags) {
    if (tag.body == body) WriteTagGeom(x, tag);
  }
}

}  // namespace

void CameraAxes(const CameraSpec& camera, double x_axis[3], double y_axis[3],
                double z_axis[3]) {
  for (int i = 0; i < 3; ++i) z_axis[i] = camera.pos[i] - camera.look_at[i];
  Normalize(z_axis);
  const double up[3] = {camera.up[0], camera.up[1], camera.up[2]};
  Cross(up, z_axis, x_axis);
  Normalize(x_axis);
  Cross(z_axis, x_axis, y_axis);
}

std::string GenerateMjcf(const CellConfig& config, ModelKind kind) {
  const bool is_true = kind == ModelKind::kTrue;
  for (const TagSpec& tag : config.tags) {
    if (tag.id < 0 || tag.id >= 587) {
      throw std::invalid_argument("tag id " + std::to_string(tag.id) +
                                  " outside tag36h11 (0..586)");
    }
    bool known = tag.body == "world";
    for (const LinkParams& l : config.arm.links) known = known || tag.body == l.name;
    if (!known) throw std::invalid_argument("tag " + std::to_string(tag.id) +
                                            " on unknown body '" + tag.body + "'");
  }
  const ErrorSet errors = DrawErrorSet(config.error_seed, config.error_model);
  const ArmParams arm = is_true ? ApplyGeometryErrors(config.arm, errors) : config.arm;

  Xml x;
  x << "<mujoco model=\"arflex_cell_" << (is_true ? "true" : "nominal") << "\">\n";
  x << "<compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n";
  x << "<option timestep=\"" << config.timestep
    << "\" integrator=\"Euler\" gravity=\"0 0 -9.81\"/>\n";
  if (is_true) {
    x << "<visual><global offwidth=\"" << config.max_render_width << "\" offheight=\""
      << config.max_render_height << "\"/><quality shadowsize=\"2048\"/>"
      << "<headlight ambient=\"0.35 0.35 0.35\" diffuse=\"0.4 0.4 0.4\" specular=\"0 0 0\"/>"
      << "</visual>\n";
    x << "<asset>\n";
    x << "<texture name=\"floor\" type=\"2d\" builtin=\"checker\" width=\"256\" height=\"256\""
      << " rgb1=\"0.42 0.42 0.44\" rgb2=\"0.36 0.36 0.38\"/>\n";
    x << "<material name=\"floor\" texture=\"floor\" texrepeat=\"8 8\" reflectance=\"0\""
      << " specular=\"0\"/>\n";
    for (const TagSpec& tag : config.tags) {
      // Placeholder pixels; Cell replaces them with the tag36h11 pattern after loading.
      x << "<texture name=\"tag" << tag.id << "\" type=\"2d\" builtin=\"flat\" width=\"120\""
        << " height=\"120\" rgb1=\"1 1 1\"/>\n";
      x << "<material name=\"tag" << tag.id << "\" texture=\"tag" << tag.id
        << "\" specular=\"0\" shininess=\"0\" reflectance=\"0\" emission=\"0.2\"/>\n";
    }
    x << "</asset>\n";
  }
  x << "<default><joint limited=\"true\"/><geom contype=\"1\" conaffinity=\"0\"/>"
       "</default>\n";
  x << "<worldbody>\n";
  if (is_true) {
    x << "<light name=\"key\" pos=\"1.8 0 6\" dir=\"0 0 -1\" diffuse=\"0.5 0.5 0.5\""
         " specular=\"0 0 0\" castshadow=\"false\"/>\n";
    x << "<geom name=\"floor\" type=\"plane\" size=\"6 6 0.1\" material=\"floor\""
         " contype=\"0\" conaffinity=\"0\"/>\n";
    x << "<geom name=\"pedestal\" type=\"cylinder\" size=\"0.35 " << 0.5 * arm.base_height
      << "\" pos=\"0 0 " << 0.5 * arm.base_height
      << "\" rgba=\"0.2 0.2 0.2 1\" contype=\"0\" conaffinity=\"0\"/>\n";
    for (const CameraSpec& cam : config.cameras) {
      double cx[3], cy[3], cz[3];
      CameraAxes(cam, cx, cy, cz);
      x << "<camera name=\"" << cam.name << "\" pos=\"" << cam.pos << "\" xyaxes=\""
        << Vec3{cx[0], cx[1], cx[2]} << ' ' << Vec3{cy[0], cy[1], cy[2]} << "\" fovy=\""
        << cam.fovy_deg << "\"/>\n";
    }
    WriteTagsOn(x, config, "world");
  }
  for (int i = 0; i < kNumJoints; ++i) {
    const LinkParams& l = arm.links[i];
    x << "<body name=\"" << l.name << "\" pos=\"" << l.offset << "\"";
    if (is_true && errors.joint_offset[i] != 0.0) {
      const auto q = AxisAngleQuat(l.axis, errors.joint_offset[i]);
      x << " quat=\"" << q[0] << ' ' << q[1] << ' ' << q[2] << ' ' << q[3] << "\"";
    }
    x << ">\n";
    x << "<inertial pos=\"" << l.com << "\" mass=\"" << l.mass << "\" diaginertia=\""
      << l.inertia << "\"/>\n";
    x << "<joint name=\"" << kJointNames[i] << "\" type=\"hinge\" axis=\"" << l.axis
      << "\" range=\"" << l.lower << ' ' << l.upper << "\" armature=\"" << l.armature
      << "\" damping=\"" << l.damping + config.gains.kd[i] << "\"/>\n";
    if (is_true && config.compliance && l.stiffness > 0.0) {
      x << "<joint name=\"" << kComplianceJointNames[i] << "\" type=\"hinge\" axis=\""
        << l.axis << "\" limited=\"false\" stiffness=\"" << l.stiffness << "\" damping=\""
        << l.compliance_damping << "\"/>\n";
    }
    x << "<geom name=\"" << l.name << "_geom\" type=\"capsule\" fromto=\"" << l.geom_from
      << ' ' << l.geom_to << "\" size=\"" << l.geom_radius << "\" rgba=\"0.95 0.55 0.1 1\"/>\n";
    if (is_true) WriteTagsOn(x, config, l.name);
  }
  // Flange: the tool is a welded child body; its origin is the F/T sensor's mount.
  x << "<site name=\"flange\" pos=\"0 0 0\" size=\"0.01\"/>\n";
  x << "<body name=\"tool\" pos=\"0 0 0\">\n";
  x << "<inertial pos=\"" << arm.tool_com << "\" mass=\"" << arm.tool_mass
    << "\" diaginertia=\"0.12 0.15 0.15\"/>\n";
  x << "<site name=\"ft\" pos=\"0 0 0\" size=\"0.01\"/>\n";
  x << "<site name=\"tcp\" pos=\"" << arm.tcp_offset << "\" size=\"0.01\"/>\n";
  x << "<geom name=\"tool_block\" type=\"box\" size=\"0.1 0.09 0.09\" pos=\"0.13 0 0\""
       " rgba=\"0.25 0.25 0.28 1\"/>\n";
  x << "<geom name=\"tool_tip\" type=\"capsule\" fromto=\"0.23 0 0 " << arm.tcp_offset[0] - 0.015
    << ' ' << arm.tcp_offset[1] << ' ' << arm.tcp_offset[2]
    << "\" size=\"0.015\" rgba=\"0.7 0.7 0.7 1\"/>\n";
  const double payload = is_true ? config.payload_mass : config.nominal_payload_mass;
  x << "<body name=\"payload\" pos=\"" << arm.payload_com << "\">\n";
  // A small sphere-like inertia so that a payload can be set at run time (Cell rescales
  // body_mass and body_inertia).
  const double pm = payload > 0.0 ? payload : 0.0;
  x << "<inertial pos=\"0 0 0\" mass=\"" << pm << "\" diaginertia=\"" << 0.4 * pm * 0.01
    << ' ' << 0.4 * pm * 0.01 << ' ' << 0.4 * pm * 0.01 << "\"/>\n";
  x << "</body>\n";
  x << "</body>\n";
  for (int i = 0; i < kNumJoints; ++i) x << "</body>\n";
  if (is_true) {
    const ObstacleSpec& ob = config.obstacle;
    const Vec3 pos = ob.enabled ? ob.pos : Vec3{0.0, 0.0, -50.0};
    x << "<body name=\"obstacle\" mocap=\"true\" pos=\"" << pos << "\">\n";
    x << "<geom name=\"obstacle\" type=\"box\" size=\"" << ob.half_size
      << "\" contype=\"0\" conaffinity=\"1\" rgba=\"0.2 0.5 0.9 1\"/>\n";
    x << "</body>\n";
  }
  x << "</worldbody>\n";
  x << "<actuator>\n";
  for (int i = 0; i < kNumJoints; ++i) {
    const LinkParams& l = arm.links[i];
    x << "<motor name=\"m" << i + 1 << "\" joint=\"" << kJointNames[i]
      << "\" ctrllimited=\"true\" ctrlrange=\"" << -l.max_torque << ' ' << l.max_torque
      << "\"/>\n";
  }
  x << "</actuator>\n";
  if (is_true) {
    x << "<sensor>\n<force name=\"ft_force\" site=\"ft\"/>\n<torque name=\"ft_torque\""
         " site=\"ft\"/>\n";
    for (int i = 0; i < kNumJoints; ++i) {
      x << "<actuatorfrc name=\"tau" << i + 1 << "\" actuator=\"m" << i + 1 << "\"/>\n";
    }
    x << "</sensor>\n";
  }
  x << "</mujoco>\n";
  return x.str();
}

}  // namespace sim
}  // namespace arflex
