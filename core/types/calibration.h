#pragma once

#include <string>

#include "core/types/transform.h"

namespace stcalib {

// The quantity stcalib estimates (docs/method.md §1–2).
struct CalibrationState {
  // Te = T_C<-L: LiDAR frame to unrectified camera 0, as R/T of calib_velo_to_cam.txt.
  Rigid3d T_camera_lidar = Rigid3d::Identity();
  // δ: a LiDAR frame stamped t_l was captured at t_l + δ on the camera clock [s].
  double time_offset_s = 0.0;
};

// Error of an estimate against a reference (truth or KITTI's calibration).
struct CalibrationError {
  double rotation_deg = 0.0;  ///< angle of R_est · R_refᵀ [deg]
  // Per-axis rotation error in the LiDAR frame: the rotation vector of R_refᵀ · R_est, i.e. the
  // small rotation applied on the LiDAR side (x forward = roll, y left = pitch, z up = yaw).
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double yaw_deg = 0.0;
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();  ///< t_est − t_ref [m]
  double translation_norm_m = 0.0;                          ///< |t_est − t_ref| [m]
  double time_offset_s = 0.0;                               ///< δ_est − δ_ref [s]
};

// Angle of R_a · R_bᵀ in degrees.
double RotationErrorDeg(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b);

CalibrationError ComputeCalibrationError(const CalibrationState& estimate,
                                         const CalibrationState& reference);

// Applies a rotation perturbation given as roll/pitch/yaw about the LiDAR axes [deg] (the same
// convention as CalibrationError) and a translation offset [m] to T_camera_lidar.
Rigid3d PerturbTcameraLidar(const Rigid3d& T_camera_lidar, const Eigen::Vector3d& rpy_lidar_deg,
                            const Eigen::Vector3d& translation_offset_m);

// The nominal mount of a forward-looking camera: the LiDAR's x forward, y left, z up become the
// camera's z (forward), −x (x right), −y (y down).
Eigen::Matrix3d NominalRcameraLidar();

// The LiDAR's mount angles relative to the camera [deg], (roll, pitch, yaw) about the LiDAR's
// axes (x forward, y left, z up): R_camera_lidar = NominalRcameraLidar() · Rz(yaw) · Ry(pitch) ·
// Rx(roll). For a forward-looking camera these are small, well-conditioned angles
// (Euler angles of R_camera_lidar itself sit at gimbal lock, pitch ≈ −90°).
Eigen::Vector3d MountRollPitchYawDeg(const Eigen::Matrix3d& R_camera_lidar);

std::string ToString(const CalibrationError& error);

}  // namespace stcalib
