#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/types/status.h"
#include "core/types/transform.h"

namespace stcalib {

// ROS 2 messages as a bag stores them: CDR (OMG XCDR version 1, little or big endian after a
// 4-byte encapsulation header; primitives aligned to their size from the end of that header).
// Only the messages and fields a calibration reads; every decoder checks every length against
// the bytes it was given and names the message type in its errors.

// The message types read and written, as bags name them.
inline constexpr char kRosImageType[] = "sensor_msgs/msg/Image";
inline constexpr char kRosCompressedImageType[] = "sensor_msgs/msg/CompressedImage";
inline constexpr char kRosCameraInfoType[] = "sensor_msgs/msg/CameraInfo";
inline constexpr char kRosPointCloud2Type[] = "sensor_msgs/msg/PointCloud2";
inline constexpr char kRosImuType[] = "sensor_msgs/msg/Imu";
inline constexpr char kRosOdometryType[] = "nav_msgs/msg/Odometry";
inline constexpr char kRosTfMessageType[] = "tf2_msgs/msg/TFMessage";

// The std_msgs/Header that opens a message (Image, CompressedImage, CameraInfo, PointCloud2, Imu,
// Odometry), without reading the rest.
Status DecodeHeader(const std::vector<uint8_t>& cdr, int64_t* stamp_ns, std::string* frame_id);

struct RosImage {
  int64_t stamp_ns = 0;  ///< header.stamp [ns]
  std::string frame_id;
  uint32_t height = 0, width = 0, step = 0;
  std::string encoding;  ///< e.g. "rgb8", "bgr8", "mono8", "mono16"
  bool big_endian = false;
  std::vector<uint8_t> data;
};
// sensor_msgs/msg/Image.
Status DecodeImage(const std::vector<uint8_t>& cdr, RosImage* image);
// The image as 8-bit BGR (rgb8, bgr8, mono8; mono16 scaled by 1/256); an error names any other
// encoding.
Status ImageToBgr(const RosImage& image, cv::Mat* bgr);

// sensor_msgs/msg/CompressedImage (format "jpeg", "png", or ROS's "bgr8; jpeg compressed bgr8"),
// decoded to 8-bit BGR; an error names an image that does not decode.
Status DecodeCompressedImage(const std::vector<uint8_t>& cdr, int64_t* stamp_ns, cv::Mat* bgr);

struct RosCameraInfo {
  int64_t stamp_ns = 0;
  std::string frame_id;
  uint32_t height = 0, width = 0;
  std::string distortion_model;  ///< "plumb_bob", "rational_polynomial", "equidistant", ...
  std::vector<double> d;         ///< distortion coefficients
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();
};
// sensor_msgs/msg/CameraInfo (binning and region of interest are read past, not kept).
Status DecodeCameraInfo(const std::vector<uint8_t>& cdr, RosCameraInfo* info);

struct RosImu {
  int64_t stamp_ns = 0;
  std::string frame_id;
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d linear_acceleration_m_s2 = Eigen::Vector3d::Zero();
};
// sensor_msgs/msg/Imu (the covariances are read past).
Status DecodeImu(const std::vector<uint8_t>& cdr, RosImu* imu);

struct RosOdometry {
  int64_t stamp_ns = 0;
  std::string frame_id, child_frame_id;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d linear_m_s = Eigen::Vector3d::Zero();     ///< in child_frame_id
  Eigen::Vector3d angular_rad_s = Eigen::Vector3d::Zero();  ///< in child_frame_id
};
// nav_msgs/msg/Odometry (the covariances are read past).
Status DecodeOdometry(const std::vector<uint8_t>& cdr, RosOdometry* odometry);

struct RosPointField {
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype =
      0;  ///< 1 int8, 2 uint8, 3 int16, 4 uint16, 5 int32, 6 uint32, 7 float32, 8 float64
  uint32_t count = 1;
};
struct RosPointCloud {
  int64_t stamp_ns = 0;
  std::string frame_id;
  uint32_t height = 0, width = 0, point_step = 0, row_step = 0;
  std::vector<RosPointField> fields;
  bool big_endian = false, dense = false;
  std::vector<uint8_t> data;
};
// sensor_msgs/msg/PointCloud2.
Status DecodePointCloud2(const std::vector<uint8_t>& cdr, RosPointCloud* cloud);

// The points of a cloud, whatever its field layout: x, y, z (float32 or float64) and, when the
// cloud has them, intensity, ring and a per-point time. The time field is the first of `time`,
// `t`, `timestamp`; float fields are seconds, integer ones nanoseconds (Velodyne's driver writes
// float seconds from the sweep's start, Ouster's uint32 ns, Hesai's float64 absolute seconds);
// the times are returned relative to the cloud's stamp [s] (a time above 1e8 s is taken as
// absolute, seconds since the epoch, and the stamp subtracted).
struct CloudPoints {
  std::vector<Eigen::Vector3d> points;
  std::vector<float> intensity;  ///< empty without an intensity field
  std::vector<uint16_t> ring;    ///< empty without a ring field
  std::vector<double> time_s;    ///< empty without a time field
  std::vector<uint32_t> row;  ///< each point's row of an organized cloud (height > 1), else empty
  std::string time_field;     ///< which field gave the times
};
// Points with a non-finite coordinate (a dense=false cloud's no-returns) or at the origin (an
// organized Ouster cloud's) are left out. Errors
// name a missing x, y or z field, a field past the point's end and an inconsistent size.
Status ExtractCloudPoints(const RosPointCloud& cloud, CloudPoints* points);

// tf2_msgs/msg/TFMessage: geometry_msgs/TransformStamped, each the pose of `child_frame_id` in
// `frame_id` (a point's child coordinates map to parent ones: p_parent = T_parent_child · p_child).
struct RosTransform {
  int64_t stamp_ns = 0;
  std::string frame_id;        ///< parent
  std::string child_frame_id;  ///< child
  Rigid3d T_parent_child = Rigid3d::Identity();
};
Status DecodeTfMessage(const std::vector<uint8_t>& cdr, std::vector<RosTransform>* transforms);

// Encoders: little-endian CDR that the decoders above read back field for field (for `stcalib
// convert`, which writes drives as bags). Covariances are written as zeros, CameraInfo's binning
// and region of interest as "none".
std::vector<uint8_t> EncodeImage(const RosImage& image);
std::vector<uint8_t> EncodeCameraInfo(const RosCameraInfo& info);
std::vector<uint8_t> EncodePointCloud2(const RosPointCloud& cloud);
std::vector<uint8_t> EncodeOdometry(const RosOdometry& odometry);
std::vector<uint8_t> EncodeImu(const RosImu& imu);
std::vector<uint8_t> EncodeTfMessage(const std::vector<RosTransform>& transforms);

// The ros2msg text of a message type the encoders write, with its nested types (an MCAP schema);
// empty for any other type.
std::string Ros2MsgDefinition(const std::string& type);

}  // namespace stcalib
