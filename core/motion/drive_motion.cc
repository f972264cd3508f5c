#include "core/motion/drive_motion.h"

namespace stcalib {

Status DriveMotion::Create(const Drive& drive, DriveMotion* motion) {
  if (!drive.has_oxts) {
    return Status::Error(drive.drive_dir + ": no oxts/ folder, so no vehicle motion");
  }
  if (!drive.has_imu_calibration) {
    return Status::Error(drive.calib_dir + "/calib_imu_to_velo.txt: missing");
  }
  DriveMotion m;
  STCALIB_RETURN_IF_ERROR(OxtsTrajectory::Create(drive.oxts, drive.oxts_stamps_ns, &m.trajectory_)
                              .WithContext(drive.drive_dir + "/oxts: "));
  m.T_imu_lidar_ = drive.T_lidar_imu.inverse();
  *motion = std::move(m);
  return Status::Ok();
}

Rigid3d DriveMotion::T_world_lidar(double t_s) const {
  return trajectory_.T_world_imu_s(t_s) * T_imu_lidar_;
}

LidarPoseFunction DriveMotion::PoseFunction() const {
  return [this](double t) { return T_world_lidar(t); };
}

double SweepDurationSeconds(const Drive& drive) {
  const size_t n = drive.NumFrames();
  if (!drive.lidar_start_stamps_ns.empty() && n > 0) {
    double sum = 0;
    for (size_t i = 0; i < n; ++i) {
      sum += NsToSeconds(drive.lidar_end_stamps_ns[i] - drive.lidar_start_stamps_ns[i]);
    }
    if (sum > 0) return sum / n;
  }
  if (n >= 2) {
    const double period =
        NsToSeconds(drive.lidar_stamps_ns.back() - drive.lidar_stamps_ns.front()) /
        static_cast<double>(n - 1);
    if (period > 0) return period;
  }
  return 0.1;
}

}  // namespace stcalib
