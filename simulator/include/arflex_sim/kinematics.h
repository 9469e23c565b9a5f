// The nominal arm's kinematics moved to the cell model (cellmodel/, docs/DECISIONS.md D24);
// the simulator keeps its old names for them.
#ifndef ARFLEX_SIM_KINEMATICS_H_
#define ARFLEX_SIM_KINEMATICS_H_

#include "arflex_cellmodel/kinematics.h"
#include "arflex_sim/params.h"

namespace arflex {
namespace sim {

using cellmodel::Jacobian6;
using cellmodel::NominalKinematics;

}  // namespace sim
}  // namespace arflex

#endif  // ARFLEX_SIM_KINEMATICS_H_
