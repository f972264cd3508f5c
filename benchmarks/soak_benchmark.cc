// Memory over a long drive (issue 53): the calibrator's memory must be bounded by its windows,
// not by the drive. The shared KITTI drive's frames are replayed in a loop with their stamps
// shifted past the loop's end, each loaded afresh through the frame source (one ahead, on a
// second thread, as `stcalib calibrate` does) and added to one calibrator that started 2° off:
// 600 frames in all. Counters: the process's peak resident memory (VmHWM) after 20, 60, 200 and
// 600 frames [MB], and the mean wall time per frame [ms] over each stretch.
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "core/online/frame_prefetcher.h"
#include "core/online/frame_source.h"
#include "core/online/online_calibrator.h"
#include "core/types/calibration.h"

namespace stcalib {
namespace {

// A field of /proc/self/status in kB ("VmHWM", "VmRSS"); 0 when unreadable.
double ProcStatusKb(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1));
  }
  return 0;
}

void BM_SoakReplayedDrive(benchmark::State& state) {
  const std::string dir =
      std::string(STCALIB_SHARED_DATA_DIR) + "/kitti/2011_09_26/2011_09_26_drive_0013_sync";
  Drive drive;
  if (!std::filesystem::is_directory(dir) || !OpenDrive(dir, "", &drive).ok()) {
    return state.SkipWithError("shared KITTI data not found");
  }
  cv::setNumThreads(1);
  FrameSourceOptions source_options;
  const int frames = static_cast<int>(drive.NumFrames());
  const int total = static_cast<int>(state.range(0));
  const int checkpoints[] = {20, 60, 200, 600};
  for (auto _ : state) {
    CalibrationState start;
    start.T_camera_lidar = PerturbTcameraLidar(drive.T_camera_lidar, Eigen::Vector3d(2, -2, 2),
                                               Eigen::Vector3d::Zero());
    OnlineCalibrator calibrator(OnlineCalibratorOptions(), start);
    int added = 0, next_checkpoint = 0, updates = 0;
    auto stretch_start = std::chrono::steady_clock::now();
    int stretch_first = 0;
    for (int cycle = 0; added < total; ++cycle) {
      // A new source per loop: its sweep cache must not serve the previous loop's sweeps.
      std::unique_ptr<DriveFrameSource> source;
      if (!DriveFrameSource::Create(&drive, source_options, &source).ok()) {
        return state.SkipWithError("frame source");
      }
      const int last = std::min(frames - 1, total - added - 1);
      FramePrefetcher prefetcher(source.get(), 0, last);
      FramePrefetcher::Loaded loaded;
      while (prefetcher.Next(&loaded)) {
        if (!loaded.cameras[0].status.ok())
          return state.SkipWithError(loaded.cameras[0].status.message().c_str());
        loaded.cameras[0].frame->camera_time_s +=
            cycle * (frames * 0.1 + 1.0);  // a loop after the last
        const FrameReport report = calibrator.AddFrame(std::move(loaded.cameras[0].frame));
        if (report.skipped) return state.SkipWithError(report.reason.c_str());
        updates += report.ran_update();
        ++added;
        if (next_checkpoint < 4 && added == checkpoints[next_checkpoint]) {
          const double ms = std::chrono::duration<double, std::milli>(
                                std::chrono::steady_clock::now() - stretch_start)
                                .count();
          const std::string n = std::to_string(added);
          state.counters["peak_MB_" + n] = ProcStatusKb("VmHWM") / 1024.0;
          state.counters["ms_per_frame_to_" + n] = ms / (added - stretch_first);
          stretch_start = std::chrono::steady_clock::now();
          stretch_first = added;
          ++next_checkpoint;
        }
      }
    }
    state.counters["updates"] = updates;
    state.SetLabel(calibrator.acquiring() ? "still acquiring" : "tracking at the end");
  }
}
BENCHMARK(BM_SoakReplayedDrive)->Arg(600)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
}  // namespace stcalib
