#include "core/sim/trajectory.h"

#include <cmath>

namespace stcalib::sim {

SimTrajectory::SimTrajectory(const SimRoad* road, std::mt19937_64* rng, double mean_speed_mps)
    : road_(road) {
  std::uniform_real_distribution<double> mean(10.0, 13.0), amplitude(1.0, 2.0), period(6.0, 12.0),
      phase(0.0, 2 * M_PI);
  v_mean_ = mean(*rng);
  v_amplitude_ = amplitude(*rng);
  v_period_ = period(*rng);
  v_phase_ = phase(*rng);
  roll_phase_ = phase(*rng);
  pitch_phase_ = phase(*rng);
  bounce_phase_ = phase(*rng);
  if (mean_speed_mps > 0) {  // after every draw: the rest of the drive stays as the seed makes it
    v_amplitude_ *= mean_speed_mps / v_mean_;
    v_mean_ = mean_speed_mps;
  }
}

double SimTrajectory::Speed(double t) const {
  return v_mean_ + v_amplitude_ * std::sin(2 * M_PI * t / v_period_ + v_phase_);
}

double SimTrajectory::ArcLength(double t) const {
  const double w = 2 * M_PI / v_period_;
  return v_mean_ * t - v_amplitude_ / w * (std::cos(w * t + v_phase_) - std::cos(v_phase_));
}

Eigen::Vector3d SimTrajectory::RollPitchYaw(double t) const {
  const double s = ArcLength(t);
  const double v = Speed(t);
  const double w = 2 * M_PI / v_period_;
  const double accel = v_amplitude_ * w * std::cos(w * t + v_phase_);
  const double lateral_accel = road_->Curvature(s) * v * v;
  // Lean out of the turn (left turn: left side up, positive roll) and squat under acceleration
  // (front up, negative pitch), plus slow suspension motion.
  const double roll = 0.004 * lateral_accel + 0.004 * std::sin(2 * M_PI * t / 2.3 + roll_phase_);
  const double pitch = -0.003 * accel + 0.003 * std::sin(2 * M_PI * t / 3.1 + pitch_phase_);
  return Eigen::Vector3d(roll, pitch, road_->Heading(s));
}

Rigid3d SimTrajectory::T_world_imu(double t) const {
  const Eigen::Vector3d rpy = RollPitchYaw(t);
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  const Eigen::Vector2d xy = road_->Position(ArcLength(t));
  const double z = kImuHeightM + 0.01 * std::sin(2 * M_PI * t / 1.7 + bounce_phase_);
  return MakeRigid(R, Eigen::Vector3d(xy.x(), xy.y(), z));
}

}  // namespace stcalib::sim
