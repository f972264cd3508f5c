// KITTI raw readers against the shared frames, and exact round trips of every writer.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/io/drive.h"
#include "core/io/kitti_calib.h"
#include "core/io/oxts.h"
#include "core/io/timestamps.h"
#include "core/io/velodyne.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

using testing::KittiCalibDir;
using testing::KittiDriveDir;

TEST(Timestamps, ParsesToTheNanosecond) {
  StampNs stamp = 0;
  ASSERT_TRUE(ParseKittiTimestamp("2011-09-26 13:10:51.168593664", &stamp));
  // Reference: Python datetime(2011, 9, 26, 13, 10, 51, tzinfo=UTC).timestamp() * 1e9 + ns.
  EXPECT_EQ(stamp, 1317042651168593664LL);
  EXPECT_EQ(FormatKittiTimestamp(stamp), "2011-09-26 13:10:51.168593664");
  ASSERT_TRUE(ParseKittiTimestamp("2000-02-29 23:59:59.5", &stamp));
  EXPECT_EQ(stamp, 951868799500000000LL);  // leap day, short fraction padded
  ASSERT_TRUE(ParseKittiTimestamp("1970-01-01 00:00:00", &stamp));
  EXPECT_EQ(stamp, 0);
}

TEST(Timestamps, RejectsMalformedText) {
  StampNs stamp = 0;
  for (const char* bad :
       {"", "2011-09-26", "2011-09-26 13:10:51.", "2011-13-01 00:00:00.0", "2011-02-29 00:00:00.0",
        "2011-09-26 24:00:00.0", "2011-09-26 13:10:51.1234567890", "2011/09/26 13:10:51.1",
        "2011-09-26 13:10:51.1x"}) {
    EXPECT_FALSE(ParseKittiTimestamp(bad, &stamp)) << "'" << bad << "'";
  }
}

TEST(Timestamps, FileRoundTripIsExact) {
  testing::ScopedTempDir tmp;
  const std::vector<StampNs> stamps = {1317042651168593664LL, 1317042651272099072LL, 5};
  const std::string path = tmp.path() + "/timestamps.txt";
  ASSERT_TRUE(WriteTimestampsFile(path, stamps).ok());
  std::vector<StampNs> read;
  ASSERT_TRUE(ReadTimestampsFile(path, &read).ok());
  EXPECT_EQ(read, stamps);
}

TEST(KittiReaders, CalibrationFilesHoldKnownValues) {
  STCALIB_REQUIRE_KITTI();
  CameraCalibration camera;
  ASSERT_TRUE(ReadCamToCam(KittiCalibDir() + "/calib_cam_to_cam.txt", &camera).ok());
  EXPECT_EQ(camera.file.keys().size(), 34u);  // calib_time, corner_dist, 8 keys x 4 cameras
  EXPECT_EQ(camera.file.Text("calib_time"), "09-Jan-2012 13:57:47");
  EXPECT_DOUBLE_EQ(camera.R_rect_00(0, 1), 9.837760e-03);
  EXPECT_DOUBLE_EQ(camera.R_rect_00(2, 2), 9.999631e-01);
  EXPECT_DOUBLE_EQ(camera.P_rect(0, 0), 7.215377e+02);
  EXPECT_DOUBLE_EQ(camera.P_rect(0, 3), 4.485728e+01);
  EXPECT_DOUBLE_EQ(camera.P_rect(2, 3), 2.745884e-03);
  EXPECT_EQ(camera.image_width, 1242);
  EXPECT_EQ(camera.image_height, 375);
  Eigen::MatrixXd D_03;
  ASSERT_TRUE(camera.file.GetMatrix("D_03", 1, 5, &D_03).ok());
  EXPECT_DOUBLE_EQ(D_03(0, 4), -5.382460e-02);

  Rigid3d T_camera_lidar;
  ASSERT_TRUE(ReadVeloToCam(KittiCalibDir() + "/calib_velo_to_cam.txt", &T_camera_lidar).ok());
  EXPECT_NEAR(T_camera_lidar(0, 0), 7.533745e-03, 1e-6);   // R moved to the nearest rotation
  EXPECT_NEAR(T_camera_lidar(0, 1), -9.999714e-01, 1e-6);  // R moved to the nearest rotation
  EXPECT_NEAR(T_camera_lidar(2, 0), 9.998621e-01, 1e-6);   // R moved to the nearest rotation
  EXPECT_DOUBLE_EQ(T_camera_lidar(0, 3), -4.069766e-03);
  EXPECT_DOUBLE_EQ(T_camera_lidar(1, 3), -7.631618e-02);
  EXPECT_DOUBLE_EQ(T_camera_lidar(2, 3), -2.717806e-01);

  Rigid3d T_lidar_imu;
  ASSERT_TRUE(ReadImuToVelo(KittiCalibDir() + "/calib_imu_to_velo.txt", &T_lidar_imu).ok());
  EXPECT_DOUBLE_EQ(T_lidar_imu(0, 3), -8.086759e-01);
  EXPECT_NEAR(T_lidar_imu(1, 2), -1.482298e-02, 1e-6);  // R moved to the nearest rotation
}

