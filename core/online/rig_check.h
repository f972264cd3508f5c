#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/refine/refine.h"
#include "core/score/calibration_frame.h"
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
  // The disagreement is within what the estimates allow: at most kRigRotationToleranceDeg +
  // 3 × rotation_std_deg, and kRigTranslationToleranceM + 3 × translation_std_m. False: one of
  // the two claims is wrong (or the rig moved).
  bool consistent = true;
};

// What a pair may disagree by beyond its estimates' spread: KITTI's own calibration is good to a
// few tenths of a degree and a few centimetres (docs/results.md#several-cameras).
inline constexpr double kRigRotationToleranceDeg = 0.3;    ///< [deg]
inline constexpr double kRigTranslationToleranceM = 0.05;  ///< [m]

// Compares the pair; `compared` false (and only the rig's transform set) unless both claimed.
CameraPairCheck CompareCameraPair(const RigCamera& from, const RigCamera& to);

// `frame` of a camera seen from the rig's reference frame (x_camera = T_camera_reference · x):
// its camera model carries the camera's rig transform (R_rect_00 · R and P's last column, the
// same projection), so a state T_reference_lidar projects its points as T_camera_reference ·
// T_reference_lidar does; and its stamp gap e0 grows by `time_offset_shift_s` (the camera's δ −
// the rig's), so that the rig's one δ is the reference's. Its maps are shared, not copied.
CalibrationFrame InRigFrame(const CalibrationFrame& frame, const Rigid3d& T_camera_reference,
                            double time_offset_shift_s);

// One camera's part in the rig's joint refinement.
struct RigCameraFrames {
  std::vector<std::shared_ptr<const CalibrationFrame>> frames;
  Rigid3d T_camera_reference = Rigid3d::Identity();
  double time_offset_shift_s = 0;  ///< its δ − the rig's δ, held [s]
};

// One LiDAR extrinsic for the rig (T_reference_lidar and the rig's δ), refined over every
// camera's frames in one problem with the rig's camera-to-camera transforms and δ differences
// imposed, from `start` (in the reference frame). docs/method.md §7, "Several cameras".
RefineResult RefineRigJointly(const std::vector<RigCameraFrames>& cameras,
                              const CalibrationState& start, const RefineOptions& options);

}  // namespace stcalib
