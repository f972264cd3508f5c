#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/types/status.h"

namespace stcalib {

// One LiDAR sweep as stored in a KITTI velodyne .bin: float32 x, y, z, reflectance per point,
// in the LiDAR frame, in scan order (docs/method.md §10). A sweep from a ROS 2 bag may also carry
// what its driver wrote per point: the ring (then the points are grouped by ring, each ring in
// KITTI's azimuth order) and the capture time; KITTI's files carry neither, and the features
// then split the rings and time the points from the azimuth.
struct LidarScan {
  std::vector<Eigen::Vector3d> points_lidar;  ///< [m]
  std::vector<float> reflectance;             ///< [0, 1]
  std::vector<uint16_t> ring;                 ///< empty, or one per point, non-decreasing
  std::vector<double> point_time_s;           ///< empty, or capture time − sweep stamp [s]

  size_t size() const { return points_lidar.size(); }
};

// Rejects files whose size is not a multiple of 16 bytes and any NaN/inf value (naming the file
// and the point index). An empty file is a valid, empty scan.
Status ReadVelodyneBin(const std::string& path, LidarScan* scan);
Status WriteVelodyneBin(const std::string& path, const LidarScan& scan);

// Per-point labels of simulated drives (velodyne_points/labels/NNNNNNNNNN.bin), one uint8 each.
enum class PointLabel : uint8_t { kStatic = 0, kDynamic = 1, kGround = 2 };
Status ReadPointLabels(const std::string& path, std::vector<uint8_t>* labels);
Status WritePointLabels(const std::string& path, const std::vector<uint8_t>& labels);

}  // namespace stcalib
