// A drive written as a ROS 2 bag (core/convert/drive_to_bag.h) and read back as one
// (core/io/bag_drive.h): the same frames, stamps, camera, extrinsic, motion and sweeps.
#include "core/io/bag_drive.h"

#include <glog/logging.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/convert/drive_to_bag.h"
#include "core/features/lidar_rings.h"
#include "core/io/image.h"
#include "core/io/mcap.h"
#include "core/io/ros_messages.h"
#include "core/motion/drive_motion.h"
#include "core/sim/simulator.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

using testing::ScopedTempDir;

BagDriveOptions ConvertedBagOptions(const std::string& bag_dir, bool odometry) {
  BagDriveOptions options;
  options.bag_dir = bag_dir;
  options.image_topic = kBagImageTopic;
  options.cloud_topic = kBagCloudTopic;
  if (odometry) options.odom_topic = kBagOdometryTopic;
  return options;
}

// Each point's capture time since the drive's reference stamp, keyed by its float coordinates
// (what a bag cloud stores).
std::map<std::array<float, 3>, double> CaptureTimes(const LidarScan& scan,
                                                    const std::vector<double>& time_s,
                                                    StampNs stamp_ns, StampNs reference_ns) {
  std::map<std::array<float, 3>, double> times;
  for (size_t i = 0; i < scan.size(); ++i) {
    const Eigen::Vector3f p = scan.points_lidar[i].cast<float>();
    times[{p.x(), p.y(), p.z()}] = NsToSeconds(stamp_ns - reference_ns) + time_s[i];
  }
  return times;
}

TEST(BagDrive, KittiThroughTheBagIsTheSameDrive) {
  STCALIB_REQUIRE_KITTI();
  Drive kitti;
  ASSERT_TRUE(testing::OpenKittiDrive(&kitti));
  ScopedTempDir tmp;
  const std::string bag_dir = tmp.path() + "/bag";
  DriveToBagSummary summary;
  const Status written = WriteDriveAsBag(kitti, bag_dir, CloudLayout::kKitti, &summary);
  ASSERT_TRUE(written.ok()) << written.message();
  EXPECT_EQ(summary.frames, kitti.NumFrames());
  EXPECT_TRUE(summary.odometry);

  Drive bag;
  const Status opened = OpenBagDrive(ConvertedBagOptions(bag_dir, true), &bag);
  ASSERT_TRUE(opened.ok()) << opened.message();
  ASSERT_EQ(bag.NumFrames(), kitti.NumFrames());
  EXPECT_EQ(bag.camera_stamps_ns, kitti.camera_stamps_ns);
  EXPECT_EQ(bag.lidar_stamps_ns, kitti.lidar_stamps_ns);
  EXPECT_TRUE(bag.camera.P_rect.isApprox(kitti.camera.P_rect, 1e-15));
  EXPECT_TRUE(bag.camera.R_rect_00.isApprox(kitti.camera.R_rect_00, 1e-15));
  EXPECT_EQ(bag.camera.image_width, kitti.camera.image_width);
  EXPECT_TRUE(bag.camera.distortion_model.empty());
  EXPECT_LT((bag.T_camera_lidar.matrix() - kitti.T_camera_lidar.matrix()).cwiseAbs().maxCoeff(),
            1e-12);
  EXPECT_LT((bag.T_lidar_imu.matrix() - kitti.T_lidar_imu.matrix()).cwiseAbs().maxCoeff(), 1e-12);

  const size_t frame = 7;
  cv::Mat kitti_image, bag_image;
  ASSERT_TRUE(kitti.LoadImage(frame, &kitti_image).ok());
  ASSERT_TRUE(bag.LoadImage(frame, &bag_image).ok());
  EXPECT_EQ(cv::norm(kitti_image, bag_image, cv::NORM_INF), 0.0);

  // The sweep: the same points in the same order, with the rings and times KITTI's derive.
  LidarScan kitti_scan, bag_scan;
  ASSERT_TRUE(kitti.LoadScan(frame, &kitti_scan).ok());
  ASSERT_TRUE(bag.LoadScan(frame, &bag_scan).ok());
  ASSERT_EQ(bag_scan.size(), kitti_scan.size());
  EXPECT_EQ(bag_scan.points_lidar, kitti_scan.points_lidar);
  EXPECT_EQ(bag_scan.reflectance, kitti_scan.reflectance);
  const ScanRings rings = SplitIntoRings(kitti_scan.points_lidar);
  EXPECT_EQ(bag_scan.ring, rings.ring);
  EXPECT_EQ(bag_scan.point_time_s, PointTimesFromAzimuth(rings, SweepDurationSeconds(kitti)));

  // The motion: odometry from the oxts gives the oxts' LiDAR poses.
  DriveMotion kitti_motion, bag_motion;
  ASSERT_TRUE(DriveMotion::CreateForDrive(kitti, &kitti_motion).ok());
  ASSERT_TRUE(DriveMotion::CreateForDrive(bag, &bag_motion).ok());
  EXPECT_EQ(bag_motion.source(), DriveMotion::Source::kOdometry);
  for (size_t i = 0; i < kitti.NumFrames(); i += 5) {
    const double t = kitti_motion.Seconds(kitti.camera_stamps_ns[i]) + 0.03;
    const Rigid3d a = kitti_motion.T_world_lidar(t), b = bag_motion.T_world_lidar(t);
    EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), 1e-9) << "frame " << i;
  }
}

