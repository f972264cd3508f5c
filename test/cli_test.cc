// The stcalib binary end to end: exit codes and messages of info and project.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/io/image.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

using RunResult = testing::CommandResult;  // stdout and stderr

RunResult RunStcalib(const std::string& args) {
  return testing::RunCommand(std::string(STCALIB_BINARY) + " " + args);
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

// `stcalib SUBCOMMAND --help` lists the options that matter, at most 20, each with its default;
// --helpfull keeps every flag (the tuning ones too).
TEST(Cli, SubcommandHelpListsAtMostTwentyOptions) {
  for (const char* command :
       {"info", "project", "simulate", "features", "calibrate", "eval-temporal", "check", "demo"}) {
    const RunResult r = RunStcalib(std::string(command) + " --help");
    EXPECT_EQ(r.exit_code, 0) << command;
    int options = 0;
    std::istringstream lines(r.output);
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("  --", 0) == 0) {
        ++options;
        EXPECT_THAT(line, HasSubstr("(default: ")) << command;
        // Defaults as a person writes them: 0.15, not the binary 0.14999999999999999.
        EXPECT_THAT(line, Not(::testing::ContainsRegex("[0-9]\\.[0-9]*(0000000|9999999)")))
            << command;
      }
    }
    EXPECT_GE(options, 2) << command << "\n" << r.output;
    EXPECT_LE(options, 20) << command << "\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr("--helpfull")) << command;
  }
  const RunResult calibrate = RunStcalib("calibrate --help");
  EXPECT_THAT(calibrate.output, HasSubstr("  --drive "));
  EXPECT_THAT(calibrate.output, HasSubstr("  --perturb_time_s "));
  EXPECT_THAT(calibrate.output, HasSubstr("  --time_offset_bound_s (default: 0.15)"));
  EXPECT_THAT(calibrate.output, Not(HasSubstr("--tracking_gain")));
  EXPECT_THAT(RunStcalib("calibrate --helpfull").output, HasSubstr("tracking_gain"));
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
  const RunResult folds =
      RunStcalib("calibrate --drive=" + drive + " --out=" + out + " --lidar_folds=sometimes");
  EXPECT_EQ(folds.exit_code, 2);
  EXPECT_THAT(folds.output, HasSubstr("--lidar_folds must be keep, drop or drop_when_tracking"));
  const RunResult detector =
      RunStcalib("calibrate --drive=" + drive + " --out=" + out + " --detector=sobel");
  EXPECT_EQ(detector.exit_code, 2);
  EXPECT_THAT(detector.output, HasSubstr("--detector must be canny, lsd or fld, got 'sobel'"));
  // --init_uncertainty: figures that are not positive numbers, or a lattice too large for memory.
  for (const char* bad : {"0,0.05,0.03", "3,-0.05,0.03", "3,0.05", "3,x,0.03"}) {
    const RunResult u =
        RunStcalib("calibrate --drive=" + drive + " --out=" + out + " --init_uncertainty=" + bad);
    EXPECT_EQ(u.exit_code, 2) << bad;
    EXPECT_THAT(u.output, HasSubstr(std::string("--init_uncertainty=") + bad));
  }
  const RunResult huge =
      RunStcalib("calibrate --drive=" + drive + " --out=" + out + " --init_uncertainty=60,2,1");
  EXPECT_EQ(huge.exit_code, 2);
  EXPECT_THAT(huge.output, HasSubstr("does not fit in memory"));
  // Without --out (optional, docs/method.md §9) the verdict and exit code are the same.
  const RunResult no_out = RunStcalib("calibrate --drive=" + drive);
  EXPECT_EQ(no_out.exit_code, 1) << no_out.output;
  EXPECT_THAT(no_out.output, HasSubstr("not converged"));
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
  // No polish ran, so δ was never freed from the forward translation: no std is claimed for it,
  // it is not observable, and the printout says the pair was not measured.
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_FALSE(result["polish"]["applied"].get<bool>());
  EXPECT_EQ(result["time_offset_vs_forward"]["rests_on"], "forward_translation_prior");
  EXPECT_FALSE(result["time_offset_vs_forward"]["measured"].get<bool>());
  EXPECT_TRUE(result["std"]["time_offset_s"].is_null()) << result["std"];
  EXPECT_FALSE(result["observable"]["time_offset_s"].get<bool>());
  EXPECT_TRUE(result["std"]["z_m"].is_null()) << result["std"];  // the forward translation too
  EXPECT_FALSE(result["observable"]["z_m"].get<bool>());
  EXPECT_THAT(r.output, HasSubstr("the polish, which frees both, did not measure them"));
}

TEST(Cli, CheckHoldsForKittiCalibrationAndCatchesOneDegreeOff) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  const RunResult good =
      RunStcalib("check --drive=" + testing::KittiDriveDir() + " --out=" + tmp.path() + " ");
  EXPECT_EQ(good.exit_code, 0) << good.output;
  EXPECT_THAT(good.output, HasSubstr("holds: the rotation lies"));
  EXPECT_THAT(good.output, HasSubstr("30 frames in 30 blocks of 1"));
  const nlohmann::json check = nlohmann::json::parse(testing::ReadFile(tmp.path() + "/check.json"));
  EXPECT_EQ(check["answer"], "holds");
  ASSERT_EQ(check["axes"].size(), 7u);
  EXPECT_EQ(check["axes"][0]["axis"], "roll_deg");
  EXPECT_TRUE(check["axes"][2]["resolved"].get<bool>());  // yaw
  // 0.58° on each of roll, pitch and yaw: 1° in all.
  const RunResult off =
      RunStcalib("check --drive=" + testing::KittiDriveDir() + " --perturb_rot_deg=0.58 --seed=3");
  EXPECT_EQ(off.exit_code, 4) << off.output;
  EXPECT_THAT(off.output, HasSubstr("off: the rotation lies"));
  // Two frames are two blocks: too few for the jackknife.
  const RunResult few = RunStcalib("check --drive=" + testing::KittiDriveDir() + " --num_frames=2");
  EXPECT_EQ(few.exit_code, 5) << few.output;
  EXPECT_THAT(few.output, HasSubstr("cannot tell"));
  // A stored calibration as `calibrate --out` leaves it: δ comes from the time_offset.txt beside
  // calib_velo_to_cam.txt. A quarter of a second off moves the scene by metres; a malformed file
  // is named.
  const std::string stored = tmp.path() + "/stored";
  std::filesystem::create_directories(stored);
  std::filesystem::copy_file(
      std::filesystem::path(testing::KittiDriveDir()).parent_path() / "calib_velo_to_cam.txt",
      stored + "/calib_velo_to_cam.txt");
  const std::string check_stored = "check --drive=" + testing::KittiDriveDir() +
                                   " --init_calib=" + stored + "/calib_velo_to_cam.txt";
  testing::WriteFile(stored + "/time_offset.txt", "0.25\n");
  const RunResult late = RunStcalib(check_stored + " --out=" + tmp.path() + "/late");
  EXPECT_EQ(late.exit_code, 4) << late.output;
  EXPECT_THAT(late.output,
              HasSubstr("time offset +0.2500 s (" + stored + "/time_offset.txt: +0.2500 s)"));
  EXPECT_THAT(late.output, HasSubstr("off: "));
  EXPECT_EQ(
      nlohmann::json::parse(testing::ReadFile(tmp.path() + "/late/check.json"))["time_offset_s"]
          .get<double>(),
      0.25);
  testing::WriteFile(stored + "/time_offset.txt", "0.01 0.02\n");
  const RunResult two = RunStcalib(check_stored);
  EXPECT_EQ(two.exit_code, 1) << two.output;
  EXPECT_THAT(two.output, HasSubstr(stored + "/time_offset.txt: expected one number"));
  EXPECT_EQ(RunStcalib("check").exit_code, 2);
  EXPECT_EQ(RunStcalib("check --drive=" + tmp.path() + "/absent").exit_code, 1);
}

