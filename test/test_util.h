#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "core/io/drive.h"
#include "core/motion/drive_motion.h"
#include "core/online/frame_source.h"

namespace stcalib::testing {

// ../shared/data, configured by CMake. Tests that need it skip only when it is absent.
inline std::string SharedDataDir() { return STCALIB_SHARED_DATA_DIR; }
inline std::string KittiCalibDir() { return SharedDataDir() + "/kitti/2011_09_26"; }
inline std::string KittiDriveDir() { return KittiCalibDir() + "/2011_09_26_drive_0013_sync"; }
inline bool HaveKitti() { return std::filesystem::is_directory(KittiDriveDir()); }

#define STCALIB_REQUIRE_KITTI()                                                              \
  if (!::stcalib::testing::HaveKitti()) {                                                    \
    GTEST_SKIP() << "shared KITTI data not found at " << ::stcalib::testing::KittiDriveDir() \
                 << " (clone with ../shared beside the repository)";                         \
  }

// A shared drive with both KITTI colour cameras (image_02 and image_03): 0020 of 2011_09_30.
inline std::string KittiStereoDriveDir() {
  return SharedDataDir() + "/kitti-odometry/2011_09_30/2011_09_30_drive_0020_sync";
}
#define STCALIB_REQUIRE_KITTI_STEREO()                                                             \
  if (!std::filesystem::is_directory(::stcalib::testing::KittiStereoDriveDir() + "/image_03")) {   \
    GTEST_SKIP() << "shared KITTI data not found at " << ::stcalib::testing::KittiStereoDriveDir() \
                 << "/image_03 (clone with ../shared beside the repository)";                      \
  }

// Opens the shared KITTI drive and, when `motion` is given, its motion; a failure names the
// file and the problem. Call after STCALIB_REQUIRE_KITTI(): ASSERT_TRUE(OpenKittiDrive(&drive)).
::testing::AssertionResult OpenKittiDrive(Drive* drive, DriveMotion* motion = nullptr);

// A shell command's exit code (128 + signal when killed; -1 when it could not start) and its
// stdout and stderr together.
struct CommandResult {
  int exit_code = -1;
  std::string output;
};
CommandResult RunCommand(const std::string& command);

// A fresh folder under the system temp dir, removed on destruction.
class ScopedTempDir {
 public:
  ScopedTempDir() {
    std::random_device rd;
    path_ = (std::filesystem::temp_directory_path() /
             ("stcalib_test_" + std::to_string(rd()) + std::to_string(rd())))
                .string();
    std::filesystem::create_directories(path_);
  }
  ~ScopedTempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

inline std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void WriteFile(const std::string& path, const std::string& contents) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << contents;
}

// Writes a small, valid KITTI-layout drive (calibration copied from fixed KITTI-like values)
// into root/2011_01_01/2011_01_01_drive_0001_sync and returns the drive folder.
std::string MakeTinyDrive(const std::string& root, int num_frames);

// Frames `indices` of `drive` as CalibrationFrames built with `options`; a frame that does not
// load is a test failure (and is left out).
std::vector<std::shared_ptr<const CalibrationFrame>> LoadCalibrationFrames(
    const Drive& drive, const FrameSourceOptions& options, const std::vector<int>& indices);

}  // namespace stcalib::testing
