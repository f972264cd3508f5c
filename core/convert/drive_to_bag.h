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
//   P = P_rect_02, K = P's left 3 × 3, no distortion: KITTI's images are rectified);
// - kBagCloudTopic: sensor_msgs/msg/PointCloud2, frame "lidar", fields x, y, z, intensity
//   (float32), ring (uint16) and time (float64 seconds from the stamp), the rings and capture
//   times stcalib derives from a KITTI sweep (which stores neither), in its point order;
// - kBagOdometryTopic: nav_msgs/msg/Odometry from the oxts packets, "world" to "imu": the pose
//   KITTI's devkit builds, the twist in the body frame (only with oxts and calib_imu_to_velo.txt);
// - /tf_static: "camera" ← "lidar" (the drive's calib_velo_to_cam.txt) and "lidar" ← "imu".
// A simulated drive's ground_truth.json is copied beside metadata.yaml.
inline constexpr char kBagImageTopic[] = "/camera/image_raw";
inline constexpr char kBagCameraInfoTopic[] = "/camera/camera_info";
inline constexpr char kBagCloudTopic[] = "/lidar/points";
inline constexpr char kBagOdometryTopic[] = "/odom";

struct DriveToBagSummary {
  size_t frames = 0;
  uint64_t messages = 0;
  std::string mcap_path;
  bool odometry = false;  ///< the drive had oxts to write as odometry
};

// `bag_dir` must not exist yet or be empty; errors name the drive's file or the bag's.
Status WriteDriveAsBag(const Drive& drive, const std::string& bag_dir, DriveToBagSummary* summary);

}  // namespace stcalib
