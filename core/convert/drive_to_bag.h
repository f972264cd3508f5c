#pragma once

#include <string>

#include "core/io/drive.h"
#include "core/types/status.h"

namespace stcalib {

// `stcalib convert` (docs/method.md §9): a drive (KITTI raw layout, real or simulated) written as
// a ROS 2 bag, a folder with metadata.yaml and one MCAP file, so that any drive can be calibrated
// through the bag path. Topics and frames:
// - kBagImageTopic: sensor_msgs/msg/Image, bgr8, frame "camera", stamped with the image;
// - kBagCameraInfoTopic: sensor_msgs/msg/CameraInfo beside every image (R = R_rect_00,
//   P = P_rect_02, K = P's left 3 × 3, no distortion: KITTI's images are rectified; a simulated
//   raw camera's images go as they are, with its model, K and D);
// - kBagCloudTopic: sensor_msgs/msg/PointCloud2, frame "lidar", in a driver's CloudLayout, with
//   the rings and capture times stcalib derives from a KITTI sweep (which stores neither);
// - kBagOdometryTopic: nav_msgs/msg/Odometry from the oxts packets, "world" to "imu": the pose
//   KITTI's devkit builds, the twist in the body frame (only with oxts and calib_imu_to_velo.txt);
// - kBagImuTopic: sensor_msgs/msg/Imu from the same packets, frame "imu": attitude, body rates
//   and accelerations;
// - /tf_static: "camera" ← "lidar" (the drive's calib_velo_to_cam.txt) and "lidar" ← "imu".
// A simulated drive's ground_truth.json is copied beside metadata.yaml.
inline constexpr char kBagImageTopic[] = "/camera/image_raw";
inline constexpr char kBagCameraInfoTopic[] = "/camera/camera_info";
inline constexpr char kBagCloudTopic[] = "/lidar/points";
inline constexpr char kBagOdometryTopic[] = "/odom";
inline constexpr char kBagImuTopic[] = "/imu";

// How the clouds are laid out, as a driver writes them (all carry the same points and times):
enum class CloudLayout {
  kKitti,     ///< KITTI's point order, stamped mid-sweep; x y z intensity, ring, time (float64 s)
  kVelodyne,  ///< velodyne_pointcloud's: firing order, stamped at the sweep's start; x y z
              ///< intensity (float32), ring (uint16, 0 = lowest beam), time (float32 s)
  kOuster,    ///< ouster-ros's: organized (a row per beam, top first; a column per firing in
              ///< spin order; no return = zeros), stamped at the start; t (uint32 ns), ring
              ///< (uint16, 0 = top), reflectivity, ambient, range
};
// The layout of a simulated drive's LiDAR (ground_truth.json's "lidar": vlp16 → Velodyne's,
// os1-64 → Ouster's), else KITTI's.
CloudLayout CloudLayoutForLidar(const std::string& lidar_name);

struct DriveToBagSummary {
  size_t frames = 0;
  uint64_t messages = 0;
  std::string mcap_path;
  bool odometry = false;  ///< the drive had oxts to write as odometry
};

// `bag_dir` must not exist yet or be empty; errors name the drive's file or the bag's.
Status WriteDriveAsBag(const Drive& drive, const std::string& bag_dir, CloudLayout layout,
                       DriveToBagSummary* summary);

}  // namespace stcalib
