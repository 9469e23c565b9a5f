// test_cellmodel - CTest cellmodel.unit.*: the cell model without MuJoCo.
//   test_cellmodel <arm|fk|jacobian|layout>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>

#include "arflex_cellmodel/arm.h"
#include "arflex_cellmodel/kinematics.h"
#include "arflex_cellmodel/layout.h"

namespace cm = arflex::cellmodel;

static int failures;
#define CHECK(c, ...)                                              \
  do {                                                             \
    if (!(c)) {                                                    \
      fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #c); \
      fprintf(stderr, __VA_ARGS__);                                \
      fputc('\n', stderr);                                         \
      ++failures;                                                  \
      return;                                                      \
    }                                                              \
  } while (0)

static const cm::JointVector kPoses[] = {
    {0, 0, 0, 0, 0, 0},        {0.3, 0.2, 0.5, -0.4, 0.7, 0.1}, {0.1, 0.45, 0.35, 0.2, 0.7, 0.3},
    {-1.2, -0.5, 1.1, 2.0, -1.0, 3.0}, {0.2, 0.5, 0.3, 0.1, 0.8, -0.2}};

// The chain as simulator/README.md "The arm" documents it (KR 210 R2700 class).
static void TestArm() {
  const cm::ArmParams arm = cm::DefaultArm();
  const double offsets[6][3] = {{0, 0, 0}, {0.35, 0, 0.675}, {0, 0, 1.15},
                                {0.50, 0, 0.041}, {0.70, 0, 0}, {0.215, 0, 0}};
  const char* axes = "zyyxyx";
  const double masses[6] = {300, 180, 150, 60, 25, 5};
  for (int i = 0; i < cm::kNumJoints; ++i) {
    const cm::LinkParams& l = arm.links[i];
    for (int k = 0; k < 3; ++k) CHECK(l.offset[k] == offsets[i][k], "link %d offset", i + 1);
    CHECK(l.axis[axes[i] - 'x'] == 1.0, "link %d axis", i + 1);
    CHECK(l.mass == masses[i], "link %d mass %g", i + 1, l.mass);
    CHECK(l.lower < 0 && l.upper > 0, "link %d limits", i + 1);
  }
  CHECK(arm.tcp_offset[0] == 0.30 && arm.tcp_offset[1] == 0 && arm.tcp_offset[2] == 0, "tcp");
  CHECK(arm.tool_mass == 25.0, "tool mass %g", arm.tool_mass);
}

// Rotation about a principal axis.
static Eigen::Matrix3d Rot(char axis, double t) {
  const Eigen::Vector3d a = axis == 'x' ? Eigen::Vector3d::UnitX()
                          : axis == 'y' ? Eigen::Vector3d::UnitY()
                                        : Eigen::Vector3d::UnitZ();
  return Eigen::AngleAxisd(t, a).toRotationMatrix();
}

// The product of exponentials against the plain chain of rotations and offsets (the form the
// Java NominalArm and the script's summary use).
static void TestFk() {
  const cm::ArmParams arm = cm::DefaultArm();
  const cm::NominalKinematics kin(arm);
  const Eigen::Vector3d home = kin.Tcp(kPoses[0]).translation();
  CHECK((home - Eigen::Vector3d(2.065, 0, 1.866)).norm() < 1e-12, "home TCP %g %g %g", home.x(),
        home.y(), home.z());
  for (const cm::JointVector& q : kPoses) {
    Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int i = 0; i < cm::kNumJoints; ++i) {
      const cm::LinkParams& l = arm.links[i];
      p += r * Eigen::Vector3d(l.offset[0], l.offset[1], l.offset[2]);
      r = r * Rot(l.axis[0] != 0 ? 'x' : l.axis[1] != 0 ? 'y' : 'z', q[i]);
    }
    const Eigen::Isometry3d flange = kin.Flange(q);
    CHECK((flange.translation() - p).norm() < 1e-12, "flange position");
    CHECK((flange.linear() - r).cwiseAbs().maxCoeff() < 1e-12, "flange rotation");
    p += r * Eigen::Vector3d(arm.tcp_offset[0], arm.tcp_offset[1], arm.tcp_offset[2]);
    const Eigen::Isometry3d tcp = kin.Tcp(q);
    CHECK((tcp.translation() - p).norm() < 1e-12, "TCP position");
    CHECK((tcp.linear() - r).cwiseAbs().maxCoeff() < 1e-12, "TCP rotation");
  }
}

// The geometric Jacobian against central differences of the TCP pose.
static void TestJacobian() {
  const cm::NominalKinematics kin(cm::DefaultArm());
  for (const cm::JointVector& q : kPoses) {
    const cm::Jacobian6 j = kin.TcpJacobian(q);
    for (int k = 0; k < cm::kNumJoints; ++k) {
      const double h = 1e-6;
      cm::JointVector a = q, b = q;
      a[k] += h;
      b[k] -= h;
      const Eigen::Isometry3d ta = kin.Tcp(a), tb = kin.Tcp(b);
      const Eigen::Vector3d v = (ta.translation() - tb.translation()) / (2 * h);
      const Eigen::AngleAxisd d(ta.linear() * tb.linear().transpose());
      const Eigen::Vector3d w = d.axis() * d.angle() / (2 * h);
      CHECK((j.block<3, 1>(0, k) - v).norm() < 1e-6, "linear column %d", k);
      CHECK((j.block<3, 1>(3, k) - w).norm() < 1e-6, "angular column %d", k);
    }
  }
}

static void TestLayout() {
  const std::vector<cm::CameraSpec> cams = cm::DefaultCameras();
  CHECK(cams.size() == 4, "%zu cameras", cams.size());
  for (const cm::CameraSpec& c : cams) CHECK(c.fovy_deg == 50.0, "%s fovy", c.name.c_str());
  const std::vector<cm::TagSpec> tags = cm::DefaultTags();
  CHECK(tags.size() == 8, "%zu tags", tags.size());
  std::set<int> ids;
  for (const cm::TagSpec& t : tags) {
    ids.insert(t.id);
    const bool board = t.id < 10;
    CHECK(t.body == (board ? "world" : "link6"), "tag %d on %s", t.id, t.body.c_str());
    CHECK(t.size == (board ? 0.24 : 0.13), "tag %d size", t.id);
    double n = 0;
    for (double c : t.quat) n += c * c;
    CHECK(std::fabs(n - 1) < 1e-12, "tag %d quaternion not unit", t.id);
  }
  CHECK(ids == std::set<int>({0, 1, 2, 3, 10, 11, 12, 13}), "tag ids");
}

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: test_cellmodel <arm|fk|jacobian|layout>\n");
    return 2;
  }
  if (strcmp(argv[1], "arm") == 0) TestArm();
  else if (strcmp(argv[1], "fk") == 0) TestFk();
  else if (strcmp(argv[1], "jacobian") == 0) TestJacobian();
  else if (strcmp(argv[1], "layout") == 0) TestLayout();
  else {
    fprintf(stderr, "unknown case %s\n", argv[1]);
    return 2;
  }
  if (failures == 0) printf("ok %s\n", argv[1]);
  return failures == 0 ? 0 : 1;
}