// The simulated drive folder (DIR/<date>/<date>_drive_0001_sync) written by `simulate`.
std::string SimulatedDrive(const std::string& out) {
  for (const auto& day : std::filesystem::directory_iterator(out)) {
    for (const auto& d : std::filesystem::directory_iterator(day.path())) {
      if (d.is_directory()) return d.path().string();
    }
  }
  return "";
}

// Simulates a drive with `args` into `out` and returns its drive folder ("" on failure).
std::string SimulateDrive(const std::string& out, const std::string& args) {
  if (RunStcalib("simulate --out=" + out + " " + args).exit_code != 0) return "";
  return SimulatedDrive(out);
}

// `calibrate` with configs/sim.flags from ±2° on each axis and ±5 cm (signs from `seed`). The
// default refinement spans 20 frames; drives shorter than that get `kShortDrive`.
constexpr char kShortDrive[] = " --refine_frames=10";
RunResult CalibrateFromTwoDegrees(const std::string& drive, const std::string& out, int seed,
                                  const std::string& extra_flags = "") {
  return RunStcalib(
      "calibrate --flagfile=" STCALIB_SOURCE_DIR "/configs/sim.flags --drive=" + drive +
      " --perturb_rot_deg=2 --perturb_trans_m=0.05 --seed=" + std::to_string(seed) +
      (out.empty() ? std::string() : " --out=" + out) + extra_flags);
}

// Replaces line `index` (0-based) of a text file; `text` empty removes it.
void EditLine(const std::string& path, size_t index, const std::string* text) {
  std::istringstream in(testing::ReadFile(path));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  ASSERT_LT(index, lines.size()) << path;
  if (text == nullptr) {
    lines.erase(lines.begin() + static_cast<long>(index));
  } else {
    lines[index] = *text;
  }
  std::string out;
  for (const std::string& line : lines) out += line + "\n";
  testing::WriteFile(path, out);
}

TEST(Cli, CalibrateSkipsFaultyFramesKeepsTheEstimateAndRecovers) {
  testing::ScopedTempDir tmp;
  const std::string drive = SimulateDrive(tmp.path(), "--frames=20 --seed=2 --time_offset_s=0.02");
  ASSERT_FALSE(drive.empty());
  // Frame 4: a burst of NaN points.
  {
    const std::string path = drive + "/velodyne_points/data/0000000004.bin";
    std::string bytes = testing::ReadFile(path);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (size_t k = 0; k < 4000 && (k + 1) * sizeof(float) <= bytes.size(); ++k) {
      std::memcpy(&bytes[k * sizeof(float)], &nan, sizeof(float));
    }
    testing::WriteFile(path, bytes);
  }
  // Frame 6: a black image.
  {
    const std::string path = drive + "/image_02/data/0000000006.png";
    cv::Mat image;
    ASSERT_TRUE(ReadImage(path, &image).ok());
    image.setTo(cv::Scalar::all(0));
    ASSERT_TRUE(WriteImage(path, image).ok());
  }
  // Frame 8: the image stamp of frame 7 again.
  {
    const std::string path = drive + "/image_02/timestamps.txt";
    std::istringstream in(testing::ReadFile(path));
    std::string line;
    for (int k = 0; k <= 7; ++k) std::getline(in, line);
    EditLine(path, 8, &line);
  }
  // Frames 10-12: the oxts receiver stalls (packets 11 and 12 repeat the stamp of packet 10).
  {
    const std::string path = drive + "/oxts/timestamps.txt";
    std::istringstream in(testing::ReadFile(path));
    std::string line;
    for (int k = 0; k <= 10; ++k) std::getline(in, line);
    EditLine(path, 11, &line);
    EditLine(path, 12, &line);
  }
  // Frame 14 dropped from every stream.
  for (const auto& [folder, ext] : std::vector<std::pair<std::string, std::string>>{
           {"image_02", ".png"}, {"velodyne_points", ".bin"}, {"oxts", ".txt"}}) {
    std::filesystem::remove(drive + "/" + folder + "/data/0000000014" + ext);
    for (const char* stamps : {"timestamps.txt", "timestamps_start.txt", "timestamps_end.txt"}) {
      const std::string path = drive + "/" + folder + "/" + stamps;
      if (std::filesystem::exists(path)) EditLine(path, 14, nullptr);
    }
  }
  std::filesystem::remove(drive + "/velodyne_points/labels/0000000014.bin");

  const std::string out = tmp.path() + "/out";
  const RunResult r = CalibrateFromTwoDegrees(drive, out, 2, kShortDrive);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const std::string csv = testing::ReadFile(out + "/per_frame.csv");
  EXPECT_THAT(csv, HasSubstr("4,0,"));
  EXPECT_THAT(csv, HasSubstr("0000000004.bin: point 0 has a NaN"));
  EXPECT_THAT(csv, HasSubstr("frame skipped: no image edges"));
  EXPECT_THAT(csv, HasSubstr("frame skipped: image stamp not after the previous frame's"));
  for (int frame : {10, 11, 12}) {
    EXPECT_THAT(csv, HasSubstr("oxts: frame " + std::to_string(frame) + " falls in a gap"));
  }
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_EQ(result["frames"]["skipped"].get<int>(), 6);
  EXPECT_TRUE(result["converged"].get<bool>());
  // The estimate after the faults is as good as the drive allows: well inside the 3.5° start.
  EXPECT_LT(result["error"]["rotation_deg"].get<double>(), 0.5);
  EXPECT_LT(std::abs(result["error"]["time_offset_s"].get<double>()), 0.015);
}

// A drive without oxts/, or whose oxts cannot be used (no calib_imu_to_velo.txt): the motion
// model comes from registering consecutive sweeps with a constant velocity between them
// (docs/method.md §3's fallback), result.json says so, and the calibration still works.
TEST(Cli, CalibratesADriveWithoutOxtsFromScanRegistration) {
  testing::ScopedTempDir tmp;
  const std::string drive = SimulateDrive(tmp.path(), "--frames=12 --seed=3 --time_offset_s=0.03");
  ASSERT_FALSE(drive.empty());
  // oxts/ without calib_imu_to_velo.txt: the packets cannot be carried to the LiDAR.
  const std::string imu_calib =
      std::filesystem::path(drive).parent_path().string() + "/calib_imu_to_velo.txt";
  const std::string no_imu_calib = tmp.path() + "/no_imu_calib";
  std::filesystem::rename(imu_calib, tmp.path() + "/calib_imu_to_velo.txt");
  const RunResult without_calib = CalibrateFromTwoDegrees(drive, no_imu_calib, 3, kShortDrive);
  EXPECT_EQ(without_calib.exit_code, 0) << without_calib.output;
  EXPECT_THAT(without_calib.output,
              HasSubstr("calib_imu_to_velo.txt: missing, so the oxts motion cannot be used; the "
                        "motion comes from registering consecutive sweeps"));
  const nlohmann::json result_without_calib =
      nlohmann::json::parse(testing::ReadFile(no_imu_calib + "/result.json"));
  EXPECT_EQ(result_without_calib["motion"], "scan_registration");
  EXPECT_LT(result_without_calib["error"]["rotation_deg"].get<double>(), 0.5);

  std::filesystem::rename(tmp.path() + "/calib_imu_to_velo.txt", imu_calib);
  std::filesystem::remove_all(drive + "/oxts");
  const std::string out = tmp.path() + "/out";
  const RunResult r = CalibrateFromTwoDegrees(drive, out, 3, kShortDrive);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("no oxts; the motion comes from registering consecutive sweeps"));
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_EQ(result["motion"], "scan_registration");
  EXPECT_LT(result["error"]["rotation_deg"].get<double>(), 0.5) << r.output;
  EXPECT_LT(std::abs(result["error"]["time_offset_s"].get<double>()), 0.01) << r.output;
  // The same drive gives the same estimate either way.
  EXPECT_EQ(result["T_camera_lidar"], result_without_calib["T_camera_lidar"]);
  EXPECT_EQ(result["time_offset_s"], result_without_calib["time_offset_s"]);

  // Without --out (optional, docs/method.md §9): the same estimate, printed in the format of
  // calib_velo_to_cam.txt and time_offset_s, and nothing written.
  const auto entries = [&]() {
    int n = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::recursive_directory_iterator(tmp.path()))
      ++n;
    return n;
  };
  const int before = entries();
  const RunResult printed = CalibrateFromTwoDegrees(drive, "", 3, kShortDrive);
  EXPECT_EQ(printed.exit_code, 0) << printed.output;
  EXPECT_EQ(entries(), before);
  EXPECT_THAT(printed.output, HasSubstr(testing::ReadFile(out + "/calib_velo_to_cam.txt")));
  EXPECT_THAT(printed.output,
              HasSubstr("time_offset_s: " + testing::ReadFile(out + "/time_offset.txt")));
}

