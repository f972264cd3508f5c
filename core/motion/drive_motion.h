#pragma once

#include <vector>

#include "core/io/drive.h"
#include "core/motion/deskew.h"
#include "core/motion/oxts_trajectory.h"
#include "core/types/status.h"

namespace stcalib {

// The LiDAR's motion over a drive. Two sources:
// - oxts (Create): the oxts packets and calib_imu_to_velo.txt, interpolated between packets; a
//   bag's odometry samples (Drive::odometry) the same way, with the transform from its tf;
// - scan registration (CreateFromScans, for drives without oxts): each sweep registered to the
//   previous one with NDT, and a constant velocity between consecutive sweep stamps (docs/method.md
//   §3's constant-velocity model), extrapolated with the nearest segment's velocity. With a bag's
//   IMU (Drive::imu) the rotation between two sweeps follows the integrated gyro instead, bent
//   evenly so that it still ends at the registered pose, and the gyro seeds each registration.
// Times are seconds relative to a reference stamp (the first oxts or LiDAR stamp).
class DriveMotion {
 public:
  enum class Source { kOxts, kOdometry, kScanRegistration };

  // Fails with the reason when the drive has no usable oxts or odometry (no folder, bad stamps).
  static Status Create(const Drive& drive, DriveMotion* motion);
  // Fails when fewer than two sweeps can be read and registered.
  static Status CreateFromScans(const Drive& drive, DriveMotion* motion);
  // Create when the drive has oxts or odometry and calib_imu_to_velo.txt, else CreateFromScans with
  // a warning that says why.
  static Status CreateForDrive(const Drive& drive, DriveMotion* motion);

  Source source() const { return source_; }
  // The poses come from a measured trajectory (oxts or odometry) looked up at the stamps, not
  // from the sweeps themselves.
  bool measured() const { return source_ != Source::kScanRegistration; }
  // "oxts", "odometry", "scan_registration" or "scan_registration_imu"
  const char* SourceName() const;
  Rigid3d T_world_lidar(double t_s) const;
  LidarPoseFunction PoseFunction() const;
  double Seconds(StampNs stamp_ns) const { return NsToSeconds(stamp_ns - reference_ns_); }
  // How far the pose at t is interpolated or extrapolated from measurements [s]: the span of
  // the oxts packets around t; for scan registration the distance outside the sweeps' stamps.
  double GapAround(double t_s) const;
  // Sweeps whose registration failed (their motion is the previous segment's velocity).
  int failed_registrations() const { return failed_registrations_; }

 private:
  Source source_ = Source::kOxts;
  StampNs reference_ns_ = 0;
  OxtsTrajectory trajectory_;
  Rigid3d T_imu_lidar_ = Rigid3d::Identity();
  std::vector<double> scan_times_s_;  // sweep stamps (scan registration)
  std::vector<Rigid3d> scan_poses_;   // T_world_lidar at those stamps
  int failed_registrations_ = 0;
  // The gyro (scan registration with an IMU): at each sample time the IMU's rotation since the
  // first sample, and the mean rate up to the next sample.
  std::vector<double> gyro_times_s_;
  std::vector<Eigen::Matrix3d> gyro_rotations_;
  std::vector<Eigen::Vector3d> gyro_rates_;
  Eigen::Matrix3d R_lidar_imu_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d GyroRotation(double t_s) const;
  // The LiDAR's rotation from time a to time b by the gyro: R_world_lidar(a)ᵀ · R_world_lidar(b).
  Eigen::Matrix3d GyroLidarRotation(double a_s, double b_s) const;
};

// Sweep duration of a drive: mean of timestamps_end − timestamps_start, else the mean LiDAR
// period, else 0.1 s.
double SweepDurationSeconds(const Drive& drive);

}  // namespace stcalib
