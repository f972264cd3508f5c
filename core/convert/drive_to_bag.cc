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

void Put(uint8_t* p, const void* value, size_t n) { std::memcpy(p, value, n); }

// One sweep's cloud in `layout`. `time_s` is each point's capture time from `stamp_ns` (the
// drive's LiDAR stamp, mid-sweep for KITTI); the layouts that stamp the start move the stamp to
// the sweep's first instant, `sweep_s` before its end, and their times with it.
RosPointCloud MakeCloud(const LidarScan& scan, const ScanRings& rings,
                        const std::vector<double>& time_s, int64_t stamp_ns, double sweep_s,
                        CloudLayout layout) {
  RosPointCloud cloud;
  cloud.frame_id = kLidarFrame;
  const size_t n = scan.size();
  const int num_rings = rings.num_rings();
  auto xyz = [&](size_t i, uint8_t* p) {
    const float v[3] = {static_cast<float>(scan.points_lidar[i].x()),
                        static_cast<float>(scan.points_lidar[i].y()),
                        static_cast<float>(scan.points_lidar[i].z())};
    Put(p, v, sizeof(v));
  };
  auto intensity = [&](size_t i) { return scan.reflectance.empty() ? 0.0f : scan.reflectance[i]; };
  // Stamped at the sweep's start (Velodyne's and Ouster's drivers): the first instant of the
  // spin, half a sweep before the stamp, which KITTI's layout puts where the head faces forward.
  const int64_t start_ns =
      layout == CloudLayout::kKitti ? stamp_ns : stamp_ns - std::llround(0.5e9 * sweep_s);
  const double shift_s = 1e-9 * static_cast<double>(stamp_ns - start_ns);
  cloud.stamp_ns = start_ns;
  if (layout != CloudLayout::kOuster) {
    // Unorganized: x y z intensity (float32) and ring (uint16), then the time, KITTI's in
    // float64 seconds in its point order, Velodyne's in float32 in firing order (by capture
    // time, the beams of one firing from the lowest up; ring 0 the lowest beam).
    const bool kitti = layout == CloudLayout::kKitti;
    std::vector<size_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = i;
    if (!kitti) {
      std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        if (time_s[a] != time_s[b]) return time_s[a] < time_s[b];
        return rings.elevation_rank[rings.ring[a]] > rings.elevation_rank[rings.ring[b]];
      });
    }
    cloud.height = 1;
    cloud.width = static_cast<uint32_t>(n);
    cloud.fields = {{"x", 0, 7, 1},     {"y", 4, 7, 1},
                    {"z", 8, 7, 1},     {"intensity", 12, 7, 1},
                    {"ring", 16, 4, 1}, {"time", kitti ? 24u : 18u, uint8_t(kitti ? 8 : 7), 1}};
    cloud.point_step = kitti ? 32 : 22;
    cloud.data.assign(n * cloud.point_step, 0);
    for (size_t k = 0; k < n; ++k) {
      const size_t i = order[k];
      uint8_t* p = cloud.data.data() + k * cloud.point_step;
      const float value = intensity(i);
      const uint16_t ring =
          kitti ? rings.ring[i]
                : static_cast<uint16_t>(num_rings - 1 - rings.elevation_rank[rings.ring[i]]);
      xyz(i, p);
      Put(p + 12, &value, 4);
      Put(p + 16, &ring, 2);
      if (kitti) {
        Put(p + 24, &time_s[i], 8);
      } else {
        const float time = static_cast<float>(time_s[i] + shift_s);
        Put(p + 18, &time, 4);
      }
    }
  } else {
    // A row per beam (top first), a column per firing in spin order (clockwise: the azimuth
    // falls from +π), as the sensor's fixed azimuth steps give them.
    const int columns = rings.azimuth_step_rad > 0
                            ? static_cast<int>(std::lround(2 * M_PI / rings.azimuth_step_rad))
                            : 1024;
    cloud.height = static_cast<uint32_t>(num_rings);
    cloud.width = static_cast<uint32_t>(columns);
    cloud.fields = {{"x", 0, 7, 1},          {"y", 4, 7, 1},        {"z", 8, 7, 1},
                    {"intensity", 16, 7, 1}, {"t", 20, 6, 1},       {"reflectivity", 24, 4, 1},
                    {"ring", 26, 4, 1},      {"ambient", 28, 4, 1}, {"range", 32, 6, 1}};
    cloud.point_step = 48;
    cloud.data.assign(size_t{cloud.height} * cloud.width * cloud.point_step, 0);
    for (size_t i = 0; i < n; ++i) {
      const int row = rings.elevation_rank[rings.ring[i]];
      const double fraction = (M_PI - rings.azimuth_rad[i]) / (2 * M_PI);
      const int column = std::clamp(static_cast<int>(fraction * columns), 0, columns - 1);
      uint8_t* p =
          cloud.data.data() + (static_cast<size_t>(row) * columns + column) * cloud.point_step;
      uint32_t range_mm;
      std::memcpy(&range_mm, p + 32, 4);
      if (range_mm != 0) continue;  // a second return in one cell: the first stays
      const float value = intensity(i) * 255.0f;
      const uint32_t t_ns =
          static_cast<uint32_t>(std::max<int64_t>(0, std::llround(1e9 * (time_s[i] + shift_s))));
      const uint16_t reflectivity = static_cast<uint16_t>(value), ring = static_cast<uint16_t>(row);
      range_mm = std::max<uint32_t>(1, static_cast<uint32_t>(1000 * scan.points_lidar[i].norm()));
      xyz(i, p);
      Put(p + 16, &value, 4);
      Put(p + 20, &t_ns, 4);
      Put(p + 24, &reflectivity, 2);
      Put(p + 26, &ring, 2);
      Put(p + 32, &range_mm, 4);
    }
  }
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.dense = layout != CloudLayout::kOuster;
  return cloud;
}