// Without odometry the sweeps are registered; the IMU's rates then shape the rotation between
// them. Against the oxts trajectory, the LiDAR's rotation over 50 ms inside each segment (as the
// de-skew and the motion model read it) is closer to it with the IMU than with a constant
// velocity.
TEST(BagDrive, ImuRatesShapeTheRotationBetweenRegisteredSweeps) {
  STCALIB_REQUIRE_KITTI();
  Drive kitti;
  DriveMotion oxts;
  ASSERT_TRUE(testing::OpenKittiDrive(&kitti, &oxts));
  ScopedTempDir tmp;
  const std::string bag_dir = tmp.path() + "/bag";
  DriveToBagSummary summary;
  ASSERT_TRUE(WriteDriveAsBag(kitti, bag_dir, CloudLayout::kKitti, &summary).ok());
  BagDriveOptions options = ConvertedBagOptions(bag_dir, false);
  Drive plain, with_imu;
  ASSERT_TRUE(OpenBagDrive(options, &plain).ok());
  options.imu_topic = kBagImuTopic;
  ASSERT_TRUE(OpenBagDrive(options, &with_imu).ok());
  ASSERT_EQ(with_imu.imu.size(), kitti.NumFrames());
  options.odom_topic = kBagOdometryTopic;
  EXPECT_THAT(OpenBagDrive(options, &plain).message(), ::testing::HasSubstr("not both"));
  options.odom_topic.clear();
  options.imu_topic.clear();
  ASSERT_TRUE(OpenBagDrive(options, &plain).ok());

  DriveMotion scans, scans_imu;
  ASSERT_TRUE(DriveMotion::CreateForDrive(plain, &scans).ok());
  ASSERT_TRUE(DriveMotion::CreateForDrive(with_imu, &scans_imu).ok());
  EXPECT_STREQ(scans.SourceName(), "scan_registration");
  EXPECT_STREQ(scans_imu.SourceName(), "scan_registration_imu");
  double plain_sum = 0, imu_sum = 0;
  for (size_t i = 0; i + 1 < kitti.NumFrames(); ++i) {
    const StampNs a = kitti.lidar_stamps_ns[i] + 25000000, b = a + 50000000;
    auto rotation = [&](const DriveMotion& m) {
      const Rigid3d T_a = m.T_world_lidar(m.Seconds(a)), T_b = m.T_world_lidar(m.Seconds(b));
      return Eigen::Matrix3d(T_a.linear().transpose() * T_b.linear());
    };
    const Eigen::Matrix3d truth = rotation(oxts);
    plain_sum += LogSO3(truth.transpose() * rotation(scans)).norm();
    imu_sum += LogSO3(truth.transpose() * rotation(scans_imu)).norm();
  }
  const double n = static_cast<double>(kitti.NumFrames() - 1);
  LOG(INFO) << "mean rotation error over 50 ms: constant velocity " << plain_sum / n * 180 / M_PI
            << " deg, IMU " << imu_sum / n * 180 / M_PI << " deg";
  EXPECT_LT(imu_sum, plain_sum);
}

// A short simulated drive with a sparse LiDAR and a distorted camera, converted in each driver's
// layout: every layout carries the drive's points, each at its own capture time, grouped by ring
// in KITTI's order, and the raw images with the model that rectifies them as the drive does.
class SimulatedLayouts : public ::testing::TestWithParam<std::pair<sim::SimLidar, CloudLayout>> {};

