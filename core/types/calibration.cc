#include "core/types/calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace stcalib {
namespace {
constexpr double kRadToDeg = 180.0 / M_PI;
}  // namespace

double RotationErrorDeg(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  return LogSO3(R_a * R_b.transpose()).norm() * kRadToDeg;
}

CalibrationError ComputeCalibrationError(const CalibrationState& estimate,
                                         const CalibrationState& reference) {
  CalibrationError error;
  const Eigen::Matrix3d& R_est = estimate.T_camera_lidar.linear();
  const Eigen::Matrix3d& R_ref = reference.T_camera_lidar.linear();
  error.rotation_deg = RotationErrorDeg(R_est, R_ref);
  const Eigen::Vector3d rpy = LogSO3(R_ref.transpose() * R_est) * kRadToDeg;
  error.roll_deg = rpy.x();
  error.pitch_deg = rpy.y();
  error.yaw_deg = rpy.z();
  error.translation_m =
      estimate.T_camera_lidar.translation() - reference.T_camera_lidar.translation();
  error.translation_norm_m = error.translation_m.norm();
  error.time_offset_s = estimate.time_offset_s - reference.time_offset_s;
  return error;
}

Rigid3d PerturbTcameraLidar(const Rigid3d& T_camera_lidar, const Eigen::Vector3d& rpy_lidar_deg,
                            const Eigen::Vector3d& translation_offset_m) {
  Rigid3d T = T_camera_lidar;
  T.linear() = T_camera_lidar.linear() * ExpSO3(rpy_lidar_deg / kRadToDeg);
  T.translation() += translation_offset_m;
  return T;
}

Eigen::Matrix3d NominalRcameraLidar() {
  Eigen::Matrix3d R;
  R << 0, -1, 0,  //
      0, 0, -1,   //
      1, 0, 0;
  return R;
}

Eigen::Vector3d MountRollPitchYawDeg(const Eigen::Matrix3d& R_camera_lidar) {
  // R_nominal_lidar = Rz(yaw)·Ry(pitch)·Rx(roll): the LiDAR's axes in the nominal frame.
  const Eigen::Matrix3d R = NominalRcameraLidar().transpose() * R_camera_lidar;
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return Eigen::Vector3d(roll, pitch, yaw) * kRadToDeg;
}

std::string ToString(const CalibrationError& error) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "rotation %.3f deg (roll %+.3f, pitch %+.3f, yaw %+.3f), translation %.4f m "
                "(%+.4f, %+.4f, %+.4f), time offset %+.4f s",
                error.rotation_deg, error.roll_deg, error.pitch_deg, error.yaw_deg,
                error.translation_norm_m, error.translation_m.x(), error.translation_m.y(),
                error.translation_m.z(), error.time_offset_s);
  return buffer;
}

}  // namespace stcalib
