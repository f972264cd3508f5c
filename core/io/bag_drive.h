#pragma once

#include <string>

#include "core/io/drive.h"
#include "core/io/image.h"
#include "core/io/ros_messages.h"
#include "core/types/status.h"

namespace stcalib {

// A ROS 2 bag opened as a drive (docs/method.md §9, `calibrate --bag`): one frame per sweep of
// the cloud topic, paired with the image nearest its stamp (within half the sweep period); the
// camera from the first CameraInfo; the extrinsic start and the odometry's transform to the LiDAR
// from the bag's /tf_static (and /tf) chain between the messages' frame ids; the motion from the
// odometry when a topic is given, else from scan registration (its rotation between sweeps
// shaped by the IMU's rates when an IMU topic is given). The images and sweeps stay on disk
// in a spool file beside nothing the user owns (the system's temporary folder) until the drive is
// closed, so a long bag costs its index, not its size, in memory.
struct BagDriveOptions {
  std::string bag_dir;
  std::string image_topic;        ///< sensor_msgs/msg/Image or CompressedImage
  std::string cloud_topic;        ///< sensor_msgs/msg/PointCloud2
  std::string camera_info_topic;  ///< empty: the image topic's namespace + "/camera_info"
  std::string odom_topic;         ///< nav_msgs/msg/Odometry; empty: scan registration
  std::string imu_topic;  ///< sensor_msgs/msg/Imu, with scan registration (not with odom_topic)
  // Without a tf between the camera and the LiDAR the start must come from elsewhere
  // (--init_calib); when this is set its absence is an error naming both frames.
  bool require_tf_extrinsic = true;
};

Status OpenBagDrive(const BagDriveOptions& options, Drive* drive);

// A sweep from its cloud, as the features read it: points grouped by ring (a driver's ring
// field; else the rows of an organized cloud; else, unless the cloud is in KITTI's order, by
// elevation), each ring in KITTI's azimuth order (docs/method.md §10); the driver's per-point
// times kept when it wrote them. A cloud in KITTI's order without rings (kitti2bag's) keeps its
// order and is split like KITTI's sweeps; without times the features time points by azimuth.
LidarScan ScanFromCloud(const CloudPoints& cloud, uint32_t rows);

// The ros2msg camera: CameraInfo's R and P are KITTI's R_rect_00 and P_rect_02 (a point X in the
// camera frame lands at P·(R·X) in the rectified image), and its K and D undistort a raw image
// (plumb_bob, rational_polynomial, equidistant); with all-zero D the image is taken as already
// rectified. `maps` rectifies the raw images (empty when they are rectified). Errors name an
// unsupported model or a P without focal length.
Status CameraFromInfo(const RosCameraInfo& info, CameraCalibration* camera, RectifyMaps* maps);

}  // namespace stcalib
