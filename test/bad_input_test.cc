// Every kind of bad input gets a Status naming the file (and line) and the problem.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>

#include "core/io/drive.h"
#include "core/io/image.h"
#include "core/io/kitti_calib.h"
#include "core/io/oxts.h"
#include "core/io/timestamps.h"
#include "core/io/velodyne.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

using ::testing::HasSubstr;
using testing::MakeTinyDrive;
using testing::ScopedTempDir;
using testing::WriteFile;

#define EXPECT_ERROR(status_expr, ...)                                    \
  do {                                                                    \
    const ::stcalib::Status _s = (status_expr);                           \
    EXPECT_FALSE(_s.ok());                                                \
    for (const std::string& part : std::vector<std::string>{__VA_ARGS__}) \
      EXPECT_THAT(_s.message(), HasSubstr(part));                         \
  } while (0)

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    drive_ = MakeTinyDrive(tmp_.path(), 3);
    calib_ = std::filesystem::path(drive_).parent_path().string();
    Drive drive;
    const Status status = OpenDrive(drive_, "", &drive);
    ASSERT_TRUE(status.ok()) << status.message();  // the intact tiny drive opens
  }
  Status Open() {
    Drive drive;
    return OpenDrive(drive_, "", &drive);
  }
  ScopedTempDir tmp_;
  std::string drive_, calib_;
};

TEST_F(BadInput, MissingDriveFolder) {
  Drive drive;
  EXPECT_ERROR(OpenDrive(tmp_.path() + "/nope", "", &drive), tmp_.path() + "/nope", "not found");
}

TEST_F(BadInput, MissingSensorFolder) {
  std::filesystem::remove_all(drive_ + "/velodyne_points/data");
  EXPECT_ERROR(Open(), drive_ + "/velodyne_points/data", "folder not found");
}

TEST_F(BadInput, MissingFrameFile) {
  std::filesystem::remove(drive_ + "/velodyne_points/data/0000000001.bin");
  EXPECT_ERROR(Open(), "velodyne_points/data", "2 frames", "has 3");
}

TEST_F(BadInput, MissingCalibrationFile) {
  std::filesystem::remove(calib_ + "/calib_velo_to_cam.txt");
  EXPECT_ERROR(Open(), calib_ + "/calib_velo_to_cam.txt", "not found");
}

TEST_F(BadInput, TimestampCountDiffersFromFrameCount) {
  WriteFile(drive_ + "/image_02/timestamps.txt",
            "2011-01-01 00:00:00.000000000\n2011-01-01 00:00:00.100000000\n");
  EXPECT_ERROR(Open(), drive_ + "/image_02/timestamps.txt", "2 timestamps for 3 frames");
}

TEST_F(BadInput, MalformedTimestampNamesTheLine) {
  WriteFile(drive_ + "/oxts/timestamps.txt",
            "2011-01-01 00:00:00.000000000\n2011-01-01 00:00:0x.1\n2011-01-01 00:00:00.2\n");
  EXPECT_ERROR(Open(), drive_ + "/oxts/timestamps.txt:2:", "malformed timestamp");
}

TEST_F(BadInput, TruncatedVelodyneFile) {
  const std::string path = drive_ + "/velodyne_points/data/0000000002.bin";
  std::filesystem::resize_file(path, 100 * 16 - 5);
  LidarScan scan;
  EXPECT_ERROR(ReadVelodyneBin(path, &scan), path, "truncated", "not a multiple of 16");
  EXPECT_TRUE(scan.points_lidar.empty());
}

TEST_F(BadInput, NanAndInfPoints) {
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                    -std::numeric_limits<float>::infinity()}) {
    const std::string path = tmp_.path() + "/bad.bin";
    const float data[8] = {1, 2, 3, 0.5f, 4, bad, 6, 0.5f};
    WriteFile(path, std::string(reinterpret_cast<const char*>(data), sizeof(data)));
    LidarScan scan;
    EXPECT_ERROR(ReadVelodyneBin(path, &scan), path, "point 1", "NaN or infinite");
    EXPECT_EQ(scan.size(), 0u);
  }
}

TEST_F(BadInput, MalformedCalibrationKeys) {
  const std::string path = calib_ + "/calib_velo_to_cam.txt";
  WriteFile(path, "calib_time: x\nR: 1 0 0 0 1 0 0 0\nT: 0 0 0\n");
  Rigid3d T;
  EXPECT_ERROR(ReadVeloToCam(path, &T), path + ":2", "key 'R' has 8 numbers, expected 9");
  WriteFile(path, "R: 1 0 0 0 1 0 0 0 1\nT: 0 zero 0\n");
  EXPECT_ERROR(ReadVeloToCam(path, &T), path + ":2", "'zero' is not a finite number");
  WriteFile(path, "R: 1 0 0 0 1 0 0 0 1\nT: 0 nan 0\n");
  EXPECT_ERROR(ReadVeloToCam(path, &T), path + ":2", "'nan'");
  WriteFile(path, "R: 1 0 0 0 1 0 0 0 1\n");
  EXPECT_ERROR(ReadVeloToCam(path, &T), path, "missing key 'T'");
  WriteFile(path, "R: 2 0 0 0 1 0 0 0 1\nT: 0 0 0\n");
  EXPECT_ERROR(ReadVeloToCam(path, &T), path, "not a rotation matrix");
  WriteFile(path, "R 1 0 0 0 1 0 0 0 1\n");
  EXPECT_ERROR(ReadVeloToCam(path, &T), path + ":1", "expected 'key: values'");
  WriteFile(path, "");
  EXPECT_ERROR(ReadVeloToCam(path, &T), path, "no calibration keys");
  EXPECT_ERROR(Open(), path);  // and the drive refuses to open
}

TEST_F(BadInput, MissingCameraKey) {
  const std::string path = calib_ + "/calib_cam_to_cam.txt";
  WriteFile(path, "S_rect_02: 64 48\nR_rect_00: 1 0 0 0 1 0 0 0 1\n");
  CameraCalibration camera;
  EXPECT_ERROR(ReadCamToCam(path, &camera), path, "missing key 'P_rect_02'");
}

TEST_F(BadInput, MalformedOxtsPacket) {
  const std::string path = drive_ + "/oxts/data/0000000001.txt";
  WriteFile(path, "49 8.4 100 0 0 0\n");
  EXPECT_ERROR(Open(), path + ":1", "6 fields, expected 30");
  OxtsPacket packet;
  WriteFile(path, "");
  EXPECT_ERROR(ReadOxtsPacket(path, &packet), path, "empty");
}

TEST_F(BadInput, UnreadablePng) {
  const std::string path = drive_ + "/image_02/data/0000000001.png";
  WriteFile(path, "this is not a png");
  Drive drive;
  ASSERT_TRUE(OpenDrive(drive_, "", &drive).ok());  // opening lists files, decoding is lazy
  cv::Mat image;
  EXPECT_ERROR(drive.LoadImage(1, &image), path, "cannot decode image");
  EXPECT_ERROR(ReadImage(tmp_.path() + "/none.png", &image), "none.png", "not found");
  EXPECT_ERROR(drive.LoadImage(7, &image), "frame 7 out of range");
}

}  // namespace
}  // namespace stcalib