// The paper's disturbance protocol at the very end of a drive: the 3.5° disturbance two frames
// before the end is pulled back within its frame, but the frames after it are too few to show
// that the estimate settled there, so nothing is claimed (a jump that late could as well land on
// a side peak the last frames merely keep).
TEST(Cli, RunEndingRightAfterADisturbanceClaimsNothing) {
  testing::ScopedTempDir tmp;
  const std::string drive = SimulateDrive(tmp.path(), "--frames=12 --seed=3 --time_offset_s=0.03");
  ASSERT_FALSE(drive.empty());
  const std::string out = tmp.path() + "/out";
  const RunResult r =
      CalibrateFromTwoDegrees(drive, out, 3, std::string(kShortDrive) + " --disturb_frame=10");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("not converged: still moving"));
  EXPECT_FALSE(std::filesystem::exists(out + "/calib_velo_to_cam.txt"));
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_LT(result["error"]["rotation_deg"].get<double>(), 0.5) << r.output;  // measured 0.18°
}

// A time offset of −100 ms from a start of δ0 = 0: the local search alone moves δ a few steps at
// a time against its prior and settles on a wrong peak; the lattice's δ hypotheses find it when
// the stated start uncertainty holds it (±100 ms). A run told that δ0 is within 20 ms must not
// claim success: a start farther off than the stated uncertainty is refused, never claimed wrong.
TEST(Cli, CalibratesALargeTimeOffsetAndNeverClaimsAWrongOne) {
  testing::ScopedTempDir tmp;
  const std::string drive = SimulateDrive(tmp.path(), "--frames=16 --seed=14 --time_offset_s=-0.1");
  ASSERT_FALSE(drive.empty());
  const RunResult r = CalibrateFromTwoDegrees(
      drive, tmp.path() + "/scan", 3, std::string(kShortDrive) + " --init_uncertainty=3,0.05,0.1");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json result =
      nlohmann::json::parse(testing::ReadFile(tmp.path() + "/scan/result.json"));
  EXPECT_LT(std::abs(result["error"]["time_offset_s"].get<double>()), 0.006) << r.output;
  EXPECT_LT(
      std::abs(result["time_offset_peak_s"].get<double>() - result["time_offset_s"].get<double>()),
      0.005);

  // The folds are dropped once acquired (the default): the polish holds the lateral and vertical
  // translation, so the fold-free update right after the acquisition must move the whole way.
  EXPECT_LT(result["error"]["rotation_deg"].get<double>(), 0.2) << r.output;
  EXPECT_THAT(testing::ReadFile(tmp.path() + "/scan/per_frame.csv"),
              HasSubstr("folds dropped, a full step"));

  const std::string out = tmp.path() + "/narrow";
  const RunResult local = CalibrateFromTwoDegrees(
      drive, out, 3, std::string(kShortDrive) + " --init_uncertainty=2,0.05,0.02");
  EXPECT_EQ(local.exit_code, 1) << local.output;
  EXPECT_FALSE(std::filesystem::exists(out + "/time_offset.txt"));
}

// Degenerate scenes (docs/method.md §7): an open road (lane markings and kerbs only) leaves
// rotation axes unobservable; a street of poles is ambiguous. The calibrator must say so, hold what
// it cannot see, and never claim success with a wrong answer.
TEST(Cli, DegenerateScenesAreReportedNeverAWrongSuccess) {
  for (const std::string scene : {"open", "poles"}) {
    SCOPED_TRACE(scene);
    testing::ScopedTempDir tmp;
    const std::string drive = SimulateDrive(
        tmp.path(), "--frames=12 --seed=4 --scene=" + scene + " --time_offset_s=0.02");
    ASSERT_FALSE(drive.empty());
    const std::string out = tmp.path() + "/out";
    const RunResult r = CalibrateFromTwoDegrees(drive, out, 1, kShortDrive);
    const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
    const bool converged = result["converged"].get<bool>();
    EXPECT_EQ(r.exit_code, converged ? 0 : 1) << r.output;
    EXPECT_EQ(std::filesystem::exists(out + "/calib_velo_to_cam.txt"), converged);
    if (converged) {  // success only with a right answer
      EXPECT_LT(result["error"]["rotation_deg"].get<double>(), 0.5) << r.output;
    }
    if (scene == "open") {
      // Roll is what an open road barely constrains: its std is 3-4x an urban drive's (0.03-0.05
      // deg over 20 frames) and sits near the default threshold (0.15 deg). With a threshold an
      // engineer might ask for, it is reported, held at its start value, and nothing is claimed.
      EXPECT_GT(result["std"]["roll_deg"].get<double>(), 0.1) << r.output;
      const RunResult strict = CalibrateFromTwoDegrees(
          drive, out + "_strict", 1, std::string(kShortDrive) + " --observable_rotation_deg=0.1");
      EXPECT_EQ(strict.exit_code, 1) << strict.output;
      const nlohmann::json held =
          nlohmann::json::parse(testing::ReadFile(out + "_strict/result.json"));
      const auto& unobservable = held["unobservable_axes"];
      ASSERT_FALSE(unobservable.empty()) << strict.output;
      EXPECT_THAT(strict.output, HasSubstr("not observable in this drive"));
      // Held: an unobservable axis keeps its start value exactly.
      for (const auto& axis : unobservable) {
        const std::string name = axis.get<std::string>();
        if (name == "time_offset_s" || name.find("_deg") == std::string::npos) continue;
        EXPECT_NEAR(held["error"][name].get<double>(), held["initial_error"][name].get<double>(),
                    0.1)
            << name;
      }
    }
  }
}

TEST(Cli, EvalTemporalBadInput) {
  testing::ScopedTempDir tmp;
  const std::string drive = testing::MakeTinyDrive(tmp.path(), 3);
  const RunResult short_drive =
      RunStcalib("eval-temporal --drive=" + drive + " --out=" + tmp.path() + "/e");
  EXPECT_EQ(short_drive.exit_code, 1);
  EXPECT_THAT(short_drive.output, HasSubstr("too few for a decimation of 2"));
  // Without --out (optional, docs/method.md §9) the same error.
  const RunResult no_out = RunStcalib("eval-temporal --drive=" + drive);
  EXPECT_EQ(no_out.exit_code, 1) << no_out.output;
  EXPECT_THAT(no_out.output, HasSubstr("too few for a decimation of 2"));
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
        std::string("--dynamic_objects=-1"), std::string("--scene=forest"),
        std::string("--camera=fisheye"), std::string("--oxts_white_position_m=-0.01"),
        std::string("--oxts_white_position_m=nan"), std::string("--oxts_error_scale=-1"),
        std::string("--oxts_error_scale=nan")}) {
    const RunResult r = RunStcalib("simulate" + out + " " + flags);
    EXPECT_EQ(r.exit_code, 2) << flags << ": " << r.output;
    EXPECT_THAT(r.output, HasSubstr("usage error")) << flags;
  }
  // Unknown names are answered with the names the simulator knows.
  EXPECT_THAT(RunStcalib("simulate" + out + " --scene=forest").output,
              HasSubstr("--scene must be urban, poles or open, got 'forest'"));
  EXPECT_THAT(RunStcalib("simulate" + out + " --oxts_white_position_m=nan").output,
              HasSubstr("--oxts_white_position_m must be between 0 and 1 m, got nan"));
  EXPECT_THAT(RunStcalib("simulate" + out + " --oxts_error_scale=11").output,
              HasSubstr("--oxts_error_scale must be between 0 and 10, got 11"));
  EXPECT_THAT(RunStcalib("simulate" + out + " --camera=fisheye").output,
              HasSubstr("--camera must be kitti, kitti_1003 or hd720, got 'fisheye'"));
  EXPECT_FALSE(std::filesystem::exists(tmp.path() + "/o"));
  EXPECT_EQ(RunStcalib("simulate --frames=2").exit_code, 2);  // no --out
  testing::WriteFile(tmp.path() + "/file", "x");
  const RunResult unwritable = RunStcalib("simulate --frames=1 --out=" + tmp.path() + "/file/sub");
  EXPECT_EQ(unwritable.exit_code, 1);
  EXPECT_THAT(unwritable.output, HasSubstr(tmp.path() + "/file/sub"));
}

}  // namespace
}  // namespace stcalib

