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
#include "core/online/health_check.h"

namespace stcalib::cli {

int RunCheck() {
  const char* kCommand = "check";
  if (FLAGS_drive.empty() && FLAGS_bag.empty()) {
    return UsageError(kCommand, "--drive=DRIVE_DIR or --bag=DIR is required");
  }
  HealthCheckOptions options;
  options.window_frames = FLAGS_window_frames;
  options.min_health = FLAGS_min_health;
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
  // The texture-suppressed maps: foliage puts an image edge near almost any point, which makes a
  // plain map's health flat (a calibration 1° off still scores near its neighbours).
  FrameSourceOptions source_options;
  source_options.suppress_texture = true;
  source_options.local_map.sweeps = FLAGS_local_map_sweeps;
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
  const HealthCheckResult result = CheckCalibrationHealth(frames, calibration, options);

  std::printf("calibration checked: %s%s; time offset %+.4f s (%s%+.4f s%s)\n", calib_path.c_str(),
              FLAGS_perturb_rot_deg != 0 || FLAGS_perturb_trans_m != 0 ? " (perturbed)" : "",
              calibration.time_offset_s,
              has_time_offset ? (time_offset_path + ": ").c_str() : "none stored: ",
              stored_time_offset_s, FLAGS_perturb_time_s != 0 ? ", plus --perturb_time_s" : "");
  std::printf(
      "health = share of the 728 neighbours at +-%.1f deg / +-%.2f m scoring worse; best "
      "neighbour = the largest score gain among them\n",
      options.rotation_step_deg, options.translation_step_m);
  nlohmann::json windows = nlohmann::json::array();
  for (const WindowHealth& w : result.windows) {
    if (w.used) {
      std::printf(
          "  frames %4d-%-4d %6d points  health %.3f  best neighbour %+5.1f%%  gray rate %.3f\n",
          w.first_frame, w.last_frame, w.points, w.health, 100 * w.best_neighbour_gain,
          w.gray_rate);
    } else {
      std::printf("  frames %4d-%-4d skipped: %s\n", w.first_frame, w.last_frame, w.note.c_str());
    }
    windows.push_back({{"first_frame", w.first_frame},
                       {"last_frame", w.last_frame},
                       {"points", w.points},
                       {"used", w.used},
                       {"health", w.health},
                       {"best_neighbour_gain", w.best_neighbour_gain},
                       {"gray_rate", w.gray_rate},
                       {"note", w.note}});
  }
  std::printf("%s\n", result.reason.c_str());
  if (!FLAGS_out.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(FLAGS_out, ec);
    const nlohmann::json j = {{"calibration", calib_path},
                              {"time_offset_s", calibration.time_offset_s},
                              {"decided", result.decided},
                              {"holds", result.holds},
                              {"mean_health", result.mean_health},
                              {"min_window_health", result.min_window_health},
                              {"min_health", options.min_health},
                              {"mean_neighbour_gain", result.mean_neighbour_gain},
                              {"max_neighbour_gain", options.max_neighbour_gain},
                              {"reason", result.reason},
                              {"windows", windows},
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
  return result.decided && result.holds ? kExitOk : kExitFailure;
}

}  // namespace stcalib::cli
