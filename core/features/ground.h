#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/types/status.h"

namespace stcalib {

// Ground removal (docs/method.md §4): a RANSAC plane through the nearby, low returns, refined by
// least squares on its inliers; points within `band_m` of it (or below it) are ground.
struct GroundOptions {
  double max_fit_range_m = 30.0;     ///< only returns this close (horizontally) fit the plane [m]
  double max_tilt_deg = 15.0;        ///< plane normals further than this from LiDAR z are rejected
  double inlier_threshold_m = 0.12;  ///< RANSAC inlier distance [m]
  double band_m = 0.25;              ///< points up to this high above the plane are ground [m]
  int iterations = 80;
  int sample_points = 3000;  ///< returns drawn for the RANSAC consensus
  uint64_t seed = 7;

  Status Validate() const;
};

struct GroundPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, pointing up (z > 0)
  double offset = 0;                                  ///< plane: normal · p + offset = 0
  bool valid = false;
  int inliers = 0;  ///< inliers among the sampled returns

  double Height(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
};

GroundPlane FitGroundPlane(const std::vector<Eigen::Vector3d>& points_lidar,
                           const GroundOptions& options);

// 1 for ground points, 0 otherwise; all zeros when the plane is not valid.
std::vector<uint8_t> GroundMask(const std::vector<Eigen::Vector3d>& points_lidar,
                                const GroundPlane& plane, double band_m);

}  // namespace stcalib