namespace stcalib {
namespace {

// A numeric column of per_frame.csv (they all come before the quoted reason) in data row `row`;
// NaN when absent.
double PerFrameNumber(const std::string& csv, size_t row, const std::string& column) {
  auto fields = [](const std::string& line) {
    std::vector<std::string> out;
    std::istringstream in(line);
    for (std::string field; std::getline(in, field, ',');) out.push_back(field);
    return out;
  };
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = fields(line);
  const auto it = std::find(header.begin(), header.end(), column);
  for (size_t k = 0; it != header.end() && std::getline(in, line); ++k) {
    if (k == row) return std::stod(fields(line).at(it - header.begin()));
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// result.json's timing_ms per update against per_frame.csv (`rows` data rows): the frames that
// searched (and refined) are the updates. Returns how many there were.
int ExpectUpdateTimingMatches(const nlohmann::json& result, const std::string& csv, size_t rows) {
  int updates = 0;
  double update_ms = 0;
  for (size_t row = 0; row < rows; ++row) {
    if (PerFrameNumber(csv, row, "search_ms") > 0) {
      ++updates;
      update_ms += PerFrameNumber(csv, row, "search_ms") + PerFrameNumber(csv, row, "refine_ms");
    }
  }
  EXPECT_EQ(result["timing_ms"]["updates"].get<int>(), updates);
  EXPECT_GT(updates, 0);
  // Each CSV value is rounded to 0.005 ms.
  EXPECT_NEAR(result["timing_ms"]["update_mean"].get<double>(), update_ms / std::max(updates, 1),
              0.011);
  return updates;
}

// --detector, --min_segment_px and --max_edge_density reach the calibration's image features
// (they were read by `features` only, and `calibrate --detector=lsd` ran on Canny edges without a
// word). On this 8-frame drive from 3.46° both end within 0.6°, on different maps (gray rate
// 0.793 and 0.759 when measured).
TEST(Cli, CalibrateUsesTheImageDetectorFlags) {
  testing::ScopedTempDir tmp;
  const std::string drive = SimulateDrive(tmp.path(), "--frames=8 --seed=4 --time_offset_s=0.03");
  ASSERT_FALSE(drive.empty());
  std::map<std::string, nlohmann::json> results;
  for (const std::string detector : {"canny", "lsd"}) {
    const std::string out = tmp.path() + "/" + detector;
    const RunResult r =
        CalibrateFromTwoDegrees(drive, out, 4, " --refine_frames=5 --detector=" + detector);
    // Claimed or still moving after the fold-free step that follows the acquisition: either way
    // result.json holds the estimate.
    EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 1) << r.output;
    results[detector] = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
    EXPECT_LT(results[detector]["error"]["rotation_deg"].get<double>(), 0.6) << r.output;
  }
  EXPECT_GT(std::abs(results["canny"]["gray_rate"].get<double>() -
                     results["lsd"]["gray_rate"].get<double>()),
            0.005);
}

// `calibrate --flagfile=configs/kitti.flags` from ±2° on roll, pitch and yaw (issue 5's KITTI
// protocol) on the shared frames.
RunResult CalibrateKitti(const std::string& out, const std::string& args) {
  return RunStcalib("calibrate --flagfile=" STCALIB_SOURCE_DIR "/configs/kitti.flags --drive=" +
                    testing::KittiDriveDir() + " --perturb_rot_deg=2 --out=" + out + " " + args);
}

// All 30 frames: the rotation grid finds the band-pass peak, the calibration converges near
// KITTI's own (measured 0.11–0.29° over seeds 1–4 after the polish, nearly all roll).
TEST(Cli, CalibratesKittiFromTwoDegrees) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  const std::string out = tmp.path() + "/out";
  const RunResult r = CalibrateKitti(out, "--seed=2");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  const auto& agreement = result["agreement_with_drive_calibration"];
  EXPECT_TRUE(result["converged"].get<bool>()) << result["reason"];
  EXPECT_EQ(result["motion"], "oxts");
  // Measured 0.29° (the refinement's optimum over these frames lies 0.11-0.37° from KITTI's on
  // roll, 16 starts of 1-3°: where the polish ends moves by a few hundredths of a degree with
  // where it starts).
  EXPECT_LT(agreement["rotation_deg"].get<double>(), 0.35) << r.output;
  EXPECT_LT(agreement["translation_m"].get<double>(), 0.06) << r.output;  // measured 5.05 cm
  EXPECT_LT(std::abs(result["time_offset_s"].get<double>()), 0.01) << r.output;
  EXPECT_TRUE(std::filesystem::exists(out + "/calib_velo_to_cam.txt"));
  EXPECT_TRUE(result["polish"]["applied"].get<bool>()) << result["polish"]["reason"];
  // These frames do not separate δ from the forward translation (measured with both free: δ std
  // 3.8 ms, forward 4.2 cm, correlation -1.00): δ rests on the forward translation's prior, and
  // result.json says so instead of reporting the tracking refinement's std, which holds the
  // forward translation (0.39 ms) and so claimed δ to a tenth of its ~6 ms agreement.
  const auto& pair = result["time_offset_vs_forward"];
  EXPECT_EQ(pair["rests_on"], "forward_translation_prior");
  EXPECT_TRUE(pair["measured"].get<bool>());
  EXPECT_LT(pair["correlation"].get<double>(), -0.9);
  EXPECT_EQ(result["time_forward_correlation"], pair["correlation"]);
  EXPECT_FALSE(result["observable"]["time_offset_s"].get<bool>());
  EXPECT_EQ(result["std"]["time_offset_s"], pair["time_offset_std_s"]);
  EXPECT_GT(pair["time_offset_std_s"].get<double>(),
            5 * pair["time_offset_std_given_forward_prior_s"].get<double>());
  // So does the forward translation (the camera's z): its std is the solve's with both free
  // (measured 6.9 cm), not the tracking refinement's 1 mm.
  EXPECT_FALSE(result["observable"]["z_m"].get<bool>());
  EXPECT_GE(result["std"]["z_m"].get<double>(), 0.9 * pair["forward_std_m"].get<double>());
  EXPECT_THAT(r.output, HasSubstr("time offset: not separated from the forward translation"));
  // The first frames find the calibration's peak, not a side peak 4-6° off: the first search
  // (frame 2) lands 4.7° off, the next frame's comes back to 1.13°. Measured at the fifth frame
  // from a 3.46° start: 1.00° (0.71° with --tracking_max_lag_deg=0, whose smaller move at frame 3
  // dropped the health to 0.84 and so ran a coarse search at frame 4); 0.29° by the seventh.
  const std::string csv = testing::ReadFile(out + "/per_frame.csv");
  EXPECT_LT(PerFrameNumber(csv, 4, "rotation_error_deg"), 1.5);
  EXPECT_LT(PerFrameNumber(csv, 6, "rotation_error_deg"), 0.5);
  // While tracking, the frames between updates neither search nor refine.
  const int updates = ExpectUpdateTimingMatches(result, csv, 30);
  EXPECT_LT(updates, 30);
  EXPECT_GT(updates, 10);
}

// KITTI's two colour cameras in one pass over the LiDAR (drive 0020 of 2011_09_30): each camera
// its own folder, claim and estimate, image_02's exactly as a run of it alone; the rig's
// result.json compares the two estimates' camera-to-camera transform with calib_cam_to_cam's.
TEST(Cli, CalibratesTwoKittiCamerasInOnePass) {
  STCALIB_REQUIRE_KITTI_STEREO();
  const std::string drive = testing::KittiStereoDriveDir();
  testing::ScopedTempDir tmp;
  const std::string flags = "calibrate --drive=" + drive + " --perturb_rot_deg=2 --seed=1 ";
  const RunResult rig =
      RunStcalib(flags + "--cameras=image_02,image_03 --rig_joint --out=" + tmp.path() + "/rig");
  EXPECT_EQ(rig.exit_code, 0) << rig.output;
  const RunResult alone = RunStcalib(flags + "--out=" + tmp.path() + "/alone");
  EXPECT_EQ(alone.exit_code, 0) << alone.output;
  const nlohmann::json left =
      nlohmann::json::parse(testing::ReadFile(tmp.path() + "/rig/image_02/result.json"));
  const nlohmann::json right =
      nlohmann::json::parse(testing::ReadFile(tmp.path() + "/rig/image_03/result.json"));
  const nlohmann::json single =
      nlohmann::json::parse(testing::ReadFile(tmp.path() + "/alone/result.json"));
  EXPECT_EQ(left["T_camera_lidar"], single["T_camera_lidar"]);
  EXPECT_EQ(left["time_offset_s"], single["time_offset_s"]);
  EXPECT_EQ(right["camera"], "image_03");
  // Measured 0.242° (image_02) and 0.287° (image_03) from KITTI's calibration.
  for (const nlohmann::json* camera : {&left, &right}) {
    EXPECT_TRUE((*camera)["converged"].get<bool>()) << (*camera)["reason"];
    EXPECT_LT((*camera)["agreement_with_drive_calibration"]["rotation_deg"].get<double>(), 0.35);
  }
  EXPECT_TRUE(std::filesystem::exists(tmp.path() + "/rig/image_03/calib_velo_to_cam.txt"));
  EXPECT_TRUE(std::filesystem::exists(tmp.path() + "/rig/image_03/report.html"));
  const nlohmann::json summary =
      nlohmann::json::parse(testing::ReadFile(tmp.path() + "/rig/result.json"));
  ASSERT_EQ(summary["cameras"].size(), 2u);
  ASSERT_EQ(summary["camera_pairs"].size(), 1u);
  const nlohmann::json& pair = summary["camera_pairs"][0];
  EXPECT_EQ(pair["from"], "image_02");
  EXPECT_EQ(pair["to"], "image_03");
  EXPECT_NEAR(pair["baseline_rig_m"].get<double>(), 0.535, 0.005);  // P_rect_02 and P_rect_03
  // Measured 0.264° and 3.4 cm (baseline +2.0 cm) with an expected spread of 0.16° and 15 cm.
  EXPECT_LT(pair["rotation_disagreement_deg"].get<double>(), 0.4);
  EXPECT_LT(pair["translation_disagreement_m"].get<double>(), 0.08);
  EXPECT_TRUE(pair["consistent"].get<bool>());
  EXPECT_TRUE(summary["rig_consistent"].get<bool>());
  // The joint estimate is one extrinsic: the same for both cameras (KITTI's share camera 0's).
  ASSERT_TRUE(summary["cameras"][0].contains("joint"));
  EXPECT_EQ(summary["cameras"][0]["joint"]["T_camera_lidar"],
            summary["cameras"][1]["joint"]["T_camera_lidar"]);
  EXPECT_LT(summary["cameras"][0]["joint"]["agreement_with_drive_calibration"]["rotation_deg"]
                .get<double>(),
            0.35);
  EXPECT_THAT(rig.output, HasSubstr("image_02 to image_03 against the rig's calibration"));
}

// A camera the drive does not have is an error naming it, not a run of the others; a name that
// is not a camera folder, a camera named twice and --cameras with a bag are usage errors.
TEST(Cli, CamerasMustBeTheDrivesOwn) {
  STCALIB_REQUIRE_KITTI_STEREO();
  const std::string drive = testing::KittiStereoDriveDir();
  testing::ScopedTempDir tmp;
  const std::string flags = "calibrate --drive=" + drive + " --out=" + tmp.path() + " ";
  const RunResult missing = RunStcalib(flags + "--cameras=image_02,image_07");
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_THAT(missing.output, HasSubstr("camera image_07"));
  EXPECT_FALSE(std::filesystem::exists(tmp.path() + "/image_02/result.json"));
  const RunResult bad = RunStcalib(flags + "--cameras=left");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_THAT(bad.output, HasSubstr("'left' is not a KITTI camera folder"));
  const RunResult twice = RunStcalib(flags + "--cameras=image_03,image_03");
  EXPECT_EQ(twice.exit_code, 2) << twice.output;
  EXPECT_THAT(twice.output, HasSubstr("names image_03 twice"));
  const RunResult bag = RunStcalib("calibrate --bag=" + tmp.path() +
                                   " --image_topic=a --cloud_topic=b --cameras=image_03");
  EXPECT_EQ(bag.exit_code, 2) << bag.output;
  const RunResult rig = RunStcalib("simulate --out=" + tmp.path() + "/s --cameras=5");
  EXPECT_EQ(rig.exit_code, 2) << rig.output;
  EXPECT_THAT(rig.output, HasSubstr("--cameras must be a number of cameras from 1 to 4"));
}

// The refined rotation (with the chosen candidate's translation and δ) is taken in place of the
// score map's best when it scores within 10 % of it (the map's peak sits a few tenths of a degree
// from the refinement's optimum on these frames). Measured over the 30 frames from 2° (seeds 1-4):
// 0.181, 0.139, 0.070 and 0.256° at the end with the default; 0.286, 0.231, 0.522 and 0.270° with
// the tolerance at 0 (the best score wins).
TEST(Cli, KittiTakesTheRefinedRotationWithinTheScoreTolerance) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  double sum_default = 0, sum_best_score = 0;
  bool taken_once = false;
  for (const int seed : {1, 2, 3, 4}) {
    double error[2] = {0, 0};
    for (const int k : {0, 1}) {
      const std::string tolerance = k == 0 ? "0.1" : "0";
      SCOPED_TRACE("seed " + std::to_string(seed) + ", tolerance " + tolerance);
      const std::string out = tmp.path() + "/s" + std::to_string(seed) + "_" + tolerance;
      const RunResult r = CalibrateKitti(
          out, "--seed=" + std::to_string(seed) + " --refined_score_tolerance=" + tolerance);
      const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
      error[k] = result["agreement_with_drive_calibration"]["rotation_deg"].get<double>();
      const std::string csv = testing::ReadFile(out + "/per_frame.csv");
      const bool taken = csv.find("its rotation only: score") != std::string::npos;
      if (k == 1) {
        EXPECT_FALSE(taken);
      }
      taken_once = taken_once || taken;
    }
    EXPECT_LE(error[0], error[1] + 0.02) << "seed " << seed;
    sum_default += error[0];
    sum_best_score += error[1];
  }
  EXPECT_TRUE(taken_once);
  EXPECT_LT(sum_default, sum_best_score - 0.3);
}

// δ started 50 ms off while the user states it is within 20 ms: the lattice's δ hypotheses do not
// reach the true δ and the local search cannot cross to it against its prior. Whatever the
// cadence, nothing may be claimed: a start farther off than its stated uncertainty is refused.
TEST(Cli, KittiWrongTimeOffsetIsRefused) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  for (const std::string every : {"1", "3"}) {
    SCOPED_TRACE(every);
    const std::string out = tmp.path() + "/out" + every;
    const RunResult r =
        CalibrateKitti(out,
                       "--seed=2 --perturb_time_s=0.05 --init_uncertainty=2,0.05,0.02 "
                       "--tracking_update_every=" +
                           every);
    EXPECT_EQ(r.exit_code, 1) << r.output;
    const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
    EXPECT_FALSE(result["converged"].get<bool>());
    EXPECT_FALSE(std::filesystem::exists(out + "/calib_velo_to_cam.txt"));
    EXPECT_THAT(r.output, HasSubstr("stcalib calibrate: not converged: "));
  }
}