TEST_P(SimulatedLayouts, CarryTheDrivesSweepsAndImages) {
  ScopedTempDir tmp;
  sim::SimulatorOptions options;
  options.frames = 3;
  options.seed = 7;
  options.time_offset_s = 0.03;
  options.lidar = GetParam().first;
  options.distortion_k1 = -0.3;
  std::string drive_dir;
  ASSERT_TRUE(sim::WriteSimulatedDrive(options, tmp.path() + "/sim", &drive_dir).ok());
  Drive drive;
  ASSERT_TRUE(OpenDrive(drive_dir, "", &drive).ok());
  ASSERT_EQ(drive.camera.distortion_model, "plumb_bob");
  const std::string bag_dir = tmp.path() + "/bag";
  DriveToBagSummary summary;
  ASSERT_TRUE(WriteDriveAsBag(drive, bag_dir, GetParam().second, &summary).ok());
  Drive bag;
  const Status opened = OpenBagDrive(ConvertedBagOptions(bag_dir, true), &bag);
  ASSERT_TRUE(opened.ok()) << opened.message();
  ASSERT_EQ(bag.NumFrames(), drive.NumFrames());
  EXPECT_EQ(bag.camera_stamps_ns, drive.camera_stamps_ns);
  EXPECT_TRUE(std::filesystem::exists(bag_dir + "/ground_truth.json"));

  const size_t frame = 1;
  for (const bool raw : {true, false}) {
    cv::Mat a, b;
    ASSERT_TRUE((raw ? drive.LoadRawImage(frame, &a) : drive.LoadImage(frame, &a)).ok());
    ASSERT_TRUE((raw ? bag.LoadRawImage(frame, &b) : bag.LoadImage(frame, &b)).ok());
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << (raw ? "raw" : "rectified");
  }

  LidarScan drive_scan, bag_scan;
  ASSERT_TRUE(drive.LoadScan(frame, &drive_scan).ok());
  ASSERT_TRUE(bag.LoadScan(frame, &bag_scan).ok());
  const ScanRings drive_rings = SplitIntoRings(drive_scan.points_lidar);
  const auto drive_times =
      CaptureTimes(drive_scan, PointTimesFromAzimuth(drive_rings, SweepDurationSeconds(drive)),
                   drive.lidar_stamps_ns[frame], drive.lidar_stamps_ns[0]);
  ASSERT_EQ(bag_scan.size(), drive_scan.size());
  ASSERT_EQ(bag_scan.point_time_s.size(), bag_scan.size());
  ASSERT_EQ(bag_scan.ring.size(), bag_scan.size());
  const ScanRings bag_rings = RingsFromLabels(bag_scan.points_lidar, bag_scan.ring);
  EXPECT_EQ(bag_rings.num_rings(), drive_rings.num_rings());
  const auto bag_times = CaptureTimes(bag_scan, bag_scan.point_time_s, bag.lidar_stamps_ns[frame],
                                      drive.lidar_stamps_ns[0]);
  ASSERT_EQ(bag_times.size(), drive_times.size());
  double worst_s = 0;
  for (const auto& [point, t] : drive_times) {
    const auto it = bag_times.find(point);
    ASSERT_NE(it, bag_times.end());
    worst_s = std::max(worst_s, std::abs(it->second - t));
  }
  EXPECT_LT(worst_s, 1e-6);  // float32 seconds or integer nanoseconds from the sweep's start
  // Each ring in KITTI's order: the azimuth grows from one point to the next.
  int up = 0, down = 0;
  for (int r = 0; r < bag_rings.num_rings(); ++r) {
    for (int i = bag_rings.ring_begin[r] + 1; i < bag_rings.ring_begin[r + 1]; ++i) {
      const double step =
          WrappedAzimuthStep(bag_rings.azimuth_rad[i - 1], bag_rings.azimuth_rad[i]);
      (step > 0 ? up : down)++;
    }
  }
  EXPECT_GT(up, 99 * down);
  EXPECT_NEAR(bag_rings.azimuth_step_rad, drive_rings.azimuth_step_rad, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Lidars, SimulatedLayouts,
                         ::testing::Values(std::pair{sim::SimLidar::kVlp16, CloudLayout::kVelodyne},
                                           std::pair{sim::SimLidar::kOs1_64, CloudLayout::kOuster},
                                           std::pair{sim::SimLidar::kVlp16, CloudLayout::kKitti}));

// A one-frame bag written here: CompressedImage, a CameraInfo, and a cloud without ring or time
// fields, organized in rows; `with_tf` adds the camera–LiDAR transform.
void WriteTinyBag(const std::string& dir, bool with_tf) {
  std::filesystem::create_directories(dir);
  McapWriter writer;
  ASSERT_TRUE(writer.Open(dir + "/tiny.mcap").ok());
  auto channel = [&](const std::string& type, const std::string& topic) {
    return writer.AddChannel(writer.AddSchema(type, Ros2MsgDefinition(type)), topic);
  };
  const uint16_t image = channel("sensor_msgs/msg/CompressedImage", "/cam/image/compressed");
  const uint16_t info = channel("sensor_msgs/msg/CameraInfo", "/cam/camera_info");
  const uint16_t cloud_channel = channel("sensor_msgs/msg/PointCloud2", "/points");
  const uint16_t tf = channel("tf2_msgs/msg/TFMessage", "/tf_static");
  const int64_t stamp = 1700000000123456789;
  // CompressedImage by hand: header, format, data.
  cv::Mat picture(40, 60, CV_8UC3, cv::Scalar(10, 200, 30));
  std::vector<uint8_t> png;
  cv::imencode(".png", picture, png);
  std::vector<uint8_t> cdr = {0, 1, 0, 0};
  auto put32 = [&](uint32_t v) {
    while ((cdr.size() - 4) % 4) cdr.push_back(0);
    for (int k = 0; k < 4; ++k) cdr.push_back(static_cast<uint8_t>(v >> (8 * k)));
  };
  auto put_string = [&](const std::string& s) {
    put32(static_cast<uint32_t>(s.size() + 1));
    cdr.insert(cdr.end(), s.begin(), s.end());
    cdr.push_back(0);
  };
  put32(static_cast<uint32_t>(stamp / 1000000000));
  put32(static_cast<uint32_t>(stamp % 1000000000));
  put_string("cam_optical");
  put_string("png");
  put32(static_cast<uint32_t>(png.size()));
  cdr.insert(cdr.end(), png.begin(), png.end());
  writer.Write(image, stamp, cdr);

  RosCameraInfo camera;
  camera.stamp_ns = stamp;
  camera.frame_id = "cam_optical";
  camera.width = 60;
  camera.height = 40;
  camera.distortion_model = "plumb_bob";
  camera.d.assign(5, 0.0);
  camera.K << 50, 0, 30, 0, 50, 20, 0, 0, 1;
  camera.R.setIdentity();
  camera.P.leftCols<3>() = camera.K;
  writer.Write(info, stamp, EncodeCameraInfo(camera));

  RosPointCloud cloud;
  cloud.stamp_ns = stamp;
  cloud.frame_id = "lidar_link";
  cloud.height = 2;
  cloud.width = 3;
  cloud.fields = {{"x", 0, 7, 1}, {"y", 4, 7, 1}, {"z", 8, 7, 1}};
  cloud.point_step = 12;
  cloud.row_step = 36;
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 3; ++c) {
      const float p[3] = {10.0f, 1.0f - c, r == 0 ? 1.0f : -1.0f};  // azimuth falls along a row
      const uint8_t* bytes = reinterpret_cast<const uint8_t*>(p);
      cloud.data.insert(cloud.data.end(), bytes, bytes + sizeof(p));
    }
  }
  writer.Write(cloud_channel, stamp, EncodePointCloud2(cloud));
  if (with_tf) {
    RosTransform t;
    t.frame_id = "lidar_link";  // given the other way round: lidar ← camera
    t.child_frame_id = "cam_optical";
    t.T_parent_child.translation() = Eigen::Vector3d(0.1, 0.2, 0.3);
    writer.Write(tf, stamp, EncodeTfMessage({t}));
  }
  ASSERT_TRUE(writer.Close().ok());
}

