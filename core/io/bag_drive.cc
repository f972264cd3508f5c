#include "core/io/bag_drive.h"

#include <glog/logging.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <opencv2/imgcodecs.hpp>

#include "core/io/image.h"
#include "core/io/rosbag2.h"

namespace fs = std::filesystem;

namespace stcalib {
namespace {

// A message copied to the spool file.
struct Spooled {
  uint64_t offset = 0, size = 0;
  int64_t stamp_ns = 0;
  int64_t middle_ns = 0;  ///< a sweep's middle (its points' times), else the stamp
  size_t index = 0;       ///< its place among the topic's messages
};

std::string StampText(int64_t stamp_ns) {
  char text[48];
  std::snprintf(text, sizeof(text), "%lld.%09lld", static_cast<long long>(stamp_ns / 1000000000),
                static_cast<long long>(stamp_ns % 1000000000));
  return text;
}

class BagFrameStore : public FrameStore {
 public:
  BagFrameStore(std::string bag_dir, std::string spool_path, std::string image_topic,
                std::string cloud_topic, bool compressed)
      : bag_dir_(std::move(bag_dir)),
        spool_path_(std::move(spool_path)),
        image_topic_(std::move(image_topic)),
        cloud_topic_(std::move(cloud_topic)),
        compressed_(compressed) {}
  ~BagFrameStore() override {
    std::error_code ec;
    fs::remove(spool_path_, ec);
  }

  Status LoadImage(size_t frame, cv::Mat* image_bgr) const override {
    std::vector<uint8_t> cdr;
    const Spooled& m = images.at(frame);
    const std::string name = MessageName(image_topic_, m);
    STCALIB_RETURN_IF_ERROR(Read(m, name, &cdr));
    if (compressed_) {
      int64_t stamp_ns;
      STCALIB_RETURN_IF_ERROR(DecodeCompressedImage(cdr, &stamp_ns, image_bgr).WithContext(name));
    } else {
      RosImage image;
      STCALIB_RETURN_IF_ERROR(DecodeImage(cdr, &image).WithContext(name));
      STCALIB_RETURN_IF_ERROR(ImageToBgr(image, image_bgr).WithContext(name));
    }
    if (image_bgr->cols != width || image_bgr->rows != height) {
      return Status::Error(name + "is " + std::to_string(image_bgr->cols) + " × " +
                           std::to_string(image_bgr->rows) + " pixels, but the CameraInfo says " +
                           std::to_string(width) + " × " + std::to_string(height));
    }
    return Status::Ok();
  }

  Status LoadScan(size_t frame, LidarScan* scan) const override {
    std::vector<uint8_t> cdr;
    const Spooled& m = clouds.at(frame);
    const std::string name = MessageName(cloud_topic_, m);
    STCALIB_RETURN_IF_ERROR(Read(m, name, &cdr));
    RosPointCloud cloud;
    STCALIB_RETURN_IF_ERROR(DecodePointCloud2(cdr, &cloud).WithContext(name));
    cdr = std::vector<uint8_t>();
    CloudPoints points;
    STCALIB_RETURN_IF_ERROR(ExtractCloudPoints(cloud, &points).WithContext(name));
    *scan = ScanFromCloud(points, cloud.height);
    return Status::Ok();
  }

  std::string ScanName(size_t frame) const override {
    return MessageName(cloud_topic_, clouds.at(frame));
  }

  std::vector<Spooled> images, clouds;  ///< per frame
  int width = 0, height = 0;

 private:
  std::string MessageName(const std::string& topic, const Spooled& m) const {
    return bag_dir_ + ": " + topic + " message " + std::to_string(m.index) + " (stamp " +
           StampText(m.stamp_ns) + "): ";
  }
  Status Read(const Spooled& m, const std::string& name, std::vector<uint8_t>* cdr) const {
    std::ifstream in(spool_path_, std::ios::binary);
    cdr->resize(m.size);
    in.seekg(static_cast<std::streamoff>(m.offset));
    if (!in.read(reinterpret_cast<char*>(cdr->data()), static_cast<std::streamsize>(m.size))) {
      return Status::Error(name + "cannot read it back from " + spool_path_);
    }
    return Status::Ok();
  }