// Sixteen frames from frame 10 (the first of them prefer a side peak 3.5° off): one hypothesis
// comes to dominate the others within them, and the run claims within 0.3° of KITTI's
// calibration (measured 0.071°; over 12 frames two rivals still stood at 1.8 and 1.9 standard
// errors). Six frames are too few for any hypothesis to dominate (DominanceOptions::min_frames,
// after two frames filling the window): nothing is claimed, and the reason names the runners-up.
TEST(Cli, KittiShortRunClaimsOnceOneHypothesisDominates) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  const std::string out = tmp.path() + "/out";
  const RunResult r = CalibrateKitti(out, "--seed=3 --first_frame=10 --num_frames=16");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_NE(result["phase"], "acquiring");
  EXPECT_LT(result["agreement_with_drive_calibration"]["rotation_deg"].get<double>(), 0.3);
  bool dominance_rule = false;
  for (const auto& rule : result["verdict_rules"]) {
    if (rule["name"] != "one_hypothesis_dominates") continue;
    dominance_rule = true;
    EXPECT_TRUE(rule["passed"].get<bool>());
  }
  EXPECT_TRUE(dominance_rule);
  EXPECT_GE(result["hypotheses"].size(), 2u);
  EXPECT_TRUE(std::filesystem::exists(out + "/calib_velo_to_cam.txt"));

  const std::string six = tmp.path() + "/six";
  const RunResult r6 = CalibrateKitti(six, "--seed=3 --first_frame=10 --num_frames=6");
  EXPECT_EQ(r6.exit_code, 1) << r6.output;
  EXPECT_THAT(r6.output, HasSubstr("still acquiring: no hypothesis dominates"));
  EXPECT_FALSE(std::filesystem::exists(six + "/calib_velo_to_cam.txt"));
}

