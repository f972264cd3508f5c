#include "core/motion/drive_motion.h"

#include <glog/logging.h>

#include <algorithm>

#include "core/motion/motion_model.h"
#include "core/pcl/registration.h"

namespace stcalib {

Status DriveMotion::Create(const Drive& drive, DriveMotion* motion) {
  if (!drive.odometry.empty()) {
    if (!drive.has_imu_calibration) {
      return Status::Error(drive.drive_dir +
                           ": the odometry's frame has no transform to the LiDAR's");
    }
    DriveMotion m;
    STCALIB_RETURN_IF_ERROR(OxtsTrajectory::FromOdometry(drive.odometry, &m.trajectory_)
                                .WithContext(drive.drive_dir + ": "));
    m.T_imu_lidar_ = drive.T_lidar_imu.inverse();
    m.source_ = Source::kOdometry;
    m.reference_ns_ = m.trajectory_.reference_ns();
    *motion = std::move(m);
    return Status::Ok();
  }
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
  m.source_ = Source::kOxts;
  m.reference_ns_ = m.trajectory_.reference_ns();
  *motion = std::move(m);
  return Status::Ok();
}

const char* DriveMotion::SourceName() const {
  switch (source_) {
    case Source::kOxts:
      return "oxts";
    case Source::kOdometry:
      return "odometry";
    case Source::kScanRegistration:
      break;
  }
  return gyro_times_s_.empty() ? "scan_registration" : "scan_registration_imu";
}

Status DriveMotion::CreateForDrive(const Drive& drive, DriveMotion* motion) {
  if ((drive.has_oxts || !drive.odometry.empty()) && drive.has_imu_calibration) {
    return Create(drive, motion);
  }
  LOG(WARNING) << (drive.has_oxts ? drive.calib_dir +
                                        "/calib_imu_to_velo.txt: missing, so the "
                                        "oxts motion cannot be used"
                                  : drive.drive_dir + ": no oxts")
               << "; the motion comes from registering consecutive sweeps (NDT) with a constant "
                  "velocity between them"
               << (drive.imu.empty() ? "" : ", the rotation shaped by the IMU's rates");
  return CreateFromScans(drive, motion);
}

Status DriveMotion::CreateFromScans(const Drive& drive, DriveMotion* motion) {
  const size_t n = drive.NumFrames();
  if (n < 2) return Status::Error(drive.drive_dir + ": scan registration needs two sweeps or more");
  DriveMotion m;
  m.source_ = Source::kScanRegistration;
  m.reference_ns_ = drive.lidar_stamps_ns.front();
  if (!drive.imu.empty() && drive.has_imu_calibration) {
    m.R_lidar_imu_ = drive.T_lidar_imu.linear();
    for (size_t k = 0; k < drive.imu.size(); ++k) {
      const double t = NsToSeconds(drive.imu[k].stamp_ns - m.reference_ns_);
      if (!m.gyro_times_s_.empty() && !(t > m.gyro_times_s_.back())) continue;  // repeated stamp
      if (m.gyro_times_s_.empty()) {
        m.gyro_rotations_.push_back(Eigen::Matrix3d::Identity());
      } else {
        // The mean of the two samples' rates over the interval (trapezoidal).
        m.gyro_rates_.back() = 0.5 * (m.gyro_rates_.back() + drive.imu[k].rate_rad_s);
        m.gyro_rotations_.push_back(m.gyro_rotations_.back() *
                                    ExpSO3(m.gyro_rates_.back() * (t - m.gyro_times_s_.back())));
      }
      m.gyro_times_s_.push_back(t);
      m.gyro_rates_.push_back(drive.imu[k].rate_rad_s);
    }
  }
  // Points between 2 and 60 m: the near car body and the sparse far field only add noise.
  auto load = [&](size_t k, std::vector<Eigen::Vector3d>* points) -> Status {
    LidarScan scan;
    STCALIB_RETURN_IF_ERROR(drive.LoadScan(k, &scan));
    points->clear();
    for (const Eigen::Vector3d& p : scan.points_lidar) {
      const double r = p.norm();
      if (r > 2.0 && r < 60.0) points->push_back(p);
    }
    if (points->size() < 1000) return Status::Error(drive.ScanName(k) + ": too few points");
    return Status::Ok();
  };
  std::vector<Eigen::Vector3d> previous, current;
  bool have_previous = false;
  Rigid3d T_world = Rigid3d::Identity();
  Rigid3d T_previous_current_guess = Rigid3d::Identity();
  double last_dt = 0.1;
  for (size_t k = 0; k < n; ++k) {
    const double t = NsToSeconds(drive.lidar_stamps_ns[k] - m.reference_ns_);
    if (!m.scan_times_s_.empty() && !(t > m.scan_times_s_.back())) {
      LOG(WARNING) << drive.drive_dir << ": sweep " << k
                   << " left out of the motion: its stamp does not increase";
      continue;
    }
    const Status status = load(k, &current);
    if (!status.ok()) {
      LOG(WARNING) << "scan motion: sweep " << k << " left out: " << status.message();
      continue;
    }
    if (have_previous) {
      const double dt = t - m.scan_times_s_.back();
      // Constant-velocity guess from the last segment, scaled to this gap.
      const LidarTwist guess_twist = ConstantVelocityTwist(T_previous_current_guess, last_dt);
      Rigid3d guess = LidarMotion(guess_twist, dt);
      if (!m.gyro_times_s_.empty()) guess.linear() = m.GyroLidarRotation(t - dt, t);
      RegistrationResult result;
      const Status registered = RegisterNdt(current, previous, guess, NdtOptions(), &result);
      Rigid3d T_previous_current = guess;
      const bool plausible = registered.ok() && result.T_target_source.matrix().allFinite() &&
                             result.T_target_source.translation().norm() < 60.0 * dt + 0.5;
      if (plausible) {
        T_previous_current = result.T_target_source;
      } else {
        ++m.failed_registrations_;
        LOG(WARNING) << "scan motion: sweep " << k << " not registered ("
                     << (registered.ok() ? "implausible result" : registered.message())
                     << "): previous velocity kept";
      }
      T_world = T_world * T_previous_current;
      T_previous_current_guess = T_previous_current;
      last_dt = dt;
    }
    m.scan_times_s_.push_back(t);
    m.scan_poses_.push_back(T_world);
    previous.swap(current);
    have_previous = true;
  }
  if (m.scan_times_s_.size() < 2) {
    return Status::Error(drive.drive_dir + ": fewer than two readable sweeps for the motion");
  }
  *motion = std::move(m);
  return Status::Ok();
}

Rigid3d DriveMotion::T_world_lidar(double t_s) const {
  if (measured()) return trajectory_.T_world_imu_s(t_s) * T_imu_lidar_;
  // Constant velocity on the segment around t (the first or last one outside the sweeps).
  const std::vector<double>& times = scan_times_s_;
  size_t i = std::upper_bound(times.begin(), times.end(), t_s) - times.begin();
  i = std::min(std::max<size_t>(i, 1), times.size() - 1) - 1;
  const double dt = times[i + 1] - times[i];
  const LidarTwist twist = ConstantVelocityTwist(scan_poses_[i].inverse() * scan_poses_[i + 1], dt);
  Rigid3d T = scan_poses_[i] * LidarMotion(twist, t_s - times[i]);
  if (gyro_times_s_.empty()) return T;
  // The gyro's rotation since the segment's start, bent evenly by what it misses at the end.
  const Eigen::Matrix3d registered =
      scan_poses_[i].linear().transpose() * scan_poses_[i + 1].linear();
  const Eigen::Vector3d miss =
      LogSO3(GyroLidarRotation(times[i], times[i + 1]).transpose() * registered);
  T.linear() = scan_poses_[i].linear() * GyroLidarRotation(times[i], t_s) *
               ExpSO3(miss * ((t_s - times[i]) / dt));
  return T;
}

Eigen::Matrix3d DriveMotion::GyroRotation(double t) const {
  const std::vector<double>& times = gyro_times_s_;
  size_t k = std::upper_bound(times.begin(), times.end(), t) - times.begin();
  k = k == 0 ? 0 : k - 1;  // before the first sample: extrapolated with its rate
  return gyro_rotations_[k] * ExpSO3(gyro_rates_[k] * (t - times[k]));
}

Eigen::Matrix3d DriveMotion::GyroLidarRotation(double a_s, double b_s) const {
  return R_lidar_imu_ * GyroRotation(a_s).transpose() * GyroRotation(b_s) *
         R_lidar_imu_.transpose();
}

double DriveMotion::GapAround(double t_s) const {
  if (measured()) return trajectory_.GapAround(t_s);
  if (t_s < scan_times_s_.front()) return scan_times_s_.front() - t_s;
  if (t_s > scan_times_s_.back()) return t_s - scan_times_s_.back();
  return 0.0;
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
