#include "core/convert/drive_to_bag.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include "core/features/lidar_rings.h"
#include "core/io/mcap.h"
#include "core/io/ros_messages.h"
#include "core/motion/drive_motion.h"
#include "core/motion/oxts_poses.h"

namespace fs = std::filesystem;

namespace stcalib {
namespace {

constexpr char kCameraFrame[] = "camera";
constexpr char kLidarFrame[] = "lidar";
constexpr char kImuFrame[] = "imu";
constexpr char kWorldFrame[] = "world";

// The cloud of one sweep: x, y, z, intensity (float32), ring (uint16), time (float64) per point.
RosPointCloud MakeCloud(const LidarScan& scan, const std::vector<uint16_t>& ring,
                        const std::vector<double>& time_s, int64_t stamp_ns) {
  RosPointCloud cloud;
  cloud.stamp_ns = stamp_ns;
  cloud.frame_id = kLidarFrame;
  cloud.height = 1;
  cloud.width = static_cast<uint32_t>(scan.size());
  cloud.fields = {{"x", 0, 7, 1},         {"y", 4, 7, 1},     {"z", 8, 7, 1},
                  {"intensity", 12, 7, 1}, {"ring", 16, 4, 1}, {"time", 24, 8, 1}};
  cloud.point_step = 32;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.dense = true;
  cloud.data.assign(size_t{cloud.row_step}, 0);
  for (size_t i = 0; i < scan.size(); ++i) {
    uint8_t* p = cloud.data.data() + i * cloud.point_step;
    const float xyzi[4] = {static_cast<float>(scan.points_lidar[i].x()),
                           static_cast<float>(scan.points_lidar[i].y()),
                           static_cast<float>(scan.points_lidar[i].z()),
                           scan.reflectance.empty() ? 0.0f : scan.reflectance[i]};
    std::memcpy(p, xyzi, sizeof(xyzi));
    std::memcpy(p + 16, &ring[i], sizeof(uint16_t));
    std::memcpy(p + 24, &time_s[i], sizeof(double));
  }
  return cloud;
}

// The YAML rosbag2 writes beside its storage files (the fields `ros2 bag info` reads).
std::string MetadataYaml(const std::string& mcap_name, const std::map<std::string, std::string>& types,
                         const std::map<std::string, uint64_t>& counts, uint64_t messages,
                         int64_t start_ns, int64_t end_ns) {
  std::string y = "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n";
  y += "  duration:\n    nanoseconds: " + std::to_string(std::max<int64_t>(end_ns - start_ns, 0)) +
       "\n";
  y += "  starting_time:\n    nanoseconds_since_epoch: " + std::to_string(start_ns) + "\n";
  y += "  message_count: " + std::to_string(messages) + "\n  topics_with_message_count:\n";
  for (const auto& [topic, type] : types) {
    y += "    - topic_metadata:\n        name: " + topic + "\n        type: " + type +
         "\n        serialization_format: cdr\n        offered_qos_profiles: \"\"\n"
         "      message_count: " +
         std::to_string(counts.count(topic) ? counts.at(topic) : 0) + "\n";
  }
  y += "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    - " +
       mcap_name + "\n";
  y += "  files:\n    - path: " + mcap_name + "\n      starting_time:\n" +
       "        nanoseconds_since_epoch: " + std::to_string(start_ns) + "\n      duration:\n" +
       "        nanoseconds: " + std::to_string(std::max<int64_t>(end_ns - start_ns, 0)) + "\n" +
       "      message_count: " + std::to_string(messages) + "\n";
  return y;
}

}  // namespace

Status WriteDriveAsBag(const Drive& drive, const std::string& bag_dir, DriveToBagSummary* summary) {
  *summary = DriveToBagSummary();
  std::error_code ec;
  if (fs::exists(bag_dir, ec) && !fs::is_empty(bag_dir, ec)) {
    return Status::Error(bag_dir + ": exists and is not empty; give a new folder for the bag");
  }
  fs::create_directories(bag_dir, ec);
  if (!fs::is_directory(bag_dir, ec)) return Status::Error(bag_dir + ": cannot create the folder");
  const std::string name = fs::path(bag_dir).filename().string();
  const std::string mcap_name = (name.empty() ? std::string("bag") : name) + "_0.mcap";
  summary->mcap_path = bag_dir + "/" + mcap_name;

  McapWriter writer;
  STCALIB_RETURN_IF_ERROR(writer.Open(summary->mcap_path));
  std::map<std::string, std::string> types;
  std::map<std::string, uint16_t> channels;
  std::map<std::string, uint64_t> counts;
  auto channel = [&](const std::string& topic, const std::string& type) {
    types[topic] = type;
    channels[topic] = writer.AddChannel(writer.AddSchema(type, Ros2MsgDefinition(type)), topic);
  };
  auto write = [&](const std::string& topic, int64_t stamp_ns, const std::vector<uint8_t>& cdr) {
    writer.Write(channels.at(topic), static_cast<uint64_t>(std::max<int64_t>(stamp_ns, 0)), cdr);
    ++counts[topic];
  };
  const bool odometry = drive.has_oxts && drive.has_imu_calibration;
  channel("/tf_static", "tf2_msgs/msg/TFMessage");
  channel(kBagImageTopic, "sensor_msgs/msg/Image");
  channel(kBagCameraInfoTopic, "sensor_msgs/msg/CameraInfo");
  channel(kBagCloudTopic, "sensor_msgs/msg/PointCloud2");
  if (odometry) channel(kBagOdometryTopic, "nav_msgs/msg/Odometry");

  const size_t n = drive.NumFrames();
  if (n == 0) return Status::Error(drive.drive_dir + ": no frames to convert");
  int64_t start_ns = std::min(drive.camera_stamps_ns.front(), drive.lidar_stamps_ns.front());
  if (odometry) start_ns = std::min(start_ns, drive.oxts_stamps_ns.front());
  int64_t end_ns = start_ns;
  std::vector<RosTransform> statics(1);
  statics[0].stamp_ns = start_ns;
  statics[0].frame_id = kCameraFrame;
  statics[0].child_frame_id = kLidarFrame;
  statics[0].T_parent_child = drive.T_camera_lidar;
  if (drive.has_imu_calibration) {
    RosTransform t;
    t.stamp_ns = start_ns;
    t.frame_id = kLidarFrame;
    t.child_frame_id = kImuFrame;
    t.T_parent_child = drive.T_lidar_imu;
    statics.push_back(t);
  }
  write("/tf_static", start_ns, EncodeTfMessage(statics));

  RosCameraInfo info;
  info.frame_id = kCameraFrame;
  info.width = static_cast<uint32_t>(drive.camera.image_width);
  info.height = static_cast<uint32_t>(drive.camera.image_height);
  info.distortion_model = "plumb_bob";
  info.d.assign(5, 0.0);
  info.K = drive.camera.P_rect_02.leftCols<3>();
  info.R = drive.camera.R_rect_00;
  info.P = drive.camera.P_rect_02;
  const double sweep_s = SweepDurationSeconds(drive);
  const OxtsOrigin origin = odometry ? OxtsOrigin{drive.oxts.front().lat, drive.oxts.front().lon,
                                                  drive.oxts.front().alt}
                                     : OxtsOrigin{};
  for (size_t i = 0; i < n; ++i) {
    if (odometry) {
      // As OxtsTrajectory reads a packet: its pose, its earth-parallel velocity in the world
      // (here carried in the body frame, as Odometry's twist is) and its body rates.
      const OxtsPacket& p = drive.oxts[i];
      RosOdometry o;
      o.stamp_ns = drive.oxts_stamps_ns[i];
      o.frame_id = kWorldFrame;
      o.child_frame_id = kImuFrame;
      const Rigid3d T_world_imu = OxtsPose(origin, p);
      o.position_m = T_world_imu.translation();
      o.orientation = Eigen::Quaterniond(T_world_imu.linear());
      const double c = std::cos(p.yaw), s = std::sin(p.yaw);
      const Eigen::Vector3d velocity_world(c * p.vf - s * p.vl, s * p.vf + c * p.vl, p.vu);
      o.linear_m_s = T_world_imu.linear().transpose() * velocity_world;
      o.angular_rad_s = Eigen::Vector3d(p.wx, p.wy, p.wz);
      write(kBagOdometryTopic, o.stamp_ns, EncodeOdometry(o));
      end_ns = std::max(end_ns, o.stamp_ns);
    }
    cv::Mat bgr;
    STCALIB_RETURN_IF_ERROR(drive.LoadImage(i, &bgr));
    RosImage image;
    image.stamp_ns = drive.camera_stamps_ns[i];
    image.frame_id = kCameraFrame;
    image.height = static_cast<uint32_t>(bgr.rows);
    image.width = static_cast<uint32_t>(bgr.cols);
    image.encoding = "bgr8";
    image.step = static_cast<uint32_t>(bgr.cols * 3);
    for (int r = 0; r < bgr.rows; ++r) {
      image.data.insert(image.data.end(), bgr.ptr<uint8_t>(r), bgr.ptr<uint8_t>(r) + image.step);
    }
    info.stamp_ns = image.stamp_ns;
    write(kBagCameraInfoTopic, image.stamp_ns, EncodeCameraInfo(info));
    write(kBagImageTopic, image.stamp_ns, EncodeImage(image));

    LidarScan scan;
    STCALIB_RETURN_IF_ERROR(drive.LoadScan(i, &scan));
    const ScanRings rings = scan.ring.empty() ? SplitIntoRings(scan.points_lidar)
                                              : RingsFromLabels(scan.points_lidar, scan.ring);
    const std::vector<double> times = scan.point_time_s.empty()
                                          ? PointTimesFromAzimuth(rings, sweep_s)
                                          : scan.point_time_s;
    write(kBagCloudTopic, drive.lidar_stamps_ns[i],
          EncodePointCloud2(MakeCloud(scan, rings.ring, times, drive.lidar_stamps_ns[i])));
    end_ns = std::max({end_ns, drive.camera_stamps_ns[i], drive.lidar_stamps_ns[i]});
  }
  STCALIB_RETURN_IF_ERROR(writer.Close());
  summary->frames = n;
  summary->messages = writer.messages_written();
  summary->odometry = odometry;

  std::ofstream metadata(bag_dir + "/metadata.yaml");
  metadata << MetadataYaml(mcap_name, types, counts, summary->messages, start_ns, end_ns);
  if (!metadata) return Status::Error(bag_dir + "/metadata.yaml: cannot write it");
  const std::string truth = drive.calib_dir + "/ground_truth.json";
  if (fs::exists(truth, ec)) {
    fs::copy_file(truth, bag_dir + "/ground_truth.json", fs::copy_options::overwrite_existing, ec);
    if (ec) return Status::Error(bag_dir + "/ground_truth.json: cannot copy it: " + ec.message());
  }
  return Status::Ok();
}

}  // namespace stcalib