// One frame alone (issue 5): with the default 3-frame search window nothing is updated and the
// reason says so; with a 1-frame window the frame gives an estimate (one frame's score is nearly
// flat: frame 0 seed 1 jumps to a hypothesis 4.9° off). Neither run claims convergence: one frame
// cannot show that an estimate has settled.
TEST(Cli, KittiSingleFrameEstimatesOnlyWithASingleFrameWindow) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  const std::string kept = tmp.path() + "/kept", single = tmp.path() + "/single";
  const RunResult r = CalibrateKitti(kept, "--seed=1 --num_frames=1");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("the estimate was never updated"));
  EXPECT_FALSE(std::filesystem::exists(kept + "/calib_velo_to_cam.txt"));
  const nlohmann::json kept_result =
      nlohmann::json::parse(testing::ReadFile(kept + "/result.json"));
  EXPECT_NEAR(kept_result["agreement_with_drive_calibration"]["rotation_deg"].get<double>(),
              kept_result["initial_error"]["rotation_deg"].get<double>(), 1e-9);

  const RunResult one = CalibrateKitti(single, "--seed=1 --num_frames=1 --window_frames=1");
  EXPECT_EQ(one.exit_code, 1) << one.output;
  EXPECT_THAT(one.output, Not(HasSubstr("never updated")));
  EXPECT_FALSE(std::filesystem::exists(single + "/calib_velo_to_cam.txt"));
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(single + "/result.json"));
  EXPECT_GT(result["initial_error"]["rotation_deg"].get<double>(), 3.4);
  EXPECT_NE(result["agreement_with_drive_calibration"]["rotation_deg"].get<double>(),
            result["initial_error"]["rotation_deg"].get<double>())
      << one.output;
}

// Issue 5's simulated protocol on one 20-frame drive (δ = +30 ms, 6 moving objects, ±2° on every
// axis, ±5 cm, δ0 = 0): the polish separates δ from the forward translation (std 1.7 cm) and the
// run meets all four criteria. Measured: 0.049°, translation 2.4 cm (y +1.2, z +2.1), δ error
// −1.8 ms, 0.09° at the fifth frame. Not every drive does (seeds 21 and 23: 0.197° with δ −1.1 ms;
// 0.084° with the pair held, 5.9 cm and δ −3.4 ms); the note reports the spread over seeds.
TEST(Cli, SimulatedDriveMeetsTheAcceptance) {
  testing::ScopedTempDir tmp;
  const std::string drive = SimulateDrive(tmp.path(), "--frames=20 --seed=22 --time_offset_s=0.03");
  ASSERT_FALSE(drive.empty());
  const std::string out = tmp.path() + "/out";
  const RunResult r = CalibrateFromTwoDegrees(drive, out, 22);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_TRUE(result["converged"].get<bool>()) << result["reason"];
  EXPECT_NEAR(result["initial_error"]["rotation_deg"].get<double>(), 2 * std::sqrt(3.0), 1e-6);
  EXPECT_NEAR(result["initial_error"]["translation_m"].get<double>(), 0.05 * std::sqrt(3.0), 1e-6);
  EXPECT_LE(result["error"]["rotation_deg"].get<double>(), 0.1) << r.output;
  EXPECT_LE(result["error"]["translation_m"].get<double>(), 0.03) << r.output;
  EXPECT_LE(std::abs(result["error"]["time_offset_s"].get<double>()), 0.003) << r.output;
  EXPECT_THAT(result["polish"]["reason"].get<std::string>(),
              HasSubstr("forward translation and δ refined"));
  // δ separated from the forward translation: observable, with the std of the solve that had
  // both free, which covers the error.
  EXPECT_EQ(result["time_offset_vs_forward"]["rests_on"], "window");
  EXPECT_TRUE(result["observable"]["time_offset_s"].get<bool>());
  EXPECT_LE(std::abs(result["error"]["time_offset_s"].get<double>()),
            3 * result["std"]["time_offset_s"].get<double>())
      << r.output;
  // So is the forward translation, its std the same solve's.
  EXPECT_TRUE(result["observable"]["z_m"].get<bool>());
  EXPECT_LE(std::abs(result["error"]["z_m"].get<double>()), 3 * result["std"]["z_m"].get<double>())
      << r.output;
  EXPECT_THAT(r.output, Not(HasSubstr("time offset: not separated")));
  EXPECT_LT(PerFrameNumber(testing::ReadFile(out + "/per_frame.csv"), 4, "rotation_error_deg"),
            0.5);
}

// A drive at walking pace (1.5 m/s): over the true δ of +30 ms the LiDAR moves 4.5 cm, which the
// score cannot see. The run claims what it observed (docs/method.md §7, partial claims): the
// rotation, with δ and the translation along travel held at the start and marked so in every
// output, exit 3. `check` reads the marked files back.
TEST(Cli, ASlowDriveClaimsItsRotationWithTheTimeOffsetHeld) {
  testing::ScopedTempDir tmp;
  const std::string drive =
      SimulateDrive(tmp.path(), "--frames=20 --seed=1 --time_offset_s=0.03 --speed_mps=1.5");
  ASSERT_FALSE(drive.empty());
  const std::string out = tmp.path() + "/out";
  const RunResult r = CalibrateFromTwoDegrees(drive, out, 1);
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_THAT(r.output, HasSubstr("PARTLY converged"));
  EXPECT_THAT(r.output, HasSubstr("time offset: held at its start"));
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_TRUE(result["converged"].get<bool>()) << result["reason"];
  EXPECT_EQ(result["claim"], "partial");
  EXPECT_EQ(result["held_axes"], nlohmann::json({"z_m", "time_offset_s"})) << result["reason"];
  EXPECT_LE(result["error"]["rotation_deg"].get<double>(), 0.3) << r.output;
  EXPECT_LE(std::abs(result["error"]["x_m"].get<double>()), 0.08) << r.output;
  EXPECT_LE(std::abs(result["error"]["y_m"].get<double>()), 0.08) << r.output;
  // The held values are the start's, marked in both files.
  EXPECT_EQ(result["time_offset_s"].get<double>(), 0.0);
  EXPECT_EQ(result["time_offset_vs_forward"]["rests_on"], "start");
  EXPECT_THAT(testing::ReadFile(out + "/time_offset.txt"), HasSubstr("# held at the start"));
  EXPECT_THAT(testing::ReadFile(out + "/calib_velo_to_cam.txt"),
              HasSubstr("held at the start (not observable in this drive): z_m"));
  const RunResult check = RunStcalib("check --drive=" + drive + " --init_calib=" + out +
                                     "/calib_velo_to_cam.txt --out=" + tmp.path() + "/check");
  EXPECT_NE(check.exit_code, 2) << check.output;
  EXPECT_THAT(check.output, HasSubstr("time_offset.txt: +0.0000 s")) << check.output;
}