TEST(BagDrive, ReadsCompressedImagesOrganizedCloudsAndTfEitherWay) {
  ScopedTempDir tmp;
  WriteTinyBag(tmp.path(), /*with_tf=*/true);
  BagDriveOptions options;
  options.bag_dir = tmp.path();
  options.image_topic = "/cam/image/compressed";  // its CameraInfo: /cam/camera_info
  options.cloud_topic = "/points";
  Drive drive;
  const Status opened = OpenBagDrive(options, &drive);
  ASSERT_TRUE(opened.ok()) << opened.message();
  ASSERT_EQ(drive.NumFrames(), 1u);
  EXPECT_TRUE(drive.T_camera_lidar.translation().isApprox(Eigen::Vector3d(-0.1, -0.2, -0.3)));
  cv::Mat image;
  ASSERT_TRUE(drive.LoadImage(0, &image).ok());
  EXPECT_EQ(image.at<cv::Vec3b>(5, 5), cv::Vec3b(10, 200, 30));
  LidarScan scan;
  ASSERT_TRUE(drive.LoadScan(0, &scan).ok());
  // The rows are the rings; each row, written clockwise, comes back counter-clockwise.
  EXPECT_EQ(scan.ring, (std::vector<uint16_t>{0, 0, 0, 1, 1, 1}));
  EXPECT_FLOAT_EQ(scan.points_lidar[0].y(), -1.0f);
  EXPECT_FLOAT_EQ(scan.points_lidar[2].y(), 1.0f);
  EXPECT_TRUE(scan.point_time_s.empty());  // no time field: the features time by azimuth
}

