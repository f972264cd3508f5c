// stcalib: targetless, online LiDAR–camera calibration of rotation, translation and time offset.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "apps/flags.h"
#include "core/types/heap.h"

namespace stcalib::cli {
namespace {

// A flag's default as a person writes it: "none" when empty, a double in its shortest form that
// reads back to the same value (0.15, not gflags' 0.14999999999999999).
std::string DefaultAsWritten(const gflags::CommandLineFlagInfo& info) {
  if (info.default_value.empty()) return "none";
  if (info.type != "double") return info.default_value;
  const double value = std::strtod(info.default_value.c_str(), nullptr);
  char text[32];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(text, sizeof(text), "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return text;
}

std::string& Positional() {
  static std::string positional;
  return positional;
}

std::string& CommandLine() {
  static std::string command_line;
  return command_line;
}

struct Subcommand {
  const char* name;
  const char* synopsis;
  const char* summary;
  int (*run)();
  // The options that matter (at most 20), listed by --help with their defaults and meanings;
  // --helpfull lists every flag.
  std::vector<const char*> options;
};

const std::vector<Subcommand>& Subcommands() {
  static const std::vector<Subcommand> kSubcommands = {
      {"info",
       "(--drive=DRIVE_DIR [--calib_dir=DIR] | --bag=DIR --image_topic=T --cloud_topic=T)",
       "frames, sensor rates, stamp gaps, points per frame and the calibration of a drive or bag",
       &RunInfo,
       {"drive", "calib_dir", "bag", "image_topic", "cloud_topic"}},
      {"project",
       "(--drive=DRIVE_DIR [--calib_dir=DIR] | --bag=DIR --image_topic=T --cloud_topic=T) "
       "--frame=I --out=FILE.png",
       "LiDAR points of one frame projected on its image, coloured by depth",
       &RunProject,
       {"drive", "frame", "out", "calib_dir", "bag", "image_topic", "cloud_topic"}},
      {"simulate",
       "--out=DIR [--frames=N (40)] [--seed=S (1)] [--time_offset_s=X (0)] "
       "[--dynamic_objects=K (6)] [--scene=urban|poles|open] [--lidar_hz=10] "
       "[--camera=kitti|kitti_1003|hd720] [--lidar=hdl64|vlp16|os1-64] [--distortion_k1=K] "
       "[--speed_mps=V] [--oxts_white_position_m=0.001] [--oxts_error_scale=1] [--cameras=N (1)]",
       "a KITTI-raw drive with exact ground truth (extrinsic, time offset, motion, labels)",
       &RunSimulate,
       {"out", "frames", "seed", "time_offset_s", "dynamic_objects", "scene", "camera", "lidar",
        "cameras", "distortion_k1", "speed_mps", "lidar_hz", "oxts_white_position_m",
        "oxts_error_scale"}},
      {"features",
       "(--drive=DRIVE_DIR [--calib_dir=DIR] | --bag=DIR --image_topic=T --cloud_topic=T) "
       "--frame=I --out=DIR",
       "image edge mask and IDT, LiDAR edge points (vertical, horizontal, dynamic) as PNGs",
       &RunFeatures,
       {"drive", "frame", "out", "calib_dir", "detector", "bag", "image_topic", "cloud_topic",
        "odom_topic"}},
      {"calibrate",
       "(--drive=DRIVE_DIR [--calib_dir=DIR] | --bag=DIR --image_topic=T --cloud_topic=T "
       "[--camera_info_topic=T] [--odom_topic=T | --imu_topic=T]) [--cameras=image_02,image_03 "
       "[--rig_joint]] "
       "[--init_calib=FILE] [--perturb_rot_deg=D] "
       "[--perturb_trans_m=M] [--perturb_time_s=S] [--init_uncertainty=DEG,M,S] [--seed=S] "
       "[--first_frame=I] [--num_frames=N] [--out=DIR] [--flagfile=configs/X.flags]",
       "online calibration of rotation, translation and time offset; with --out writes the "
       "estimate, result.json, per_frame.csv, pictures and report.html, without it prints the "
       "estimate; exit 0 when converged, 3 when converged partly (held axes at the start)",
       &RunCalibrate,
       {"drive",
        "bag",
        "image_topic",
        "cloud_topic",
        "cameras",
        "init_calib",
        "out",
        "first_frame",
        "num_frames",
        "perturb_rot_deg",
        "perturb_trans_m",
        "perturb_time_s",
        "init_uncertainty",
        "seed",
        "estimate_time_offset",
        "time_offset_bound_s",
        "prior_sigma_translation_m",
        "detector",
        "remove_dynamic",
        "polish"}},
      {"eval-temporal",
       "--drive=DRIVE_DIR [--lidar_decimation=2] [--lidar_delay_s=0.1] [--out=DIR]",
       "the paper's Table I: ApproximateTime pairing vs the motion model (filter_cloud, "
       "infer_cloud, infer_cloud_interpolation); prints the tables, --out also writes them",
       &RunEvalTemporal,
       {"drive", "lidar_decimation", "lidar_delay_s", "eval_max_range_m", "out"}},
      {"check",
       "(--drive=DRIVE_DIR [--calib_dir=DIR] | --bag=DIR --image_topic=T --cloud_topic=T) "
       "[--init_calib=FILE] [--perturb_rot_deg=D] "
       "[--perturb_trans_m=M] [--perturb_time_s=S (added to the stored δ)] [--seed=S] "
       "[--first_frame=I] "
       "[--num_frames=N] [--out=DIR]",
       "tests the stored calibration (δ from time_offset.txt beside it) against the drive's own "
       "optimum and its spread: exit 0 when it holds, 4 when it is off, 5 when the drive cannot "
       "tell, with the per-axis evidence",
       &RunCheck,
       {"drive", "calib_dir", "bag", "image_topic", "cloud_topic", "odom_topic", "init_calib",
        "perturb_rot_deg", "perturb_trans_m", "perturb_time_s", "seed", "first_frame", "num_frames",
        "out"}},
      {"convert",
       "--drive=DRIVE_DIR [--calib_dir=DIR] --bag=OUT_DIR",
       "a drive written as a ROS 2 bag (MCAP): image, camera info, cloud with rings and point "
       "times, odometry from the oxts, /tf_static; calibrate --bag reads it back",
       &RunConvert,
       {"drive", "calib_dir", "bag"}},
      {"report",
       "RUN_DIR",
       "report.html of a calibrate or check run folder, written again from the folder's own "
       "files",
       &RunReport,
       {}},
      {"demo",
       "[--out=DIR] [--seed=S]",
       "simulate a drive (true time offset +30 ms), calibrate it from +-2 deg / +-5 cm, print "
       "truth, start, estimate and error",
       &RunDemo,
       {"out", "seed"}},
  };
  return kSubcommands;
}

void PrintUsage(std::ostream& out) {
  out << "stcalib: targetless online LiDAR-camera calibration (rotation, translation, time "
         "offset)\n\nUsage: stcalib <subcommand> [--flags]\n\nSubcommands:\n";
  for (const Subcommand& s : Subcommands()) {
    out << "  " << s.name << " " << s.synopsis << "\n      " << s.summary << "\n";
  }
  out << "\nExit codes: 0 success, 1 failure (bad input or negative result), 2 usage error.\n"
         "`stcalib <subcommand> --helpfull` lists every flag with its default.\n";
}

}  // namespace

int Main(int argc, char** argv) {
  // Per-frame buffers are reused instead of faulted in afresh each frame (core/types/heap.h).
  RetainFreedHeapMemory();
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "help") == 0) {
    PrintUsage(argc < 2 ? std::cerr : std::cout);
    return argc < 2 ? kExitUsage : kExitOk;
  }
  const std::string name = argv[1];
  for (int i = 0; i < argc; ++i) CommandLine() += (i ? " " : "") + std::string(argv[i]);
  const Subcommand* command = nullptr;
  for (const Subcommand& s : Subcommands()) {
    if (name == s.name) command = &s;
  }
  if (command == nullptr) {
    std::cerr << "stcalib: unknown subcommand '" << name << "'\n\n";
    PrintUsage(std::cerr);
    return kExitUsage;
  }
  for (int i = 2; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::cout << "Usage: stcalib " << command->name << " " << command->synopsis << "\n  "
                << command->summary << "\n\nOptions:\n";
      for (const char* option : command->options) {
        gflags::CommandLineFlagInfo info;
        CHECK(gflags::GetCommandLineFlagInfo(option, &info)) << option;
        std::cout << "  --" << info.name << " (default: " << DefaultAsWritten(info) << ")\n      "
                  << info.description << "\n";
      }
      std::cout << "\nEvery other flag, with its default: stcalib " << command->name
                << " --helpfull\n";
      return kExitOk;
    }
  }
  // Drop the subcommand so that gflags sees only flags.
  std::vector<char*> args(argv, argv + argc);
  args.erase(args.begin() + 1);
  int args_count = static_cast<int>(args.size());
  char** args_data = args.data();
  gflags::SetUsageMessage(std::string("stcalib ") + command->name + " " + command->synopsis);
  gflags::ParseCommandLineFlags(&args_count, &args_data, /*remove_flags=*/true);
  // `report` takes its run folder as the one argument that is not a flag.
  if (name == "report" && args_count == 2) {
    Positional() = args_data[1];
  } else if (args_count > 1) {
    return UsageError(command->name, std::string("unexpected argument '") + args_data[1] + "'");
  }
  FLAGS_logtostderr = true;
  google::InitGoogleLogging(argv[0]);
  return command->run();
}

const std::string& PositionalArgument() { return Positional(); }
const std::string& CommandLineText() { return CommandLine(); }

}  // namespace stcalib::cli

int main(int argc, char** argv) { return stcalib::cli::Main(argc, argv); }
