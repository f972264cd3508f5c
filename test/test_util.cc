#include "test/test_util.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <opencv2/core.hpp>

#include "core/io/image.h"
#include "core/io/kitti_calib.h"
#include "core/io/oxts.h"
#include "core/io/timestamps.h"
#include "core/io/velodyne.h"

namespace stcalib::testing {

CommandResult RunCommand(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) {
    result.output.append(buffer.data(), n);
  }
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

std::string MakeTinyDrive(const std::string& root, int num_frames) {
  namespace fs = std::filesystem;
  const std::string calib_dir = root + "/2011_01_01";
  const std::string drive = calib_dir + "/2011_01_01_drive_0001_sync";
  for (const char* sub : {"image_02/data", "velodyne_points/data", "oxts/data"}) {
    fs::create_directories(drive + "/" + sub);
  }
  WriteFile(calib_dir + "/calib_cam_to_cam.txt",
            "calib_time: 01-Jan-2011 00:00:00\n"
            "S_rect_02: 6.400000e+01 4.800000e+01\n"
            "R_rect_00: 1 0 0 0 1 0 0 0 1\n"
            "P_rect_02: 50 0 32 0 0 50 24 0 0 0 1 0\n");
  WriteFile(calib_dir + "/calib_velo_to_cam.txt",
            "calib_time: 01-Jan-2011 00:00:00\n"
            "R: 0 -1 0 0 0 -1 1 0 0\nT: 0 -0.08 -0.27\n");
  WriteFile(calib_dir + "/calib_imu_to_velo.txt",
            "calib_time: 01-Jan-2011 00:00:00\nR: 1 0 0 0 1 0 0 0 1\nT: -0.8 0.3 -0.8\n");
  std::vector<StampNs> camera, lidar, oxts;
  for (int i = 0; i < num_frames; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%010d", i);
    cv::Mat image(48, 64, CV_8UC3, cv::Scalar(40, 80, 120));
    EXPECT_TRUE(WriteImage(drive + "/image_02/data/" + name + ".png", image).ok());
    LidarScan scan;
    for (int k = 0; k < 100; ++k) {
      scan.points_lidar.emplace_back(5.0 + 0.1 * k, -1.0 + 0.02 * k, -0.5);
      scan.reflectance.push_back(0.5f);
    }
    EXPECT_TRUE(WriteVelodyneBin(drive + "/velodyne_points/data/" + name + ".bin", scan).ok());
    OxtsPacket packet;
    packet.lat = 49.0;
    packet.lon = 8.4;
    packet.vf = 10.0;
    EXPECT_TRUE(WriteOxtsPacket(drive + "/oxts/data/" + name + ".txt", packet).ok());
    const StampNs base = 1293840000000000000LL + i * 100000000LL;
    lidar.push_back(base);
    camera.push_back(base + 10000000);
    oxts.push_back(base + 5000000);
  }
  EXPECT_TRUE(WriteTimestampsFile(drive + "/image_02/timestamps.txt", camera).ok());
  EXPECT_TRUE(WriteTimestampsFile(drive + "/velodyne_points/timestamps.txt", lidar).ok());
  EXPECT_TRUE(WriteTimestampsFile(drive + "/oxts/timestamps.txt", oxts).ok());
  return drive;
}

::testing::AssertionResult OpenKittiDrive(Drive* drive, DriveMotion* motion) {
  Status status = OpenDrive(KittiDriveDir(), "", drive);
  if (status.ok() && motion != nullptr) status = DriveMotion::Create(*drive, motion);
  if (!status.ok()) return ::testing::AssertionFailure() << status.message();
  return ::testing::AssertionSuccess();
}

std::vector<std::shared_ptr<const CalibrationFrame>> LoadCalibrationFrames(
    const Drive& drive, const FrameSourceOptions& options, const std::vector<int>& indices) {
  std::vector<std::shared_ptr<const CalibrationFrame>> frames;
  std::unique_ptr<DriveFrameSource> source;
  const Status created = DriveFrameSource::Create(&drive, options, &source);
  EXPECT_TRUE(created.ok()) << created.message();
  if (!created.ok()) return frames;
  for (int i : indices) {
    auto frame = std::make_shared<CalibrationFrame>();
    const Status loaded = source->Load(i, frame.get());
    EXPECT_TRUE(loaded.ok()) << loaded.message();
    if (loaded.ok()) frames.push_back(frame);
  }
  return frames;
}

}  // namespace stcalib::testing
