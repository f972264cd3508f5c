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
  check.consistent = check.rotation_deg <= kRigRotationToleranceDeg + 3 * check.rotation_std_deg &&
                     check.translation_m <= kRigTranslationToleranceM + 3 * check.translation_std_m;
  return check;
}

CalibrationFrame InRigFrame(const CalibrationFrame& frame, const Rigid3d& T_camera_reference,
                            double time_offset_shift_s) {
  CalibrationFrame out = frame;
  // h = P₃ₓ₃·R_rect·(R·x + t) + p₄ = P₃ₓ₃·(R_rect·R)·x + (p₄ + P₃ₓ₃·R_rect·t).
  CameraModel& camera = out.camera;
  const Eigen::Matrix3d P = camera.P_rect.leftCols<3>();
  camera.P_rect.col(3) += P * camera.R_rect_00 * T_camera_reference.translation();
  camera.R_rect_00 = camera.R_rect_00 * T_camera_reference.linear();
  out.e0_s += time_offset_shift_s;
  return out;
}

RefineResult RefineRigJointly(const std::vector<RigCameraFrames>& cameras,
                              const CalibrationState& start, const RefineOptions& options) {
  std::vector<CalibrationFrame> frames;
  for (const RigCameraFrames& camera : cameras) {
    for (const auto& frame : camera.frames) {
      frames.push_back(InRigFrame(*frame, camera.T_camera_reference, camera.time_offset_shift_s));
    }
  }
  std::vector<const CalibrationFrame*> window;
  for (const CalibrationFrame& frame : frames) window.push_back(&frame);
  return Refine(window, start, start, start, options);
}

}  // namespace stcalib
