// Pivot calibration of a tool: the tool-centre point (TCP) in the marker frame from marker
// poses measured while the tool tip rests in one fixed point (a divot) at several
// orientations. Each pose i (world_from_marker = (R_i, p_i)) puts the tip at
// R_i t + p_i = c, with t the tip in the marker frame and c the pivot point in the world:
//
//     [ R_i  -I ] [ t ; c ] = -p_i        (3 rows per pose, 6 unknowns)
//
// solved by linear least squares over all poses. Only the measured poses enter the solve.
//
// Conditioning: the component of t along an axis about which every pose is turned the same
// way cannot be seen (turning about an axis through the tip moves nothing). The solver
// measures the rotation spread: the smallest singular value of the stacked, mean-removed
// rotation matrices divided by sqrt(N) (for small angles, the RMS angle of the rotations
// about the weakest axis, in rad) and refuses a set below `min_spread_deg`, naming that axis.
//
// Allocation: Solve allocates (dynamic Eigen matrices, strings): not for an RT thread.
#ifndef ARFLEX_VISION_CALIB_PIVOT_H_
#define ARFLEX_VISION_CALIB_PIVOT_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace arflex {
namespace vision {
namespace calib {

struct PivotOptions {
  int min_poses = 6;             // fewer poses: refused
  double min_spread_deg = 5.0;   // smaller rotation spread about the weakest axis: refused
  // A pose whose tip residual exceeds this is reported as the reason of a refusal (the tip
  // slipped, a pose was measured wrong): the set is refused, not silently re-weighted.
  double max_residual_m = 0.5e-3;
};

struct PivotResult {
  bool ok = false;
  std::string reason = "not solved";  // why it was refused; "ok" when ok
  Eigen::Vector3d tip_in_marker = Eigen::Vector3d::Zero();  // t (m)
  Eigen::Vector3d pivot_in_world = Eigen::Vector3d::Zero();  // c (m)
  std::vector<double> residual_m;   // |R_i t + p_i - c| per pose (m)
  double rms_m = 0.0;               // sqrt(mean residual^2) (m)
  double max_residual_m = 0.0;
  int worst_pose = -1;
  // 1-sigma uncertainty of t per axis of the marker frame from the residual scatter
  // (s^2 (A^T A)^-1, s^2 = sum r^2 / (3N - 6)); zero with an exact fit.
  Eigen::Vector3d tip_sigma_m = Eigen::Vector3d::Zero();
  double spread_deg = 0.0;          // rotation spread about the weakest axis
  Eigen::Vector3d weakest_axis = Eigen::Vector3d::UnitZ();  // in the marker frame
  int poses = 0;
};

// Solves the pivot calibration from `world_from_marker` (the measured marker poses). Never
// throws; a refused set gives ok = false with the reason (which pose, which axis, which
// limit). The residuals and spread are filled whenever the solve itself ran.
// `weights` (may be null: all 1) weighs each pose's three equations: 1 / sigma_i^2 of that
// pose's tip position, e.g. from the pose estimate's reprojection residual. Each must be
// finite and > 0; the reported sigma of the tip is then that of the weighted fit (scaled by
// its weighted residual), the residuals stay in metres.
PivotResult SolvePivot(const std::vector<Eigen::Isometry3d>& world_from_marker,
                       const PivotOptions& options = PivotOptions(),
                       const std::vector<double>* weights = nullptr);

}  // namespace calib
}  // namespace vision
}  // namespace arflex

#endif  // ARFLEX_VISION_CALIB_PIVOT_H_
