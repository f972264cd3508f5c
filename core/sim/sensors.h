#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <random>
#include <type_traits>
#include <vector>

#include "core/io/oxts.h"
#include "core/io/velodyne.h"
#include "core/motion/oxts_poses.h"
#include "core/sim/scene.h"
#include "core/sim/trajectory.h"

namespace stcalib::sim {

// An HDL-64E-like spinning LiDAR by default: 64 beams (32 from +2° to −8.33°, 32 from −8.83° to
// −24.9°), spinning clockwise seen from above, one return per beam and azimuth step. Other
// sensors (MakeLidarModel) list their beams' elevations instead.
struct LidarModel {
  std::vector<double> beam_elevations_deg;  ///< top beam first; empty: the HDL-64E's two blocks
  double elevation_top_deg = 2.0;
  double elevation_upper_bottom_deg = -8.33;
  double elevation_lower_top_deg = -8.83;
  double elevation_bottom_deg = -24.9;
  int beams = 64;
  double azimuth_step_deg = 0.09;       ///< [deg]
  double range_noise_m = 0.02;          ///< Gaussian σ [m]
  double max_range_m = 120.0;           ///< [m]
  double min_range_m = 2.0;             ///< returns nearer than this are dropped [m]
  double foliage_penetration_m = 0.35;  ///< returns in tree crowns land up to this deep [m]

  double ElevationDeg(int beam) const;  ///< beam 0 is the top one
};

// The simulated LiDARs (`simulate --lidar`): beams, azimuth step, range and noise as the data
// sheets give them.
enum class SimLidar {
  kHdl64,   ///< Velodyne HDL-64E (KITTI's): 64 beams +2° to −24.9°, 0.09° steps at 10 Hz
  kVlp16,   ///< Velodyne VLP-16: 16 beams ±15° every 2°, 0.2° steps at 10 Hz, 100 m, σ 3 cm
  kOs1_64,  ///< Ouster OS1-64 (gen 1): 64 beams ±16.6°, 1024 columns, 120 m, σ 3 cm
};
LidarModel MakeLidarModel(SimLidar lidar);

struct SimulatedSweep {
  LidarScan scan;                    ///< KITTI order: lasers top to bottom, each CCW from ahead
  std::vector<uint8_t> labels;       ///< PointLabel per point
  std::vector<double> point_time_s;  ///< true capture time of every point [s]
  std::vector<uint16_t> ring;        ///< beam of every point, 0 = top
};

// One sweep centred (facing forward) at t_mid_s, lasting sweep_duration_s. Every point is
// captured at its own azimuth time: t = t_mid − azimuth/2π · duration, azimuth in (−π, π].
SimulatedSweep SimulateLidarSweep(const Scene& scene, const SimTrajectory& trajectory,
                                  const Rigid3d& T_imu_lidar, const LidarModel& model,
                                  double t_mid_s, double sweep_duration_s, std::mt19937_64* rng);

struct CameraRig {
  Eigen::Matrix3d R_rect_00 = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 3, 4> P_rect = Eigen::Matrix<double, 3, 4>::Zero();
  int width = 1242, height = 375;
  // The camera's mount tilted nose-down about its own centre, relative to KITTI's [deg].
  double nose_down_deg = 0.0;
  Rigid3d T_imu_camera = Rigid3d::Identity();  ///< unrectified camera 0 in the IMU frame
  Eigen::Vector3d sun_world = Eigen::Vector3d(0.3, 0.4, 0.87).normalized();
  double noise_sigma = 2.0;  ///< image noise σ [grey levels]
  // A raw, distorted image instead of a rectified one: plumb_bob coefficients k1 k2 p1 p2 k3 of a
  // camera with matrix P_rect_02's left 3 × 3 whose frame is the unrectified one R_rect_00 turns
  // (ROS CameraInfo's model: rectified pixel = P · R · X). Empty: rectified.
  std::vector<double> distortion;
};

// Renders image_02 at time t_s (global shutter) by ray casting through P_rect_02 and R_rect_00,
// each pixel's ray first undistorted when the rig has a distortion.
cv::Mat RenderCameraImage(const Scene& scene, const SimTrajectory& trajectory, const CameraRig& rig,
                          double t_s, std::mt19937_64* rng);

// The error of a fused GPS/INS navigation solution such as KITTI's OXTS RT3003 (RTK): a smooth
// drift of a few centimetres and a few 1e-4 rad that wanders over tens of seconds, plus a small
// white part per packet. The drift is a sum of sinusoids with random periods and phases, so it can
// be evaluated at any time alone (each frame is simulated alone) and its rate is exact: the written
// velocities carry the position drift's rate, as a Kalman filter's output would, and a slow drift
// of their own, as KITTI's shared packets show (measured: docs/tuning.md#navigation-error).
struct NavigationErrorOptions {
  double position_drift_m = 0.02;    ///< σ of the slow position error, per axis [m]
  double angle_drift_rad = 2e-4;     ///< σ of the slow roll, pitch and yaw error [rad]
  double velocity_drift_mps = 0.08;  ///< σ of the velocities' own slow error, east and north [m/s]
  double vertical_velocity_drift_mps = 0.025;  ///< the same, up [m/s]
  double min_period_s = 10.0;           ///< shortest period of the position and attitude drift [s]
  double max_period_s = 100.0;          ///< longest period of the position and attitude drift [s]
  double velocity_min_period_s = 2.0;   ///< shortest period of the velocities' drift [s]
  double velocity_max_period_s = 20.0;  ///< longest period of the velocities' drift [s]
  double position_white_m = 0.001;      ///< σ of each packet's own position noise, per axis [m]
  double angle_white_rad = 2e-5;        ///< σ of each packet's own attitude noise [rad]
  double velocity_white_mps = 0.02;     ///< σ of each packet's own velocity noise, per axis [m/s]
  double acceleration_white_mps2 = 0.05;  ///< σ of each packet's acceleration noise [m/s²]
  double rate_white_radps = 5e-4;         ///< σ of each packet's angular-rate noise [rad/s]

