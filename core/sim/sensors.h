#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "core/io/oxts.h"
#include "core/io/velodyne.h"
#include "core/motion/oxts_poses.h"
#include "core/sim/scene.h"
#include "core/sim/trajectory.h"

namespace stcalib::sim {

// An HDL-64E-like spinning LiDAR: 64 beams (32 from +2° to −8.33°, 32 from −8.83° to −24.9°),
// spinning clockwise seen from above, one return per beam and azimuth step.
struct LidarModel {
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
  Eigen::Matrix<double, 3, 4> P_rect_02 = Eigen::Matrix<double, 3, 4>::Zero();
  int width = 1242, height = 375;
  // The camera's mount tilted nose-down about its own centre, relative to KITTI's [deg].
  double nose_down_deg = 0.0;
  Rigid3d T_imu_camera = Rigid3d::Identity();  ///< unrectified camera 0 in the IMU frame
  Eigen::Vector3d sun_world = Eigen::Vector3d(0.3, 0.4, 0.87).normalized();
  double noise_sigma = 2.0;  ///< image noise σ [grey levels]
};

// Renders image_02 at time t_s (global shutter) by ray casting through P_rect_02 and R_rect_00.
cv::Mat RenderCameraImage(const Scene& scene, const SimTrajectory& trajectory, const CameraRig& rig,
                          double t_s, std::mt19937_64* rng);

// An oxts packet of the true motion at t_s with measurement noise.
OxtsPacket SynthesizeOxtsPacket(const SimTrajectory& trajectory, const OxtsOrigin& origin,
                                double t_s, std::mt19937_64* rng);

}  // namespace stcalib::sim