// A start ±5° on each axis, ±20 cm and δ0 70 ms off, told with --init_uncertainty=5,0.2,0.1: the
// lattice holds it; the run claims, within 0.3° and 5 cm across travel. The same start with the
// default uncertainty (±3°, ±5 cm, ±30 ms), which does not hold it, must not claim.
TEST(Cli, CalibratesFromAWideStartWhenToldItsUncertainty) {
  testing::ScopedTempDir tmp;
  const std::string drive =
      SimulateDrive(tmp.path(), "--frames=30 --seed=102 --time_offset_s=0.03");
  ASSERT_FALSE(drive.empty());
  const std::string start =
      " --perturb_rot_deg=5 --perturb_trans_m=0.2 --perturb_time_s=-0.07 --seed=2";
  const std::string out = tmp.path() + "/out";
  const RunResult r = RunStcalib("calibrate --flagfile=" + std::string(STCALIB_SOURCE_DIR) +
                                 "/configs/sim.flags --drive=" + drive + start +
                                 " --init_uncertainty=5,0.2,0.1 --out=" + out);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_NEAR(result["initial_error"]["rotation_deg"].get<double>(), 5 * std::sqrt(3.0), 1e-6);
  EXPECT_TRUE(result["converged"].get<bool>()) << result["reason"];
  EXPECT_LE(result["error"]["rotation_deg"].get<double>(), 0.3) << r.output;
  EXPECT_LE(std::abs(result["error"]["x_m"].get<double>()), 0.05) << r.output;
  EXPECT_LE(std::abs(result["error"]["y_m"].get<double>()), 0.05) << r.output;
  EXPECT_LE(std::abs(result["error"]["time_offset_s"].get<double>()), 0.005) << r.output;

  const std::string told_narrow = tmp.path() + "/told_narrow";
  const RunResult r2 =
      RunStcalib("calibrate --flagfile=" + std::string(STCALIB_SOURCE_DIR) +
                 "/configs/sim.flags --drive=" + drive + start + " --out=" + told_narrow);
  EXPECT_NE(r2.exit_code, 0) << r2.output;
  const nlohmann::json result2 =
      nlohmann::json::parse(testing::ReadFile(told_narrow + "/result.json"));
  EXPECT_FALSE(result2["converged"].get<bool>()) << r2.output;
  EXPECT_FALSE(std::filesystem::exists(told_narrow + "/calib_velo_to_cam.txt"));
}

// Another rig than KITTI's: a 1280×720 camera, f 800 px, principal point off centre, mounted 3°
// nose-down, whose upper 40 % no LiDAR beam reaches. Everything image-sized is read from the
// image and the calib files. Measured: 0.153° (seed 5 on this drive), δ error +1.4 ms with the
// forward translation separated from δ by the polish (δ std 1.2 ms with both free), translation
// 5.8 cm from 8.7; 20-frame drives of seeds 1-8 end 0.046-0.124° off.
TEST(Cli, CalibratesAnotherCameraAndImageSize) {
  testing::ScopedTempDir tmp;
  const std::string drive =
      SimulateDrive(tmp.path(), "--frames=14 --seed=5 --time_offset_s=0.03 --camera=hd720");
  ASSERT_FALSE(drive.empty());
  EXPECT_THAT(testing::ReadFile(std::filesystem::path(drive).parent_path().string() +
                                "/calib_cam_to_cam.txt"),
              HasSubstr("S_rect_02: 1.280000000000e+03 7.200000000000e+02"));
  const std::string out = tmp.path() + "/out";
  const RunResult r = CalibrateFromTwoDegrees(drive, out, 5, kShortDrive);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_LT(result["error"]["rotation_deg"].get<double>(), 0.3) << r.output;
  EXPECT_LT(std::abs(result["error"]["time_offset_s"].get<double>()), 0.006) << r.output;
  EXPECT_LT(result["error"]["translation_m"].get<double>(), 0.08) << r.output;
  // Whatever δ rests on, its reported std covers its error.
  EXPECT_LE(std::abs(result["error"]["time_offset_s"].get<double>()),
            3 * result["std"]["time_offset_s"].get<double>())
      << result["time_offset_vs_forward"];
  EXPECT_EQ(result["motion"], "oxts");
  // The first two frames fill the search window without an update.
  EXPECT_LE(ExpectUpdateTimingMatches(result, testing::ReadFile(out + "/per_frame.csv"), 14), 12);
  cv::Mat overlay;
  ASSERT_TRUE(ReadImage(out + "/overlay_after.png", &overlay).ok());
  EXPECT_EQ(overlay.cols, 1280);
  EXPECT_EQ(overlay.rows, 720);
  // The legend, bottom left: a green dot (on an image edge) and a red one (off every edge).
  ASSERT_EQ(overlay.type(), CV_8UC3);
  const cv::Vec3b green = overlay.at<cv::Vec3b>(overlay.rows - 16, 14);
  const cv::Vec3b red = overlay.at<cv::Vec3b>(overlay.rows - 34, 14);
  EXPECT_GT(green[1], 200);
  EXPECT_LT(green[2], 120);
  EXPECT_GT(red[2], 200);
  EXPECT_LT(red[1], 120);
}

// `stcalib demo`, what scripts/demo runs: it simulates a drive (δ = +30 ms, moving objects),
// calibrates it from ±2° on each axis, ±5 cm and δ0 = 0, and prints truth, start, estimate and
// the pictures. The printed table is the run's result.json, and the δ line says what δ rests on.
// Measured (seed 1): 0.070°, translation (-0.5, -4.1, -4.9) cm with the forward axis held, δ
// error +6.3 ms, resting on the forward translation's prior (both free: std 2.5 ms and 2.3 cm,
// over the polish's 2 cm).
TEST(Cli, DemoCalibratesASimulatedDriveAndPrintsTheTable) {
  testing::ScopedTempDir tmp;
  const RunResult r = RunStcalib("demo --seed=1 --out=" + tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string out = tmp.path() + "/calibration";
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_TRUE(result["converged"].get<bool>()) << result["reason"];
  // The table's rows: total, roll, pitch, yaw [deg] | x, y, z [cm] | δ [ms]. The estimate's row
  // prints "held" (read as NaN here) on an axis result.json does not call observable.
  auto table_row = [&](const std::string& name) {
    std::vector<double> row(8, std::numeric_limits<double>::quiet_NaN());
    const size_t at = r.output.find("\n  " + name + " ");
    if (at == std::string::npos) return row;
    const size_t from = at + 3 + name.size();
    std::istringstream in(r.output.substr(from, r.output.find('\n', from) - from));
    size_t k = 0;
    for (std::string token; in >> token && k < row.size();) {
      if (token == "|") continue;
      if (token != "held") row[k] = std::stod(token);
      ++k;
    }
    return row;
  };
  const std::vector<double> truth = table_row("truth"), start = table_row("start"),
                            estimate = table_row("estimate");
  EXPECT_NEAR(truth[7], 30.0, 1e-9) << r.output;
  EXPECT_NEAR(start[0], 2 * std::sqrt(3.0), 1e-3) << r.output;
  for (int k = 1; k < 4; ++k) EXPECT_NEAR(std::abs(start[k]), 2.0, 1e-3) << r.output;
  for (int k = 4; k < 7; ++k) EXPECT_NEAR(std::abs(start[k]), 5.0, 0.05) << r.output;
  EXPECT_NEAR(start[7], 0.0, 1e-9);
  const nlohmann::json& error = result["error"];
  EXPECT_NEAR(estimate[0], error["rotation_deg"].get<double>(), 1e-3) << r.output;
  // Each axis: its value where result.json calls it observable, "held" where not.
  const char* names[7] = {"roll_deg", "pitch_deg", "yaw_deg", "x_m", "y_m", "z_m", "time_offset_s"};
  for (int k = 0; k < 7; ++k) {
    const bool observable = result["observable"][names[k]].get<bool>();
    EXPECT_EQ(std::isnan(estimate[k + 1]), !observable) << names[k] << "\n" << r.output;
    if (!observable) continue;
    const double value = k < 3   ? error[names[k]].get<double>()
                         : k < 6 ? 100 * error[names[k]].get<double>()
                                 : 1000 * result["time_offset_s"].get<double>();
    EXPECT_NEAR(estimate[k + 1], value, k < 3 ? 1e-3 : 0.05) << names[k] << "\n" << r.output;
  }
  EXPECT_LT(estimate[0], 0.3) << r.output;
  EXPECT_LT(std::abs(1000 * result["time_offset_s"].get<double>() - truth[7]), 10.0) << r.output;
  // δ's line exactly when result.json says it rests on the forward translation's prior.
  const bool on_prior = result["time_offset_vs_forward"]["rests_on"] == "forward_translation_prior";
  EXPECT_EQ(r.output.find("time offset: not separated") != std::string::npos, on_prior) << r.output;
  EXPECT_THAT(r.output, HasSubstr("\nconverged; "));
  // Every picture it names exists and decodes.
  int pictures = 0;
  for (const char* name : {"overlay_before.png", "overlay_after.png", "convergence.png"}) {
    const std::string path = out + "/" + name;
    EXPECT_THAT(r.output, HasSubstr(path)) << name;
    cv::Mat image;
    EXPECT_TRUE(ReadImage(path, &image).ok()) << path;
    pictures += !image.empty();
  }
  EXPECT_EQ(pictures, 3);
}

}  // namespace
}  // namespace stcalib

