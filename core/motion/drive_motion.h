#pragma once

#include "core/io/drive.h"
#include "core/motion/deskew.h"
#include "core/motion/oxts_trajectory.h"
#include "core/types/status.h"

namespace stcalib {

// The LiDAR's motion over a drive, from its oxts packets and calib_imu_to_velo.txt. Times are
// seconds relative to the first oxts stamp, on the stamps' own clocks.
class DriveMotion {
 public:
  // Fails with the reason when the drive has no usable oxts (no folder, bad stamps).
  static Status Create(const Drive& drive, DriveMotion* motion);

  Rigid3d T_world_lidar(double t_s) const;
  LidarPoseFunction PoseFunction() const;
  double Seconds(StampNs stamp_ns) const {
    return NsToSeconds(stamp_ns - trajectory_.reference_ns());
  }
  const OxtsTrajectory& trajectory() const { return trajectory_; }

 private:
  OxtsTrajectory trajectory_;
  Rigid3d T_imu_lidar_ = Rigid3d::Identity();
};

// Sweep duration of a drive: mean of timestamps_end − timestamps_start, else the mean LiDAR
// period, else 0.1 s.
double SweepDurationSeconds(const Drive& drive);

}  // namespace stcalib
