// MJCF generation: the TRUE and NOMINAL models of the cell come from one CellConfig.
#ifndef ARFLEX_SIM_MJCF_H_
#define ARFLEX_SIM_MJCF_H_

#include <mujoco/mujoco.h>

#include <string>

#include "arflex_sim/params.h"

namespace arflex {
namespace sim {

enum class ModelKind {
  // What moves: geometry errors of the seeded error set, joint offset errors, series
  // compliance (passive hinges "j2c", "j3c", "j5c"), the scene (floor, cameras, tags,
  // obstacle, lights), sensors.
  kTrue,
  // What the controller knows: the ideal geometry, rigid joints, the nominal payload, no
  // scene. Joint names "j1".."j6", sites "flange" and "tcp".
  kNominal,
};

// Returns the MJCF text of the cell for `kind`. Deterministic: the same config gives the
// same text.
std::string GenerateMjcf(const CellConfig& config, ModelKind kind);

// Compiles MJCF text (through a private virtual file system, nothing touches the disk).
// Returns the model, owned by the caller (free with mj_deleteModel), or nullptr with
// `*error` naming `name` and MuJoCo's message.
mjModel* LoadMjcf(const std::string& xml, const std::string& name, std::string* error);

// Camera frame axes (MuJoCo convention: the camera looks along its -z, +y is up in the
// image) for a camera at `pos` looking at `look_at` with `up` as the up hint.
void CameraAxes(const CameraSpec& camera, double x_axis[3], double y_axis[3], double z_axis[3]);

// Names used in the generated models.
inline constexpr const char* kJointNames[kNumJoints] = {"j1", "j2", "j3", "j4", "j5", "j6"};
inline constexpr const char* kComplianceJointNames[kNumJoints] = {"j1c", "j2c", "j3c",
                                                                  "j4c", "j5c", "j6c"};

}  // namespace sim
}  // namespace arflex

#endif  // ARFLEX_SIM_MJCF_H_