TEST(BagDrive, BadBagsAreNamed) {
  ScopedTempDir tmp;
  WriteTinyBag(tmp.path() + "/no_tf", /*with_tf=*/false);
  BagDriveOptions options;
  options.bag_dir = tmp.path() + "/no_tf";
  options.image_topic = "/cam/image/compressed";
  options.cloud_topic = "/points";
  Drive drive;
  Status status = OpenBagDrive(options, &drive);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::HasSubstr("\"cam_optical\""));
  EXPECT_THAT(status.message(), ::testing::HasSubstr("--init_calib"));
  options.require_tf_extrinsic = false;  // the start comes from --init_calib
  EXPECT_TRUE(OpenBagDrive(options, &drive).ok());

  options.cloud_topic = "/lidar";
  status = OpenBagDrive(options, &drive);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::HasSubstr("no topic /lidar"));
  EXPECT_THAT(status.message(), ::testing::HasSubstr("/points  [sensor_msgs/msg/PointCloud2]"));

  options.cloud_topic = "/cam/camera_info";
  status = OpenBagDrive(options, &drive);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(),
              ::testing::HasSubstr("/cam/camera_info (sensor_msgs/msg/CameraInfo): not a "
                                   "sensor_msgs/msg/PointCloud2"));

  // Cut short inside the cloud, the last message: what came before the cut is read (the image
  // and its CameraInfo), and the cloud topic has nothing. The closing records and magic are 50
  // bytes.
  options.cloud_topic = "/points";
  const std::string mcap = tmp.path() + "/no_tf/tiny.mcap";
  std::filesystem::resize_file(mcap, std::filesystem::file_size(mcap) - 60);
  status = OpenBagDrive(options, &drive);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::HasSubstr("/points has no message"));
}

// A cloud without ring and time fields: in a driver's firing order its rings come from the
// elevations (each the simulated beam's returns, in KITTI's order); in KITTI's order (as
// kitti2bag writes KITTI's sweeps) it keeps that order for KITTI's ring split.
TEST(BagDrive, RingsOfACloudWithoutThemComeFromItsOrderOrItsElevations) {
  sim::SimulatorOptions options;
  options.frames = 1;
  options.lidar = sim::SimLidar::kVlp16;
  const sim::Simulator simulator(options);
  const sim::SimulatedSweep sweep = simulator.SimulateSweep(0);
  CloudPoints kitti_order;
  kitti_order.points = sweep.scan.points_lidar;
  const LidarScan kept = ScanFromCloud(kitti_order, 1);
  EXPECT_TRUE(kept.ring.empty());
  EXPECT_EQ(kept.points_lidar, sweep.scan.points_lidar);

  // Firing order: by capture time, then beam.
  std::vector<size_t> firing(sweep.scan.size());
  for (size_t i = 0; i < firing.size(); ++i) firing[i] = i;
  std::stable_sort(firing.begin(), firing.end(), [&](size_t a, size_t b) {
    return sweep.point_time_s[a] < sweep.point_time_s[b];
  });
  CloudPoints fired;
  std::map<std::array<float, 3>, uint16_t> beam_of;
  for (size_t i : firing) {
    fired.points.push_back(sweep.scan.points_lidar[i]);
    const Eigen::Vector3f p = sweep.scan.points_lidar[i].cast<float>();
    beam_of[{p.x(), p.y(), p.z()}] = sweep.ring[i];
  }
  const LidarScan grouped = ScanFromCloud(fired, 1);
  ASSERT_EQ(grouped.ring.size(), grouped.size());
  const ScanRings rings = RingsFromLabels(grouped.points_lidar, grouped.ring);
  EXPECT_EQ(rings.num_rings(), 16);
  for (int r = 0; r < rings.num_rings(); ++r) {
    const int begin = rings.ring_begin[r], end = rings.ring_begin[r + 1];
    auto beam = [&](int i) {
      const Eigen::Vector3f p = grouped.points_lidar[i].cast<float>();
      return beam_of.at({p.x(), p.y(), p.z()});
    };
    for (int i = begin + 1; i < end; ++i) {
      ASSERT_EQ(beam(i), beam(begin)) << "ring " << r;
      ASSERT_GT(WrappedAzimuthStep(rings.azimuth_rad[i - 1], rings.azimuth_rad[i]), 0.0);
    }
  }
}