TEST(KittiReaders, DriveIndexesThirtyFramesWithMonotonicStamps) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  const Status status = OpenDrive(KittiDriveDir(), "", &drive);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(drive.NumFrames(), 30u);
  EXPECT_EQ(drive.frame_names.front(), "0000000000");
  EXPECT_EQ(drive.frame_names.back(), "0000000029");
  ASSERT_TRUE(drive.has_oxts);
  ASSERT_TRUE(drive.has_imu_calibration);
  for (const auto* stamps :
       {&drive.camera_stamps_ns, &drive.lidar_stamps_ns, &drive.lidar_start_stamps_ns,
        &drive.lidar_end_stamps_ns, &drive.oxts_stamps_ns}) {
    ASSERT_EQ(stamps->size(), 30u);
    for (size_t i = 1; i < stamps->size(); ++i) EXPECT_GT((*stamps)[i], (*stamps)[i - 1]);
  }
  // First stamps, exactly as in the files.
  EXPECT_EQ(FormatKittiTimestamp(drive.camera_stamps_ns[0]), "2011-09-26 13:10:51.168593664");
  EXPECT_EQ(FormatKittiTimestamp(drive.lidar_stamps_ns[0]), "2011-09-26 13:10:51.158069617");
  for (size_t i = 0; i < drive.NumFrames(); ++i) {
    // docs/method.md §10: the velodyne stamp is the middle of start and end (to 1 µs), the sweep
    // lasts about 103.6 ms, and the camera stamp is about 10.5 ms after the velodyne stamp.
    const StampNs mid = (drive.lidar_start_stamps_ns[i] + drive.lidar_end_stamps_ns[i]) / 2;
    EXPECT_NEAR(static_cast<double>(drive.lidar_stamps_ns[i] - mid), 0.0, 1000.0);
    EXPECT_NEAR((drive.lidar_end_stamps_ns[i] - drive.lidar_start_stamps_ns[i]) * 1e-6, 103.6, 1.0);
    EXPECT_NEAR((drive.camera_stamps_ns[i] - drive.lidar_stamps_ns[i]) * 1e-6, 10.5, 0.5);
  }
  // Oxts frame 0, every field by name (oxts/data/0000000000.txt).
  const OxtsPacket& p = drive.oxts[0];
  EXPECT_DOUBLE_EQ(p.lat, 49.013141872681);
  EXPECT_DOUBLE_EQ(p.lon, 8.4378138518088);
  EXPECT_DOUBLE_EQ(p.alt, 114.06644439697);
  EXPECT_DOUBLE_EQ(p.yaw, 1.8456953267949);
  EXPECT_DOUBLE_EQ(p.vf, 11.842084178285);
  EXPECT_DOUBLE_EQ(p.vl, -0.083632098803428);
  EXPECT_DOUBLE_EQ(p.az, 9.663174859472);
  EXPECT_DOUBLE_EQ(p.wu, 0.006226415927148);
  EXPECT_DOUBLE_EQ(p.pos_accuracy, 0.14961617559609);
  EXPECT_DOUBLE_EQ(p.vel_accuracy, 0.031827660925679);
  EXPECT_EQ(p.navstat, 4);
  EXPECT_EQ(p.numsats, 8);
  EXPECT_EQ(p.posmode, 4);
  EXPECT_EQ(p.velmode, 4);
  EXPECT_EQ(p.orimode, 0);
}

TEST(KittiReaders, VelodynePointCountsMatchFileSizes) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  for (size_t i : {size_t{0}, size_t{29}}) {
    LidarScan scan;
    ASSERT_TRUE(drive.LoadScan(i, &scan).ok());
    EXPECT_EQ(scan.size() * 16, std::filesystem::file_size(drive.VelodynePath(i)));
    EXPECT_EQ(scan.reflectance.size(), scan.size());
  }
  LidarScan scan;
  ASSERT_TRUE(drive.LoadScan(0, &scan).ok());
  EXPECT_EQ(scan.size(), 115267u);  // 1844272 bytes / 16
  double max_range = 0;
  for (const auto& p : scan.points_lidar) max_range = std::max(max_range, p.norm());
  EXPECT_GT(max_range, 50.0);
  EXPECT_LT(max_range, 130.0);  // HDL-64E
  cv::Mat image;
  ASSERT_TRUE(drive.LoadImage(0, &image).ok());
  EXPECT_EQ(image.cols, drive.camera.image_width);
  EXPECT_EQ(image.rows, drive.camera.image_height);
  EXPECT_EQ(image.type(), CV_8UC3);
}

