// The generated models load, agree with the checked-in copies, and carry the documented
// error set; bad configurations are refused with a message naming the problem.
#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "arflex_sim/cell.h"
#include "arflex_sim/mjcf.h"
#include "arflex_sim/tags.h"

namespace arflex {
namespace sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(ModelTest, TrueAndNominalModelsLoad) {
  std::string error;
  auto cell = Cell::Create(DefaultCellConfig(), JointVector{}, &error);
  ASSERT_NE(cell, nullptr) << error;
  const mjModel* m = cell->model();
  // Six motor joints plus the passive compliance joints in series with joints 2, 3 and 5.
  EXPECT_EQ(m->nq, 9);
  EXPECT_EQ(m->nu, 6);
  EXPECT_EQ(m->ncam, 4);
  EXPECT_GE(mj_name2id(m, mjOBJ_JOINT, "j2c"), 0);
  EXPECT_GE(mj_name2id(m, mjOBJ_JOINT, "j3c"), 0);
  EXPECT_GE(mj_name2id(m, mjOBJ_JOINT, "j5c"), 0);
  EXPECT_LT(mj_name2id(m, mjOBJ_JOINT, "j1c"), 0);
  EXPECT_DOUBLE_EQ(m->opt.timestep, 0.001);
  EXPECT_EQ(cell->compliance_qpos(0), -1);
  EXPECT_GE(cell->compliance_qpos(1), 0);

  const std::string nominal_xml = GenerateMjcf(DefaultCellConfig(), ModelKind::kNominal);
  mjModel* nominal = LoadMjcf(nominal_xml, "nominal", &error);
  ASSERT_NE(nominal, nullptr) << error;
  EXPECT_EQ(nominal->nq, 6);
  EXPECT_EQ(nominal->ncam, 0);
  mj_deleteModel(nominal);
}

TEST(ModelTest, ArmIsInTheHeavyPayloadClass) {
  const ArmParams arm = DefaultArm();
  double mass = arm.tool_mass;
  for (const LinkParams& l : arm.links) mass += l.mass;
  EXPECT_GT(mass, 600.0);
  EXPECT_LT(mass, 1200.0);
  // Wrist-centre reach with the arm stretched forward: shoulder offset + upper arm + forearm.
  const double reach = arm.links[1].offset[0] + arm.links[2].offset[2] +
                       arm.links[3].offset[0] + arm.links[4].offset[0];
  EXPECT_NEAR(reach, 2.70, 0.01);
}

TEST(ModelTest, GenerationIsDeterministicAndSeeded) {
  CellConfig a = DefaultCellConfig();
  CellConfig b = DefaultCellConfig();
  EXPECT_EQ(GenerateMjcf(a, ModelKind::kTrue), GenerateMjcf(b, ModelKind::kTrue));
  b.error_seed = 2;
  EXPECT_NE(GenerateMjcf(a, ModelKind::kTrue), GenerateMjcf(b, ModelKind::kTrue));
  // The nominal model does not depend on the error seed.
  EXPECT_EQ(GenerateMjcf(a, ModelKind::kNominal), GenerateMjcf(b, ModelKind::kNominal));
}

std::string ReadWithoutFirstLine(const std::string& path) {
  std::ifstream in(path);
  std::string first;
  std::getline(in, first);
  std::stringstream rest;
  rest << in.rdbuf();
  return rest.str();
}

TEST(ModelTest, CheckedInModelsMatchTheGenerator) {
  // simulator/models/ holds the output of arflex-sim-mjcf for the default cell, for reading
  // and for other tools. Regenerate with: arflex-sim-mjcf simulator/models
  const CellConfig config = DefaultCellConfig();
  EXPECT_EQ(ReadWithoutFirstLine(std::string(ARFLEX_SIM_MODELS_DIR) + "/cell_true.xml"),
            GenerateMjcf(config, ModelKind::kTrue));
  EXPECT_EQ(ReadWithoutFirstLine(std::string(ARFLEX_SIM_MODELS_DIR) + "/cell_nominal.xml"),
            GenerateMjcf(config, ModelKind::kNominal));
}

TEST(ModelTest, ErrorSetStaysWithinTheDocumentedBounds) {
  const ErrorModel model;
  for (uint64_t seed = 1; seed <= 50; ++seed) {
    const ErrorSet e = DrawErrorSet(seed, model);
    for (const Vec3& v : e.offset_error) {
      for (double c : v) EXPECT_LE(std::fabs(c), model.clip_sigma * model.length_sigma);
    }
    for (double q : e.joint_offset) EXPECT_LT(std::fabs(q), 0.1 * kDeg);
  }
  // The documented default set (simulator/README.md), to catch a silent generator change.
  const ErrorSet e = DrawErrorSet(1, model);
  EXPECT_NEAR(e.offset_error[1][2], -0.372e-3, 0.0005e-3);
  EXPECT_NEAR(e.joint_offset[1], 0.0122 * kDeg, 0.00005 * kDeg);
  EXPECT_NEAR(e.joint_offset[4], 0.0209 * kDeg, 0.00005 * kDeg);
}

TEST(ModelTest, RefusesBadConfigurationsWithAClearMessage) {
  std::string error;
  CellConfig config = DefaultCellConfig();
  config.timestep = 0.0;
  EXPECT_EQ(Cell::Create(config, JointVector{}, &error), nullptr);
  EXPECT_NE(error.find("timestep"), std::string::npos) << error;

  config = DefaultCellConfig();
  config.tags.push_back({999, 0.1, "world", {0, 0, 0}});
  EXPECT_EQ(Cell::Create(config, JointVector{}, &error), nullptr);
  EXPECT_NE(error.find("tag id 999"), std::string::npos) << error;

  config = DefaultCellConfig();
  config.tags.push_back({5, 0.1, "elbow", {0, 0, 0}});
  EXPECT_EQ(Cell::Create(config, JointVector{}, &error), nullptr);
  EXPECT_NE(error.find("unknown body 'elbow'"), std::string::npos) << error;

  JointVector q{};
  q[1] = 2.0;  // beyond joint 2's upper limit (80 deg)
  EXPECT_EQ(Cell::Create(DefaultCellConfig(), q, &error), nullptr);
  EXPECT_NE(error.find("joint 2"), std::string::npos) << error;

  EXPECT_EQ(LoadMjcf("<mujoco><worldbody><bogus/></worldbody></mujoco>", "bad", &error),
            nullptr);
  EXPECT_NE(error.find("bad.xml"), std::string::npos) << error;
}

TEST(ModelTest, TagImagesMatchLibapriltagRendering) {
  apriltag_family_t* family = tag36h11_create();
  for (int id : {0, 1, 13, 586}) {
    std::vector<uint8_t> ours;
    ASSERT_TRUE(Tag36h11Image(id, 1, &ours));
    image_u8_t* ref = apriltag_to_image(family, id);
    ASSERT_EQ(ref->width, Tag36h11TotalModules());
    for (int y = 0; y < ref->height; ++y) {
      for (int x = 0; x < ref->width; ++x) {
        EXPECT_EQ(ours[y * ref->width + x], ref->buf[y * ref->stride + x])
            << "tag " << id << " module " << x << "," << y;
      }
    }
    image_u8_destroy(ref);
  }
  tag36h11_destroy(family);
  std::vector<uint8_t> image;
  EXPECT_FALSE(Tag36h11Image(587, 4, &image));
  EXPECT_FALSE(Tag36h11Image(3, 0, &image));
}

}  // namespace
}  // namespace sim
}  // namespace arflex