TEST(BagDrive, CameraInfoRectifiesARawImageOntoP) {
  // A point seen by a plumb_bob camera lands, in the rectified image, where P · R · X says.
  RosCameraInfo info;
  info.width = 640;
  info.height = 480;
  info.distortion_model = "plumb_bob";
  info.d = {-0.3, 0.08, 0.001, -0.0005, 0.0};
  info.K << 500, 0, 321, 0, 502, 238, 0, 0, 1;
  info.R = Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
  info.P << 480, 0, 318, 0, 0, 480, 242, 0, 0, 0, 1, 0;
  CameraCalibration camera;
  RectifyMaps maps;
  ASSERT_TRUE(CameraFromInfo(info, &camera, &maps).ok());
  ASSERT_FALSE(maps.empty());
  cv::Mat K, D(info.d, true);
  cv::eigen2cv(info.K, K);
  for (const Eigen::Vector3d& X : {Eigen::Vector3d(0.3, -0.2, 2.0), Eigen::Vector3d(-1, 0.5, 3)}) {
    std::vector<cv::Point3d> object{{X.x(), X.y(), X.z()}};
    std::vector<cv::Point2d> raw;
    cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, raw);
    const Eigen::Vector3d q = camera.P_rect * (camera.R_rect_00 * X).homogeneous();
    const int u = static_cast<int>(std::lround(q.x() / q.z()));
    const int v = static_cast<int>(std::lround(q.y() / q.z()));
    // The map at the rectified pixel reads the raw image where the point is (the rounding of the
    // rectified pixel moves it by up to half a pixel times the local scale).
    EXPECT_NEAR(maps.map_x.at<float>(v, u), raw[0].x, 0.8);
    EXPECT_NEAR(maps.map_y.at<float>(v, u), raw[0].y, 0.8);
  }
  // The same for the equidistant (fisheye) model, against cv::fisheye::projectPoints.
  info.distortion_model = "equidistant";
  info.d = {0.05, -0.01, 0.002, -0.0003};
  ASSERT_TRUE(CameraFromInfo(info, &camera, &maps).ok());
  const cv::Mat D4(info.d, true);
  for (const Eigen::Vector3d& X : {Eigen::Vector3d(0.3, -0.2, 2.0), Eigen::Vector3d(-1, 0.5, 3)}) {
    std::vector<cv::Point3d> object{{X.x(), X.y(), X.z()}};
    std::vector<cv::Point2d> raw;
    cv::fisheye::projectPoints(object, raw, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D4);
    const Eigen::Vector3d q = camera.P_rect * (camera.R_rect_00 * X).homogeneous();
    const int u = static_cast<int>(std::lround(q.x() / q.z()));
    const int v = static_cast<int>(std::lround(q.y() / q.z()));
    EXPECT_NEAR(maps.map_x.at<float>(v, u), raw[0].x, 0.8);
    EXPECT_NEAR(maps.map_y.at<float>(v, u), raw[0].y, 0.8);
  }
  info.d.push_back(0.0);  // five coefficients: not the equidistant model's four
  EXPECT_THAT(CameraFromInfo(info, &camera, &maps).message(), ::testing::HasSubstr("needs 4"));
  info.distortion_model = "kannala";
  const Status unknown = CameraFromInfo(info, &camera, &maps);
  ASSERT_FALSE(unknown.ok());
  EXPECT_THAT(unknown.message(), ::testing::HasSubstr("\"kannala\" is not supported"));
}

}  // namespace
}  // namespace stcalib