  std::string bag_dir_, spool_path_, image_topic_, cloud_topic_;
  bool compressed_;
};

// Beams of a spinning LiDAR lie at least this far apart in elevation (a VLP-16's 2°, an
// HDL-64E's and an OS1-64's 0.33–0.53°), and one beam's returns within it [deg].
constexpr double kRingGapDeg = 0.12;

std::string SpoolPath() {
  static std::atomic<int> counter{0};
  std::error_code ec;
  fs::path dir = fs::temp_directory_path(ec);
  if (ec) dir = ".";
  return (dir /
          ("stcalib-bag-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + ".spool"))
      .string();
}

// The pose of `source` in `target` through the bag's transforms (each usable both ways).
bool LookUpTransform(const std::vector<RosTransform>& transforms, const std::string& target,
                     const std::string& source, Rigid3d* T_target_source) {
  // Breadth-first from `source`: T_frame_source for every frame reached.
  std::map<std::string, Rigid3d, std::less<>> reached{{source, Rigid3d::Identity()}};
  std::deque<std::string> queue{source};
  while (!queue.empty()) {
    const std::string frame = queue.front();
    queue.pop_front();
    const Rigid3d T_frame_source = reached.at(frame);
    if (frame == target) {
      *T_target_source = T_frame_source;
      return true;
    }
    for (const RosTransform& t : transforms) {
      if (t.child_frame_id == frame && !reached.count(t.frame_id)) {
        reached[t.frame_id] = t.T_parent_child * T_frame_source;
        queue.push_back(t.frame_id);
      } else if (t.frame_id == frame && !reached.count(t.child_frame_id)) {
        reached[t.child_frame_id] = t.T_parent_child.inverse() * T_frame_source;
        queue.push_back(t.child_frame_id);
      }
    }
  }
  return false;
}

// The CameraInfo topic beside an image topic: "/ns/image_raw[/compressed]" → "/ns/camera_info".
std::string CameraInfoTopicFor(std::string image_topic) {
  const std::string compressed = "/compressed";
  if (image_topic.size() > compressed.size() &&
      image_topic.compare(image_topic.size() - compressed.size(), compressed.size(), compressed) ==
          0) {
    image_topic.resize(image_topic.size() - compressed.size());
  }
  const size_t slash = image_topic.rfind('/');
  return (slash == std::string::npos ? std::string() : image_topic.substr(0, slash)) +
         "/camera_info";
}

// Each point's ring by elevation: a new ring wherever the sorted elevations leave a gap wider
// than any one beam's spread; numbered from the top.
std::vector<int> RingsByElevation(const std::vector<Eigen::Vector3d>& points) {
  const size_t n = points.size();
  std::vector<double> elevation_deg(n);
  for (size_t i = 0; i < n; ++i) {
    elevation_deg[i] = std::atan2(points[i].z(), points[i].head<2>().norm()) * 180.0 / M_PI;
  }
  std::vector<size_t> by_elevation(n);
  std::iota(by_elevation.begin(), by_elevation.end(), 0);
  std::sort(by_elevation.begin(), by_elevation.end(),
            [&](size_t a, size_t b) { return elevation_deg[a] > elevation_deg[b]; });
  std::vector<int> ring(n, 0);
  int current = 0;
  for (size_t k = 1; k < n; ++k) {
    if (elevation_deg[by_elevation[k - 1]] - elevation_deg[by_elevation[k]] > kRingGapDeg) {
      ++current;
    }
    ring[by_elevation[k]] = current;
  }
  return ring;
}

}  // namespace

LidarScan ScanFromCloud(const CloudPoints& cloud, uint32_t rows) {
  const size_t n = cloud.points.size();
  std::vector<int> label;
  std::vector<double> azimuth_rad(n);
  for (size_t i = 0; i < n; ++i)
    azimuth_rad[i] = std::atan2(cloud.points[i].y(), cloud.points[i].x());
  auto azimuth = [&](size_t i) { return azimuth_rad[i]; };
  // Steps between consecutive points (of `order`, from `begin` to `end`) that turn
  // counter-clockwise (`up`) and clockwise (`down`).
  auto count_turns = [&](const std::vector<size_t>& order, size_t begin, size_t end, int* up,
                         int* down) {
    *up = *down = 0;
    for (size_t k = begin + 1; k < end; ++k) {
      const double step = std::remainder(azimuth(order[k]) - azimuth(order[k - 1]), 2 * M_PI);
      (step > 0 ? *up : *down) += step != 0;
    }
  };
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  if (!cloud.ring.empty()) {
    label.assign(cloud.ring.begin(), cloud.ring.end());
  } else if (rows > 1 && cloud.row.size() == n) {
    label.assign(cloud.row.begin(), cloud.row.end());
  } else {
    // No rings given. A cloud in KITTI's order (kitti2bag's) keeps it: its rings are split
    // where each laser's run ends, as KITTI's are. Any other order (a driver's firing order)
    // is grouped by elevation.
    int up = 0, down = 0;
    count_turns(order, 0, n, &up, &down);
    if (9 * down > up) label = RingsByElevation(cloud.points);
  }
  if (!label.empty()) {
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return label[a] < label[b]; });
    // Each ring in KITTI's order (counter-clockwise, azimuth growing): kept when it already runs
    // that way (KITTI's own sweeps), reversed when it runs clockwise (a spinning driver's firing
    // order), sorted by azimuth from straight ahead otherwise.
    for (size_t begin = 0; begin < n;) {
      size_t end = begin + 1;
      while (end < n && label[order[end]] == label[order[begin]]) ++end;
      int up = 0, down = 0;
      count_turns(order, begin, end, &up, &down);
      if (down > 9 * up) {
        std::reverse(order.begin() + begin, order.begin() + end);
      } else if (9 * down > up) {
        auto ahead = [&](size_t i) {
          const double a = azimuth(i);
          return a < 0 ? a + 2 * M_PI : a;
        };
        std::stable_sort(order.begin() + begin, order.begin() + end,
                         [&](size_t a, size_t b) { return ahead(a) < ahead(b); });
      }
      begin = end;
    }
  }
  LidarScan scan;
  scan.points_lidar.reserve(n);
  scan.reflectance.reserve(n);
  for (size_t i : order) {
    scan.points_lidar.push_back(cloud.points[i]);
    scan.reflectance.push_back(cloud.intensity.empty() ? 0.0f : cloud.intensity[i]);
    if (!label.empty()) scan.ring.push_back(static_cast<uint16_t>(label[i]));
    if (!cloud.time_s.empty()) scan.point_time_s.push_back(cloud.time_s[i]);
  }
  return scan;
}

Status CameraFromInfo(const RosCameraInfo& info, CameraCalibration* camera, RectifyMaps* maps) {
  *camera = CameraCalibration();
  camera->image_width = static_cast<int>(info.width);
  camera->image_height = static_cast<int>(info.height);
  if (info.width == 0 || info.height == 0) {
    return Status::Error("sensor_msgs/msg/CameraInfo: image size " + std::to_string(info.width) +
                         " × " + std::to_string(info.height));
  }
  camera->R_rect_00 = info.R.isZero() ? Eigen::Matrix3d::Identity() : info.R;
  camera->P_rect = info.P;
  if (info.P.isZero()) camera->P_rect.leftCols<3>() = info.K;
  if (!(camera->P_rect(0, 0) > 0 && camera->P_rect(1, 1) > 0)) {
    return Status::Error("sensor_msgs/msg/CameraInfo: P (and K) have no positive focal length");
  }
  const bool distorted =
      std::any_of(info.d.begin(), info.d.end(), [](double d) { return d != 0.0; });
  if (distorted) {
    camera->distortion_model = info.distortion_model;
    camera->K = info.K;
    camera->distortion = info.d;
  }
  return MakeRectifyMaps(*camera, maps).WithContext(std::string(kRosCameraInfoType) + ": ");
}

Status OpenBagDrive(const BagDriveOptions& options, Drive* drive) {
  *drive = Drive();
  const std::string& bag = options.bag_dir;
  if (options.image_topic.empty() || options.cloud_topic.empty()) {
    return Status::Error(bag + ": a bag needs --image_topic and --cloud_topic");
  }
  const std::string info_topic = options.camera_info_topic.empty()
                                     ? CameraInfoTopicFor(options.image_topic)
                                     : options.camera_info_topic;
  const std::string spool_path = SpoolPath();
  std::ofstream spool(spool_path, std::ios::binary | std::ios::trunc);
  if (!spool) return Status::Error(spool_path + ": cannot create the bag's spool file");

  std::vector<Spooled> images, clouds;
  bool have_info = false;
  RosCameraInfo info;
  std::string image_frame, cloud_frame;
  std::vector<RosTransform> transforms;
  std::vector<RosOdometry> odometry;
  std::vector<RosImu> imus;
  Status failure = Status::Ok();
  uint64_t spooled_bytes = 0;
  auto fail = [&](const BagMessage& m, const Status& status) {
    if (failure.ok()) {
      failure = status.WithContext(bag + ": " + m.topic->name + " (" + m.topic->type + "): ");
    }
  };
  auto spool_message = [&](const BagMessage& m, std::vector<Spooled>* list, std::string* frame) {
    Spooled s;
    const Status status = DecodeHeader(m.data, &s.stamp_ns, frame);
    if (!status.ok()) return fail(m, status);
    s.middle_ns = s.stamp_ns;
    s.offset = spooled_bytes;
    s.size = m.data.size();
    s.index = list->size();
    spool.write(reinterpret_cast<const char*>(m.data.data()),
                static_cast<std::streamsize>(m.data.size()));
    spooled_bytes += m.data.size();
    list->push_back(s);
  };
  BagSummary summary;
  const Status read = ReadRosbag2(
      bag,
      [&](const BagMessage& m) {
        if (!failure.ok()) return;
        const std::string& topic = m.topic->name;
        const std::string& type = m.topic->type;
        if (topic == options.image_topic) {
          if (type != kRosImageType && type != kRosCompressedImageType) {
            return fail(m, Status::Error(std::string("not an image type (") + kRosImageType + ", " +
                                         kRosCompressedImageType + ")"));
          }
          spool_message(m, &images, &image_frame);
        } else if (topic == options.cloud_topic) {
          if (type != kRosPointCloud2Type) {
            return fail(m, Status::Error(std::string("not a ") + kRosPointCloud2Type));
          }
          spool_message(m, &clouds, &cloud_frame);
          if (!failure.ok()) return;
          // The sweep's middle, from its points' times: drivers stamp the start or the end.
          RosPointCloud cloud;
          CloudPoints points;
          Status status = DecodePointCloud2(m.data, &cloud);
          if (status.ok()) status = ExtractCloudPoints(cloud, &points);
          if (!status.ok()) return fail(m, status);
          if (!points.time_s.empty()) {
            const auto [first, last] =
                std::minmax_element(points.time_s.begin(), points.time_s.end());
            clouds.back().middle_ns += std::llround(0.5e9 * (*first + *last));
          }
        } else if (topic == info_topic && !have_info) {
          if (type != kRosCameraInfoType)
            return fail(m, Status::Error(std::string("not a ") + kRosCameraInfoType));
          const Status status = DecodeCameraInfo(m.data, &info);
          if (!status.ok()) return fail(m, status);
          have_info = true;
        } else if (!options.odom_topic.empty() && topic == options.odom_topic) {
          if (type != kRosOdometryType) {
            return fail(m, Status::Error(std::string("not a ") + kRosOdometryType));
          }
          RosOdometry o;
          const Status status = DecodeOdometry(m.data, &o);
          if (!status.ok()) return fail(m, status);
          odometry.push_back(o);
        } else if (!options.imu_topic.empty() && topic == options.imu_topic) {
          if (type != kRosImuType)
            return fail(m, Status::Error(std::string("not a ") + kRosImuType));
          RosImu imu;
          const Status status = DecodeImu(m.data, &imu);
          if (!status.ok()) return fail(m, status);
          imus.push_back(imu);
        } else if (type == kRosTfMessageType && (topic == "/tf_static" || topic == "/tf")) {
          std::vector<RosTransform> t;
          const Status status = DecodeTfMessage(m.data, &t);
          if (!status.ok()) return fail(m, status);
          transforms.insert(transforms.end(), t.begin(), t.end());
        }
      },
      &summary);
  spool.close();
  auto cleanup = [&](Status status) {
    std::error_code ec;
    fs::remove(spool_path, ec);
    return status;
  };
  if (!read.ok()) return cleanup(read);
  if (!failure.ok()) return cleanup(failure);
  if (!spool) return cleanup(Status::Error(spool_path + ": writing the spool file failed"));
  if (!summary.stopped.empty()) {
    LOG(WARNING) << bag << ": " << summary.stopped << "; calibrating with what came before";
  }
  if (!options.imu_topic.empty() && !options.odom_topic.empty()) {
    return cleanup(Status::Error(bag + ": give --odom_topic or --imu_topic, not both"));
  }
  for (const std::string& topic : {options.image_topic, options.cloud_topic, info_topic,
                                   options.odom_topic, options.imu_topic}) {
    if (!topic.empty() && !summary.topics.count(topic)) {
      return cleanup(Status::Error(bag + ": no topic " + topic + " (" +
                                   (topic == info_topic && options.camera_info_topic.empty()
                                        ? "the image topic's CameraInfo; name another with "
                                          "--camera_info_topic"
                                        : "as asked") +
                                   "). The bag has:\n" + ListBagTopics(summary)));
    }
  }
  if (!have_info) return cleanup(Status::Error(bag + ": " + info_topic + " has no message"));
  if (clouds.empty() || images.empty()) {
    return cleanup(Status::Error(bag + ": " +
                                 (clouds.empty() ? options.cloud_topic : options.image_topic) +
                                 " has no message"));
  }

  // Frames: each sweep with the image nearest its middle, within half the sweep period; an image
  // serves the sweep nearest to it only.
  auto by_stamp = [](const Spooled& a, const Spooled& b) { return a.middle_ns < b.middle_ns; };
  std::stable_sort(images.begin(), images.end(), by_stamp);
  std::stable_sort(clouds.begin(), clouds.end(), by_stamp);
  std::vector<int64_t> periods;
  for (size_t k = 1; k < clouds.size(); ++k) {
    periods.push_back(clouds[k].middle_ns - clouds[k - 1].middle_ns);
  }
  int64_t period_ns = 100000000;
  if (!periods.empty()) {
    std::nth_element(periods.begin(), periods.begin() + periods.size() / 2, periods.end());
    period_ns = std::max<int64_t>(periods[periods.size() / 2], 1);
  }
  std::map<size_t, std::pair<int64_t, size_t>> best;  // image → (|Δt|, cloud)
  for (size_t c = 0; c < clouds.size(); ++c) {
    const auto it = std::lower_bound(images.begin(), images.end(), clouds[c], by_stamp);
    for (auto candidate : {it, it == images.begin() ? images.end() : std::prev(it)}) {
      if (candidate == images.end()) continue;
      const int64_t gap = std::llabs(candidate->middle_ns - clouds[c].middle_ns);
      const size_t i = static_cast<size_t>(candidate - images.begin());
      if (2 * gap > period_ns) continue;
      auto found = best.find(i);
      if (found == best.end() || gap < found->second.first) best[i] = {gap, c};
    }
  }
  std::map<size_t, size_t> frames;  // cloud → image (by cloud: time order)
  for (const auto& [image, pair] : best) {
    if (!frames.count(pair.second) || std::llabs(images[frames[pair.second]].middle_ns -
                                                 clouds[pair.second].middle_ns) > pair.first) {
      frames[pair.second] = image;
    }
  }
  if (frames.empty()) {
    return cleanup(Status::Error(bag + ": no image of " + options.image_topic +
                                 " lies within half a sweep period of a sweep of " +
                                 options.cloud_topic));
  }

  auto store = std::make_shared<BagFrameStore>(
      bag, spool_path, options.image_topic, options.cloud_topic,
      summary.topics.at(options.image_topic).type == kRosCompressedImageType);
  drive->drive_dir = bag;
  drive->calib_dir = bag;
  for (const auto& [cloud, image] : frames) {
    char name[16];
    std::snprintf(name, sizeof(name), "%010zu", drive->frame_names.size());
    drive->frame_names.push_back(name);
    drive->lidar_stamps_ns.push_back(clouds[cloud].stamp_ns);
    drive->camera_stamps_ns.push_back(images[image].stamp_ns);
    store->clouds.push_back(clouds[cloud]);
    store->images.push_back(images[image]);
  }
  STCALIB_RETURN_IF_ERROR(CameraFromInfo(info, &drive->camera, &drive->rectify)
                              .WithContext(bag + ": " + info_topic + ": "));
  store->width = drive->camera.image_width;
  store->height = drive->camera.image_height;

  const std::string camera_frame = info.frame_id.empty() ? image_frame : info.frame_id;
  if (!LookUpTransform(transforms, camera_frame, cloud_frame, &drive->T_camera_lidar) &&
      options.require_tf_extrinsic) {
    return Status::Error(bag + ": no transform between the camera frame \"" + camera_frame +
                         "\" and the LiDAR frame \"" + cloud_frame +
                         "\" in /tf_static or /tf: give the start with --init_calib");
  }
  // The odometry's (or IMU's) frame in the LiDAR's, which carries its motion to the LiDAR.
  auto place_body = [&](const std::string& topic, const std::string& frame) -> Status {
    if (!LookUpTransform(transforms, cloud_frame, frame, &drive->T_lidar_imu)) {
      return Status::Error(bag + ": " + topic + ": no transform between its frame \"" + frame +
                           "\" and the LiDAR frame \"" + cloud_frame + "\" in /tf_static or /tf");
    }
    drive->has_imu_calibration = true;
    return Status::Ok();
  };
  if (!odometry.empty()) {
    STCALIB_RETURN_IF_ERROR(place_body(options.odom_topic, odometry.front().child_frame_id));
    for (const RosOdometry& o : odometry) {
      OdometrySample s;
      s.stamp_ns = o.stamp_ns;
      s.T_world_body.linear() = o.orientation.normalized().toRotationMatrix();
      s.T_world_body.translation() = o.position_m;
      s.velocity_world_m_s = s.T_world_body.linear() * o.linear_m_s;
      s.rate_body_rad_s = o.angular_rad_s;
      drive->odometry.push_back(s);
    }
  }
  if (!imus.empty()) {
    STCALIB_RETURN_IF_ERROR(place_body(options.imu_topic, imus.front().frame_id));
    for (const RosImu& imu : imus) {
      if (!imu.angular_velocity_rad_s.allFinite()) {
        return Status::Error(bag + ": " + options.imu_topic + " message at " +
                             StampText(imu.stamp_ns) + ": angular velocity is not finite");
      }
      drive->imu.push_back({imu.stamp_ns, imu.angular_velocity_rad_s});
    }
    std::stable_sort(
        drive->imu.begin(), drive->imu.end(),
        [](const ImuSample& a, const ImuSample& b) { return a.stamp_ns < b.stamp_ns; });
  }
  drive->store = std::move(store);
  LOG(INFO) << bag << ": " << drive->NumFrames() << " frames from " << clouds.size()
            << " sweeps and " << images.size() << " images";
  return Status::Ok();
}

}  // namespace stcalib
