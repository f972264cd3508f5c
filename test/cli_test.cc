// The stcalib binary end to end: exit codes and messages of info and project.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/io/image.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

using ::testing::HasSubstr;

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

RunResult RunStcalib(const std::string& args) {
  RunResult result;
  const std::string command = std::string(STCALIB_BINARY) + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

TEST(Cli, HelpListsSubcommands) {
  const RunResult r = RunStcalib("--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("info"));
  EXPECT_THAT(r.output, HasSubstr("project"));
  EXPECT_EQ(RunStcalib("").exit_code, 2);
  const RunResult unknown = RunStcalib("frobnicate");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.output, HasSubstr("unknown subcommand 'frobnicate'"));
}

TEST(Cli, InfoAndProjectOnKitti) {
  STCALIB_REQUIRE_KITTI();
  const RunResult info = RunStcalib("info --drive=" + testing::KittiDriveDir());
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_THAT(info.output, HasSubstr("frames       30"));
  EXPECT_THAT(info.output, HasSubstr("1242x375"));
  testing::ScopedTempDir tmp;
  const std::string png = tmp.path() + "/overlay.png";
  const RunResult project =
      RunStcalib("project --drive=" + testing::KittiDriveDir() + " --frame=3 --out=" + png);
  ASSERT_EQ(project.exit_code, 0) << project.output;
  cv::Mat overlay;
  ASSERT_TRUE(ReadImage(png, &overlay).ok());
  EXPECT_EQ(overlay.cols, 1242);
  EXPECT_EQ(overlay.rows, 375);
}

TEST(Cli, BadInputExitsNonZeroNamingTheFile) {
  testing::ScopedTempDir tmp;
  const RunResult missing = RunStcalib("info --drive=" + tmp.path() + "/absent");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_THAT(missing.output, HasSubstr(tmp.path() + "/absent"));

  const std::string drive = testing::MakeTinyDrive(tmp.path(), 2);
  const std::string bin = drive + "/velodyne_points/data/0000000001.bin";
  std::filesystem::resize_file(bin, 33);
  const RunResult truncated = RunStcalib("info --drive=" + drive);
  EXPECT_EQ(truncated.exit_code, 1);
  EXPECT_THAT(truncated.output, HasSubstr(bin));
  EXPECT_THAT(truncated.output, HasSubstr("truncated"));

  const RunResult no_out = RunStcalib("project --drive=" + drive + " --frame=0");
  EXPECT_EQ(no_out.exit_code, 2);
  const RunResult out_of_range =
      RunStcalib("project --drive=" + drive + " --frame=5 --out=" + tmp.path() + "/x.png");
  EXPECT_EQ(out_of_range.exit_code, 1);
  EXPECT_THAT(out_of_range.output, HasSubstr("frame 5 out of range"));
  const RunResult unwritable = RunStcalib("project --drive=" + drive +
                                          " --frame=0 --out=" + tmp.path() + "/no/such/dir/x.png");
  EXPECT_EQ(unwritable.exit_code, 1);
  EXPECT_THAT(unwritable.output, HasSubstr("no/such/dir/x.png"));
}

TEST(Cli, SimulateWritesAReadableDrive) {
  testing::ScopedTempDir tmp;
  const RunResult sim =
      RunStcalib("simulate --out=" + tmp.path() + " --frames=2 --seed=9 --time_offset_s=0.02");
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const std::string drive = tmp.path() + "/2026_01_10/2026_01_10_drive_0001_sync";
  EXPECT_THAT(sim.output, HasSubstr(drive));
  const RunResult info = RunStcalib("info --drive=" + drive);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_THAT(info.output, HasSubstr("frames       2"));
  EXPECT_TRUE(std::filesystem::exists(tmp.path() + "/2026_01_10/ground_truth.json"));
}

TEST(Cli, FeaturesWritesPicturesAndNumbers) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  const RunResult r = RunStcalib("features --drive=" + testing::KittiDriveDir() +
                                 " --frame=4 --out=" + tmp.path() + "/f");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("64 rings"));
  for (const char* name :
       {"edge_mask.png", "idt.png", "idt_suppressed.png", "lidar_edges.png", "alignment.png"}) {
    cv::Mat picture;
    ASSERT_TRUE(ReadImage(tmp.path() + "/f/" + name, &picture).ok()) << name;
    EXPECT_EQ(picture.cols, 1242);
  }
  EXPECT_EQ(RunStcalib("features --drive=" + testing::KittiDriveDir() + " --frame=4").exit_code, 2);
  EXPECT_EQ(RunStcalib("features --drive=" + testing::KittiDriveDir() +
                       " --frame=4 --detector=x --out=" + tmp.path())
                .exit_code,
            2);
}

TEST(Cli, FeaturesOnDegenerateFramesWarnsButDoesNotCrash) {
  testing::ScopedTempDir tmp;
  // The tiny drive: flat images (no edges) and 100 points in a line (no rings worth the name).
  const std::string drive = testing::MakeTinyDrive(tmp.path(), 3);
  const RunResult r =
      RunStcalib("features --drive=" + drive + " --frame=1 --out=" + tmp.path() + "/f");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("0 edge pixels"));
  EXPECT_THAT(r.output, HasSubstr("no edges found"));
  // An empty sweep.
  testing::WriteFile(drive + "/velodyne_points/data/0000000002.bin", "");
  const RunResult empty =
      RunStcalib("features --drive=" + drive + " --frame=2 --out=" + tmp.path() + "/g");
  EXPECT_EQ(empty.exit_code, 0) << empty.output;
  EXPECT_THAT(empty.output, HasSubstr("empty sweep"));
}

