#pragma once

#include <functional>
#include <vector>

#include "core/types/transform.h"

namespace stcalib {

// T_world_lidar at a time given in seconds relative to some reference.
using LidarPoseFunction = std::function<Rigid3d(double t_s)>;

// Moves every point of a sweep from its own capture time (stamp_s + time_s[i]) to the sweep
// stamp: p_stamp = T_world_lidar(stamp)⁻¹ · T_world_lidar(stamp + t_i) · p_i. The relative poses
// are tabulated at `bins` times across the sweep (0.4 ms apart for a 0.1 s sweep with the
// default) and each point interpolates between the two around its time.
std::vector<Eigen::Vector3d> DeskewToStamp(const std::vector<Eigen::Vector3d>& points_lidar,
                                           const std::vector<double>& time_s, double stamp_s,
                                           const LidarPoseFunction& T_world_lidar, int bins = 256);

// Pose of the sweep stamped t_from in the frame of the sweep stamped t_to.
Rigid3d RelativeLidarPose(const LidarPoseFunction& T_world_lidar, double t_to_s, double t_from_s);

// How that relative pose changes when both stamps shift together: d/dδ of
// RelativeLidarPose(T_world_lidar, t_to + δ, t_from + δ) at δ = 0, as [∂R/∂δ | ∂t/∂δ] [1/s, m/s]
// (central difference over ±5 ms). Zero for a constant twist; not zero while the vehicle
// accelerates or turns in or out. The LiDAR's stamps are off by the time offset δ (docs/method.md
// §2), so a local map merged at the stamps is merged at the wrong times: a point p of the sweep
// t_from sits at T·p + δ·(∂R·p + ∂t) in the sweep t_to's frame, to first order.
Eigen::Matrix<double, 3, 4> RelativeLidarPoseRate(const LidarPoseFunction& T_world_lidar,
                                                  double t_to_s, double t_from_s);

}  // namespace stcalib
