#pragma once

#include <array>
#include <string>

#include "core/refine/refine.h"
#include "core/types/calibration.h"
#include "core/types/transform.h"

namespace stcalib {

// One camera of a rig as a calibration run left it (docs/method.md §7, "Several cameras").
struct RigCamera {
  std::string name;                              ///< e.g. "image_03"
  bool claimed = false;                          ///< a whole or partial claim
  Rigid3d T_camera_lidar = Rigid3d::Identity();  ///< the estimate, in the camera's own frame
  // The camera's rectified optical frame from its frame (RectifiedFromCamera), and its frame from
  // the rig's reference frame (CameraCalibration::T_camera_reference): the rig's own geometry.
  Rigid3d T_rectified_camera = Rigid3d::Identity();
  Rigid3d T_camera_reference = Rigid3d::Identity();
  // Reported std per axis (roll, pitch, yaw [deg], x, y, z [m], δ [s]); has_std false: none.
  std::array<double, kNumAxes> std_dev{};
  std::array<bool, kNumAxes> has_std{};
};

// The transform from camera `from`'s rectified optical frame to camera `to`'s, as the two
// estimates imply it (T_to_lidar · T_from_lidar⁻¹) and as the rig's own calibration gives it,
// and how far they disagree.
struct CameraPairCheck {
  std::string from, to;
  bool compared = false;  ///< both cameras claimed
  Rigid3d T_to_from_estimated = Rigid3d::Identity(), T_to_from_rig = Rigid3d::Identity();
  double rotation_deg = 0;   ///< angle of the rotation between the two [deg]
  double translation_m = 0;  ///< |t_estimated − t_rig| [m]
  double baseline_m = 0;     ///< |t_estimated| − |t_rig|: the baseline's length error [m]
  // The disagreement the two estimates' reported std predict for independent errors: the root of
  // the sum of both cameras' rotation (translation) variances; 0 when either has none.
  double rotation_std_deg = 0, translation_std_m = 0;
};

// Compares the pair; `compared` false (and only the rig's transform set) unless both claimed.
CameraPairCheck CompareCameraPair(const RigCamera& from, const RigCamera& to);

}  // namespace stcalib