TEST(Cli, CalibrateWithoutFeaturesFailsAndClaimsNothing) {
  testing::ScopedTempDir tmp;
  const std::string drive = testing::MakeTinyDrive(tmp.path(), 4);
  const std::string out = tmp.path() + "/cal";
  const RunResult r = RunStcalib("calibrate --drive=" + drive + " --out=" + out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("not converged"));
  EXPECT_FALSE(std::filesystem::exists(out + "/calib_velo_to_cam.txt"));
  EXPECT_FALSE(std::filesystem::exists(out + "/time_offset.txt"));
  std::ifstream result(out + "/result.json");
  std::stringstream text;
  text << result.rdbuf();
  EXPECT_THAT(text.str(), HasSubstr("\"converged\": false"));
  EXPECT_EQ(RunStcalib("calibrate --drive=" + drive + " --out=" + out + " --loss=l3").exit_code, 2);
  EXPECT_EQ(RunStcalib("calibrate --drive=" + drive).exit_code, 2);  // no --out
  EXPECT_EQ(
      RunStcalib("calibrate --drive=" + drive + " --out=" + out + " --num_frames=50").exit_code, 1);
}

TEST(Cli, CalibrateFromAStartSoWrongNothingProjects) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  const std::string out = tmp.path() + "/cal";
  const RunResult r = RunStcalib("calibrate --drive=" + testing::KittiDriveDir() +
                                 " --perturb_rot_deg=120 --num_frames=3 --out=" + out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("not converged"));
  EXPECT_FALSE(std::filesystem::exists(out + "/calib_velo_to_cam.txt"));
  EXPECT_THAT(testing::ReadFile(out + "/result.json"), HasSubstr("\"converged\": false"));
}

TEST(Cli, CheckHoldsForKittiCalibrationAndCatchesOneDegreeOff) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  const RunResult good =
      RunStcalib("check --drive=" + testing::KittiDriveDir() + " --out=" + tmp.path() + " ");
  EXPECT_EQ(good.exit_code, 0) << good.output;
  EXPECT_THAT(good.output, HasSubstr("the calibration holds"));
  EXPECT_THAT(good.output, HasSubstr("frames   27-29"));
  EXPECT_THAT(testing::ReadFile(tmp.path() + "/check.json"), HasSubstr("\"holds\": true"));
  // 0.58° on each of roll, pitch and yaw: 1° in all.
  const RunResult off =
      RunStcalib("check --drive=" + testing::KittiDriveDir() + " --perturb_rot_deg=0.58 --seed=3");
  EXPECT_EQ(off.exit_code, 1) << off.output;
  EXPECT_THAT(off.output, HasSubstr("the calibration is off"));
  EXPECT_EQ(RunStcalib("check").exit_code, 2);
  EXPECT_EQ(RunStcalib("check --drive=" + tmp.path() + "/absent").exit_code, 1);
}

TEST(Cli, EvalTemporalBadInput) {
  testing::ScopedTempDir tmp;
  const std::string drive = testing::MakeTinyDrive(tmp.path(), 3);
  const RunResult short_drive =
      RunStcalib("eval-temporal --drive=" + drive + " --out=" + tmp.path() + "/e");
  EXPECT_EQ(short_drive.exit_code, 1);
  EXPECT_THAT(short_drive.output, HasSubstr("too few for a decimation of 2"));
  EXPECT_EQ(RunStcalib("eval-temporal --drive=" + drive).exit_code, 2);
  EXPECT_EQ(RunStcalib("eval-temporal --drive=" + drive + " --out=" + tmp.path() +
                       "/e --lidar_decimation=0")
                .exit_code,
            2);
}

TEST(Cli, SimulateRejectsBadFlags) {
  testing::ScopedTempDir tmp;
  const std::string out = " --out=" + tmp.path() + "/o";
  for (const std::string& flags :
       {std::string("--frames=0"), std::string("--frames=-5"), std::string("--lidar_hz=500"),
        std::string("--lidar_hz=0"), std::string("--time_offset_s=3"),
        std::string("--dynamic_objects=-1"), std::string("--scene=forest")}) {
    const RunResult r = RunStcalib("simulate" + out + " " + flags);
    EXPECT_EQ(r.exit_code, 2) << flags << ": " << r.output;
    EXPECT_THAT(r.output, HasSubstr("usage error")) << flags;
  }
  EXPECT_FALSE(std::filesystem::exists(tmp.path() + "/o"));
  EXPECT_EQ(RunStcalib("simulate --frames=2").exit_code, 2);  // no --out
  testing::WriteFile(tmp.path() + "/file", "x");
  const RunResult unwritable = RunStcalib("simulate --frames=1 --out=" + tmp.path() + "/file/sub");
  EXPECT_EQ(unwritable.exit_code, 1);
  EXPECT_THAT(unwritable.output, HasSubstr(tmp.path() + "/file/sub"));
}

}  // namespace
}  // namespace stcalib
