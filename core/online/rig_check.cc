#include "core/online/rig_check.h"

#include <cmath>

namespace stcalib {

namespace {

// √ of the summed variances of axes [begin, end) of both cameras; 0 when either lacks one.
double CombinedStd(const RigCamera& a, const RigCamera& b, int begin, int end) {
  double variance = 0;
  for (int k = begin; k < end; ++k) {
    if (!a.has_std[k] || !b.has_std[k]) return 0;
    variance += a.std_dev[k] * a.std_dev[k] + b.std_dev[k] * b.std_dev[k];
  }
  return std::sqrt(variance);
}

}  // namespace

CameraPairCheck CompareCameraPair(const RigCamera& from, const RigCamera& to) {
  CameraPairCheck check;
  check.from = from.name;
  check.to = to.name;
  // Rectified frame from the reference frame, for each camera: the rig's own geometry.
  const Rigid3d T_to_reference = to.T_rectified_camera * to.T_camera_reference;
  const Rigid3d T_from_reference = from.T_rectified_camera * from.T_camera_reference;
  check.T_to_from_rig = T_to_reference * T_from_reference.inverse();
  if (!from.claimed || !to.claimed) return check;
  check.compared = true;
  check.T_to_from_estimated = (to.T_rectified_camera * to.T_camera_lidar) *
                              (from.T_rectified_camera * from.T_camera_lidar).inverse();
  check.rotation_deg =
      RotationErrorDeg(check.T_to_from_estimated.linear(), check.T_to_from_rig.linear());
  const Eigen::Vector3d t_estimated = check.T_to_from_estimated.translation();
  const Eigen::Vector3d t_rig = check.T_to_from_rig.translation();
  check.translation_m = (t_estimated - t_rig).norm();
  check.baseline_m = t_estimated.norm() - t_rig.norm();
  check.rotation_std_deg = CombinedStd(from, to, 0, 3);
  check.translation_std_m = CombinedStd(from, to, 3, 6);
  return check;
}

}  // namespace stcalib