namespace stcalib {
namespace {

// Issue 56's acceptance on the shared KITTI drive: converted to a bag and calibrated through it,
// the estimate is the drive's (every number of result.json but the timings; 8 frames here, the
// full 20-frame run is in docs/results.md#ros-2-bags).
TEST(Cli, KittiThroughItsBagGivesTheDrivesEstimate) {
  STCALIB_REQUIRE_KITTI();
  testing::ScopedTempDir tmp;
  const std::string bag = tmp.path() + "/bag";
  const RunResult convert =
      RunStcalib("convert --drive=" + testing::KittiDriveDir() + " --bag=" + bag);
  ASSERT_EQ(convert.exit_code, 0) << convert.output;
  EXPECT_THAT(convert.output, HasSubstr("--odom_topic=/odom"));
  const std::string common = " --flagfile=" + std::string(STCALIB_SOURCE_DIR) +
                             "/configs/kitti.flags --drive=" + testing::KittiDriveDir() +
                             " --perturb_rot_deg=2 --seed=3 --num_frames=8";
  const RunResult from_drive = RunStcalib("calibrate" + common + " --out=" + tmp.path() + "/d");
  const RunResult from_bag =
      RunStcalib("calibrate" + common + " --bag=" + bag +
                 " --image_topic=/camera/image_raw --cloud_topic=/lidar/points "
                 "--odom_topic=/odom --out=" +
                 tmp.path() + "/b");
  EXPECT_EQ(from_bag.exit_code, from_drive.exit_code) << from_bag.output;
  const nlohmann::json d = nlohmann::json::parse(testing::ReadFile(tmp.path() + "/d/result.json"));
  const nlohmann::json b = nlohmann::json::parse(testing::ReadFile(tmp.path() + "/b/result.json"));
  EXPECT_EQ(b["motion"], "odometry");
  EXPECT_EQ(d["motion"], "oxts");
  for (int k = 0; k < 16; ++k) {
    EXPECT_NEAR(b["T_camera_lidar"][k].get<double>(), d["T_camera_lidar"][k].get<double>(), 1e-6);
  }
  EXPECT_NEAR(b["time_offset_s"].get<double>(), d["time_offset_s"].get<double>(), 1e-6);
  EXPECT_EQ(b["converged"], d["converged"]);
  EXPECT_NEAR(b["agreement_with_drive_calibration"]["rotation_deg"].get<double>(),
              d["agreement_with_drive_calibration"]["rotation_deg"].get<double>(), 1e-6);

  // The other readers take the bag too: check on it says what check on the drive says.
  const std::string topics =
      " --bag=" + bag + " --image_topic=/camera/image_raw --cloud_topic=/lidar/points";
  const RunResult check_bag = RunStcalib("check" + topics + " --odom_topic=/odom --num_frames=12");
  const RunResult check_drive =
      RunStcalib("check --drive=" + testing::KittiDriveDir() + " --num_frames=12");
  EXPECT_EQ(check_bag.exit_code, check_drive.exit_code);
  auto verdict = [](const std::string& output) { return output.substr(output.find("\naxis")); };
  EXPECT_EQ(verdict(check_bag.output), verdict(check_drive.output)) << check_bag.output;
  EXPECT_EQ(RunStcalib("project" + topics + " --frame=3 --out=" + tmp.path() + "/p.png").exit_code,
            0);
  EXPECT_THAT(RunStcalib("info" + topics).output, HasSubstr("the bag's tf"));

  // A topic the bag does not have: the error lists what it has.
  const RunResult wrong = RunStcalib(
      "calibrate --bag=" + bag + " --image_topic=/camera/image_rect --cloud_topic=/lidar/points");
  EXPECT_EQ(wrong.exit_code, 1);
  EXPECT_THAT(wrong.output, HasSubstr("no topic /camera/image_rect"));
  EXPECT_THAT(wrong.output, HasSubstr("/lidar/points  [sensor_msgs/msg/PointCloud2]"));
  EXPECT_EQ(RunStcalib("calibrate --bag=" + bag).exit_code, 2);  // no topics
  EXPECT_EQ(RunStcalib("convert --drive=" + testing::KittiDriveDir()).exit_code, 2);
  // The bag folder exists: convert writes no second bag into it.
  const RunResult again =
      RunStcalib("convert --drive=" + testing::KittiDriveDir() + " --bag=" + bag);
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_THAT(again.output, HasSubstr("exists and is not empty"));
}

// An Ouster OS1-64 and a raw camera with k1 = −0.3, δ = +30 ms, through a bag written as
// ouster-ros writes clouds (organized, uint32 ns times, stamped at the sweep's start).
// Measured: 0.059° (this seed; from the drive itself 0.023°), docs/results.md#ros-2-bags.
TEST(Cli, CalibratesAnOusterBagWithARawCamera) {
  testing::ScopedTempDir tmp;
  const std::string drive = SimulateDrive(
      tmp.path(),
      "--frames=20 --seed=104 --time_offset_s=0.03 --lidar=os1-64 --distortion_k1=-0.3");
  ASSERT_FALSE(drive.empty());
  const std::string bag = tmp.path() + "/bag";
  const RunResult convert = RunStcalib("convert --drive=" + drive + " --bag=" + bag);
  ASSERT_EQ(convert.exit_code, 0) << convert.output;
  const std::string out = tmp.path() + "/out";
  const RunResult r = RunStcalib("calibrate --flagfile=" + std::string(STCALIB_SOURCE_DIR) +
                                 "/configs/sim.flags --bag=" + bag +
                                 " --image_topic=/camera/image_raw --cloud_topic=/lidar/points "
                                 "--odom_topic=/odom --perturb_rot_deg=2 --perturb_trans_m=0.05 "
                                 "--seed=104 --out=" +
                                 out);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_EQ(result["reference"], "ground truth (simulated)");
  EXPECT_LE(result["error"]["rotation_deg"].get<double>(), 0.3) << r.output;
  EXPECT_LE(std::abs(result["error"]["time_offset_s"].get<double>()), 0.01) << r.output;
}

}  // namespace
}  // namespace stcalib
