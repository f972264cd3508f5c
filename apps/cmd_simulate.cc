// stcalib simulate: a KITTI-raw drive with exact ground truth.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "apps/commands.h"
#include "apps/flags.h"
#include "core/sim/simulator.h"

namespace stcalib::cli {

int RunSimulate() {
  if (FLAGS_out.empty()) return UsageError("simulate", "--out=DIR is required");
  sim::SimulatorOptions options;
  options.frames = FLAGS_frames;
  options.seed = FLAGS_seed;
  options.time_offset_s = FLAGS_time_offset_s;
  options.dynamic_objects = FLAGS_dynamic_objects;
  options.lidar_hz = FLAGS_lidar_hz;
  options.oxts_error.position_white_m = FLAGS_oxts_white_position_m;
  if (!(FLAGS_oxts_error_scale >= 0.0 && FLAGS_oxts_error_scale <= 10.0)) {
    return UsageError("simulate", "--oxts_error_scale must be between 0 and 10, got " +
                                      std::to_string(FLAGS_oxts_error_scale));
  }
  options.oxts_error = options.oxts_error.Scaled(FLAGS_oxts_error_scale);
  if (!sim::ParseSceneType(FLAGS_scene, &options.scene)) {
    return UsageError("simulate",
                      "--scene must be " + sim::SceneTypeChoices() + ", got '" + FLAGS_scene + "'");
  }
  if (!sim::ParseSimCamera(FLAGS_camera, &options.camera)) {
    return UsageError(
        "simulate", "--camera must be " + sim::SimCameraChoices() + ", got '" + FLAGS_camera + "'");
  }
  if (!sim::ParseSimLidar(FLAGS_lidar, &options.lidar)) {
    return UsageError("simulate",
                      "--lidar must be " + sim::SimLidarChoices() + ", got '" + FLAGS_lidar + "'");
  }
  if (!FLAGS_cameras.empty()) {  // simulate reads --cameras as the rig's number of cameras
    char* end = nullptr;
    const long cameras = std::strtol(FLAGS_cameras.c_str(), &end, 10);
    if (end == FLAGS_cameras.c_str() || *end != '\0') {
      return UsageError("simulate",
                        "--cameras must be a number of cameras, got '" + FLAGS_cameras + "'");
    }
    // Its range is SimulatorOptions::Validate's (below); clamped only to fit an int.
    options.cameras = static_cast<int>(std::clamp(cameras, -1L, 1000L));
  }
  options.distortion_k1 = FLAGS_distortion_k1;
  options.speed_mps = FLAGS_speed_mps;
  const Status valid = options.Validate();
  if (!valid.ok()) return UsageError("simulate", valid.message());

  const auto start = std::chrono::steady_clock::now();
  std::string drive_dir;
  const Status status =
      sim::WriteSimulatedDrive(options, FLAGS_out, &drive_dir, [](int done, int total) {
        std::fprintf(stderr, "\rsimulate: frame %d/%d", done, total);
        if (done == total) std::fprintf(stderr, "\n");
      });
  if (!status.ok()) return ReportError("simulate", status);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "simulated %d frames (scene %s, camera %s x %d, lidar %s, seed %llu, time offset %+.4f s, "
      "%d moving objects) in %.1f s\ndrive: %s\n",
      options.frames, sim::SceneTypeName(options.scene).c_str(),
      sim::SimCameraName(options.camera).c_str(), options.cameras,
      sim::SimLidarName(options.lidar).c_str(), static_cast<unsigned long long>(options.seed),
      options.time_offset_s, options.dynamic_objects, seconds, drive_dir.c_str());
  return kExitOk;
}

}  // namespace stcalib::cli