// The YAML rosbag2 writes beside its storage files (the fields `ros2 bag info` reads).
std::string MetadataYaml(const std::string& mcap_name,
                         const std::map<std::string, std::string>& types,
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

CloudLayout CloudLayoutForLidar(const std::string& lidar_name) {
  if (lidar_name == "vlp16") return CloudLayout::kVelodyne;
  if (lidar_name == "os1-64") return CloudLayout::kOuster;
  return CloudLayout::kKitti;
}

Status WriteDriveAsBag(const Drive& drive, const std::string& bag_dir, CloudLayout layout,
                       DriveToBagSummary* summary) {
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
  channel("/tf_static", kRosTfMessageType);
  channel(kBagImageTopic, kRosImageType);
  channel(kBagCameraInfoTopic, kRosCameraInfoType);
  channel(kBagCloudTopic, kRosPointCloud2Type);
  if (odometry) channel(kBagOdometryTopic, kRosOdometryType);
  if (odometry) channel(kBagImuTopic, kRosImuType);

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
  info.K = drive.camera.P_rect.leftCols<3>();
  if (!drive.camera.distortion_model.empty()) {  // raw images: their model goes with them
    info.distortion_model = drive.camera.distortion_model;
    info.d = drive.camera.distortion;
    info.K = drive.camera.K;
  }
  info.R = drive.camera.R_rect_00;
  info.P = drive.camera.P_rect;
  const double sweep_s = SweepDurationSeconds(drive);
  const OxtsOrigin origin =
      odometry ? OxtsOrigin{drive.oxts.front().lat, drive.oxts.front().lon, drive.oxts.front().alt}
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
      RosImu imu;
      imu.stamp_ns = o.stamp_ns;
      imu.frame_id = kImuFrame;
      imu.orientation = o.orientation;
      imu.angular_velocity_rad_s = o.angular_rad_s;
      imu.linear_acceleration_m_s2 = Eigen::Vector3d(p.ax, p.ay, p.az);
      write(kBagImuTopic, imu.stamp_ns, EncodeImu(imu));
      end_ns = std::max(end_ns, o.stamp_ns);
    }
    cv::Mat bgr;
    STCALIB_RETURN_IF_ERROR(drive.LoadRawImage(i, &bgr));
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
    const std::vector<double> times =
        scan.point_time_s.empty() ? PointTimesFromAzimuth(rings, sweep_s) : scan.point_time_s;
    const RosPointCloud cloud =
        MakeCloud(scan, rings, times, drive.lidar_stamps_ns[i], sweep_s, layout);
    write(kBagCloudTopic, cloud.stamp_ns, EncodePointCloud2(cloud));
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
