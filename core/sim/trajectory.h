#pragma once

#include <random>

#include "core/sim/road.h"
#include "core/types/transform.h"

namespace stcalib::sim {

// The ego vehicle's true motion: it follows the road centreline with a smooth speed profile
// (8–15 m/s, or around `mean_speed_mps` when it is positive, with the same relative swing), leans
// in turns and pitches under acceleration, with small suspension motion.
// Time t is in seconds from the start of the drive. The world is east-north-up (x east).
class SimTrajectory {
 public:
  SimTrajectory(const SimRoad* road, std::mt19937_64* rng, double mean_speed_mps = 0);

  double ArcLength(double t_s) const;  ///< s(t) [m], s(0) = 0
  double Speed(double t_s) const;      ///< ds/dt [m/s]
  // Pose of the IMU (vehicle body: x forward, y left, z up) in the world.
  Rigid3d T_world_imu(double t_s) const;
  // Roll, pitch and yaw of the body [rad] (oxts conventions: R = Rz(yaw)·Ry(pitch)·Rx(roll)).
  Eigen::Vector3d RollPitchYaw(double t_s) const;
  static constexpr double kImuHeightM = 0.93;  ///< IMU above the ground plane [m]
  static constexpr double kMaxSpeedMps = 15.0;

 private:
  const SimRoad* road_;
  double v_mean_, v_amplitude_, v_period_, v_phase_;
  double roll_phase_, pitch_phase_, bounce_phase_;
};

}  // namespace stcalib::sim