  // Every σ above times `factor` (the periods unchanged): 0 is exact navigation.
  NavigationErrorOptions Scaled(double factor) const;
  // Every σ above: the one list that Scaled and SimulatorOptions::Validate walk.
  std::array<double*, 9> Sigmas() { return SigmasOf(*this); }
  std::array<const double*, 9> Sigmas() const { return SigmasOf(*this); }

 private:
  template <typename Self>
  static std::array<std::conditional_t<std::is_const_v<Self>, const double*, double*>, 9> SigmasOf(
      Self& o) {
    return {&o.position_drift_m,   &o.angle_drift_rad,
            &o.velocity_drift_mps, &o.vertical_velocity_drift_mps,
            &o.position_white_m,   &o.angle_white_rad,
            &o.velocity_white_mps, &o.acceleration_white_mps2,
            &o.rate_white_radps};
  }
};

class NavigationError {
 public:
  NavigationError() = default;  ///< no drift; the default options' white noise
  NavigationError(const NavigationErrorOptions& options, std::mt19937_64* rng);

  const NavigationErrorOptions& options() const { return options_; }
  Eigen::Vector3d PositionDrift(double t_s) const;      ///< east, north, up [m]
  Eigen::Vector3d PositionDriftRate(double t_s) const;  ///< d/dt of PositionDrift [m/s]
  Eigen::Vector3d AngleDrift(double t_s) const;         ///< roll, pitch, yaw [rad]
  Eigen::Vector3d VelocityDrift(double t_s) const;      ///< east, north, up, beyond the rate [m/s]

 private:
  static constexpr int kTerms = 4;  ///< sinusoids per axis
  struct Term {
    double amplitude = 0, angular_frequency = 0, phase = 0;
  };
  using Axis = std::array<Term, kTerms>;
  // Each axis's sum of sinusoids at t_s, or (rate) its time derivative.
  static Eigen::Vector3d Evaluate(const std::array<Axis, 3>& axes, double t_s, bool rate);

  NavigationErrorOptions options_;
  std::array<Axis, 3> position_{}, angle_{}, velocity_{};
};

// An oxts packet of the true motion at t_s with `error`'s drift and white noise drawn from `rng`.
OxtsPacket SynthesizeOxtsPacket(const SimTrajectory& trajectory, const OxtsOrigin& origin,
                                const NavigationError& error, double t_s, std::mt19937_64* rng);

}  // namespace stcalib::sim