TEST(KittiWriters, VeloToCamRoundTripIsExactToPrintedPrecision) {
  testing::ScopedTempDir tmp;
  const Rigid3d T =
      MakeRigid(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix(),
                Eigen::Vector3d(-0.00406976612345, -0.0763161812345, -0.27178));
  const std::string a = tmp.path() + "/a.txt", b = tmp.path() + "/b.txt";
  ASSERT_TRUE(WriteVeloToCam(a, T).ok());
  Rigid3d read;
  ASSERT_TRUE(ReadVeloToCam(a, &read).ok());
  // 13 significant digits are printed: relative error below 1e-12.
  EXPECT_LT((read.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  ASSERT_TRUE(WriteVeloToCam(b, read).ok());
  EXPECT_EQ(testing::ReadFile(a), testing::ReadFile(b));
  // The printed estimate (calibrate without --out) is the file's text.
  EXPECT_EQ(VeloToCamText(T), testing::ReadFile(a));
}

TEST(KittiWriters, TimeOffsetRoundTripAndBadFilesAreNamed) {
  testing::ScopedTempDir tmp;
  const std::string path = tmp.path() + "/time_offset.txt";
  ASSERT_TRUE(WriteTimeOffset(path, -0.0123456789).ok());
  EXPECT_EQ(testing::ReadFile(path), "-0.012345679\n");
  double read = 0;
  ASSERT_TRUE(ReadTimeOffset(path, &read).ok());
  EXPECT_EQ(read, -0.012345679);
  testing::WriteFile(path, "\n  0.03 \n\n");  // blank lines and spaces are fine
  ASSERT_TRUE(ReadTimeOffset(path, &read).ok());
  EXPECT_EQ(read, 0.03);
  // A partial claim's note is a comment line, skipped on reading.
  ASSERT_TRUE(WriteTimeOffset(path, 0.02, "held at the start: not observable in this drive").ok());
  EXPECT_EQ(testing::ReadFile(path),
            "0.020000000\n# held at the start: not observable in this drive\n");
  ASSERT_TRUE(ReadTimeOffset(path, &read).ok());
  EXPECT_EQ(read, 0.02);
  for (const auto& [text, message] :
       std::vector<std::pair<std::string, std::string>>{{"", "expected one number"},
                                                        {"0.1 0.2\n", "found 2"},
                                                        {"nan\n", "'nan' is not a finite number"},
                                                        {"30ms\n", "'30ms' is not a finite"},
                                                        {"1.5\n", "beyond ±1 s"},
                                                        {"# 0.03\n", "expected one number"}}) {
    testing::WriteFile(path, text);
    const Status status = ReadTimeOffset(path, &read);
    EXPECT_FALSE(status.ok()) << text;
    EXPECT_THAT(status.message(), ::testing::HasSubstr(path + ": ")) << text;
    EXPECT_THAT(status.message(), ::testing::HasSubstr(message)) << status.message();
  }
  EXPECT_FALSE(ReadTimeOffset(tmp.path() + "/absent.txt", &read).ok());
}

TEST(KittiWriters, CamToCamRewritesEveryKey) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  KittiCalibFile file;
  ASSERT_TRUE(KittiCalibFile::Read(KittiCalibDir() + "/calib_cam_to_cam.txt", &file).ok());
  ASSERT_TRUE(file.Write(tmp.path() + "/c.txt").ok());
  KittiCalibFile again;
  ASSERT_TRUE(KittiCalibFile::Read(tmp.path() + "/c.txt", &again).ok());
  EXPECT_EQ(again.keys(), file.keys());
  EXPECT_EQ(again.numbers(), file.numbers());
}

TEST(KittiWriters, OxtsAndVelodyneRoundTripsAreExact) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  OxtsPacket packet;
  ASSERT_TRUE(ReadOxtsPacket(KittiDriveDir() + "/oxts/data/0000000007.txt", &packet).ok());
  ASSERT_TRUE(WriteOxtsPacket(tmp.path() + "/o.txt", packet).ok());
  OxtsPacket again;
  ASSERT_TRUE(ReadOxtsPacket(tmp.path() + "/o.txt", &again).ok());
  EXPECT_EQ(FormatOxtsPacket(again), FormatOxtsPacket(packet));
  EXPECT_EQ(again.lat, packet.lat);
  EXPECT_EQ(again.wu, packet.wu);

  LidarScan scan;
  ASSERT_TRUE(
      ReadVelodyneBin(KittiDriveDir() + "/velodyne_points/data/0000000003.bin", &scan).ok());
  ASSERT_TRUE(WriteVelodyneBin(tmp.path() + "/v.bin", scan).ok());
  EXPECT_EQ(testing::ReadFile(tmp.path() + "/v.bin"),
            testing::ReadFile(KittiDriveDir() + "/velodyne_points/data/0000000003.bin"));

  const std::vector<uint8_t> labels = {0, 1, 2, 2, 0};
  ASSERT_TRUE(WritePointLabels(tmp.path() + "/l.bin", labels).ok());
  std::vector<uint8_t> labels_read;
  ASSERT_TRUE(ReadPointLabels(tmp.path() + "/l.bin", &labels_read).ok());
  EXPECT_EQ(labels_read, labels);
}

}  // namespace
}  // namespace stcalib
