// stcalib check: does the stored calibration still hold? (docs/method.md §7 and §9)
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>

#include "apps/commands.h"
#include "apps/flags.h"
#include "apps/report.h"
#include "core/io/image.h"
#include "core/io/kitti_calib.h"
#include "core/io/text.h"
#include "core/online/frame_source.h"
#include "core/online/calibration_check.h"

namespace stcalib::cli {

int RunCheck() {
  const char* kCommand = "check";
  if (FLAGS_drive.empty() && FLAGS_bag.empty()) {
    return UsageError(kCommand, "--drive=DRIVE_DIR or --bag=DIR is required");
  }
  CalibrationCheckOptions options;
  Status status = options.Validate();
  if (!status.ok()) return UsageError(kCommand, status.message());
  Drive drive;
  status = OpenDriveOrBagFromFlags(&drive);
  if (!status.ok()) return ReportError(kCommand, status);

  CalibrationState calibration;
  std::mt19937_64 rng(FLAGS_seed);
  status = StartingCalibration(drive, FLAGS_init_calib, FLAGS_perturb_rot_deg,
                               FLAGS_perturb_trans_m, &rng, &calibration.T_camera_lidar);
  if (!status.ok()) return ReportError(kCommand, status);
  // δ: stcalib's time_offset.txt beside the checked calib_velo_to_cam.txt when there is one
  // (what `calibrate --out` writes), plus --perturb_time_s.
  const std::string calib_path =
      FLAGS_init_calib.empty() ? drive.calib_dir + "/calib_velo_to_cam.txt" : FLAGS_init_calib;
  const std::string time_offset_path =
      (std::filesystem::path(calib_path).parent_path() / kTimeOffsetFileName).string();
  double stored_time_offset_s = 0;
  std::error_code ec;
  const bool has_time_offset = std::filesystem::exists(time_offset_path, ec);
  if (has_time_offset) {
    status = ReadTimeOffset(time_offset_path, &stored_time_offset_s);
    if (!status.ok()) return ReportError(kCommand, status);
  }
  calibration.time_offset_s = stored_time_offset_s + FLAGS_perturb_time_s;

  const int count = static_cast<int>(drive.NumFrames());
  const int first = FLAGS_first_frame;
  const int last = FLAGS_num_frames > 0 ? first + FLAGS_num_frames - 1 : count - 1;
  if (first < 0 || first >= count || last >= count) {
    return ReportError(
        kCommand, Status::Error(drive.drive_dir + ": frames " + std::to_string(first) + ".." +
                                std::to_string(last) + " out of range (" + std::to_string(count) +
                                " frames)"));
  }
  FrameSourceOptions source_options;
  source_options.local_map.sweeps = kCheckLocalMapSweeps;
  status = ImageOptionsFromFlags(&source_options.image);  // the edges calibrate read
  if (!status.ok()) return UsageError(kCommand, status.message());
  source_options.view_T_camera_lidar = calibration.T_camera_lidar;  // the view it checks
  std::unique_ptr<DriveFrameSource> source;
  status = DriveFrameSource::Create(&drive, source_options, &source);
  if (!status.ok()) return ReportError(kCommand, status);
  std::vector<std::shared_ptr<const CalibrationFrame>> frames;
  for (int i = first; i <= last; ++i) {
    auto frame = std::make_shared<CalibrationFrame>();
    status = source->Load(i, frame.get());
    if (!status.ok()) {
      std::fprintf(stderr, "stcalib check: frame %d skipped: %s\n", i, status.message().c_str());
      continue;
    }
    frames.push_back(frame);
  }
  const CalibrationCheckResult result = CheckCalibration(frames, calibration, options);

  std::printf("calibration checked: %s%s; time offset %+.4f s (%s%+.4f s%s)\n", calib_path.c_str(),
              FLAGS_perturb_rot_deg != 0 || FLAGS_perturb_trans_m != 0 ? " (perturbed)" : "",
              calibration.time_offset_s,
              has_time_offset ? (time_offset_path + ": ").c_str() : "none stored: ",
              stored_time_offset_s, FLAGS_perturb_time_s != 0 ? ", plus --perturb_time_s" : "");
  std::printf("%-16s %10s %10s %10s  %s\n", "axis", "offset", "std", "tolerance", "");
  nlohmann::json axes = nlohmann::json::array();
  for (int axis = 0; axis < kNumAxes; ++axis) {
    const AxisCheck& a = result.axes[axis];
    std::printf("%-16s %+10.4f %10.4f %10.4f  %s\n", kAxisNames[axis], a.offset, a.std,
                a.tolerance, a.off ? "off" : a.resolved ? "within" : "not resolved");
    axes.push_back({{"axis", kAxisNames[axis]},
                    {"offset", a.offset},
                    {"std", a.std},
                    {"tolerance", a.tolerance},
                    {"resolved", a.resolved},
                    {"off", a.off}});
  }
  std::printf("%s\n", result.reason.c_str());
  if (!FLAGS_out.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(FLAGS_out, ec);
    const nlohmann::json j = {{"calibration", calib_path},
                              {"time_offset_s", calibration.time_offset_s},
                              {"answer", CheckAnswerName(result.answer)},
                              {"reason", result.reason},
                              {"frames_used", result.frames_used},
                              {"blocks", result.blocks},
                              {"block_frames", result.block_frames},
                              {"t_quantile", result.t_quantile},
                              {"rotation_offset_deg", result.rotation_offset_deg},
                              {"rotation_std_deg", result.rotation_std_deg},
                              {"tolerance_rotation_deg", options.tolerance_rotation_deg},
                              {"axes", axes},
                              {"stcalib_version", StcalibVersion()},
                              {"command", CommandLineText()},
                              {"input", FLAGS_bag.empty() ? FLAGS_drive : FLAGS_bag}};
    status = WriteTextFile(FLAGS_out + "/check.json", j.dump(2) + "\n");
    if (!status.ok()) return ReportError(kCommand, status);
    // The report's strip: checked frames at the checked calibration.
    status = WriteFrameStrip(drive, frames,
                             {{"checked_", calibration, "at the checked calibration"}}, FLAGS_out);
    if (!status.ok()) return ReportError(kCommand, status);
    status = WriteRunReport(FLAGS_out);
    if (!status.ok()) return ReportError(kCommand, status);
  }
  switch (result.answer) {
    case CheckAnswer::kHolds:
      return kExitOk;
    case CheckAnswer::kOff:
      return kExitCheckOff;
    case CheckAnswer::kCannotTell:
      break;
  }
  return kExitCannotTell;
}

}  // namespace stcalib::cli
