// Reading and projecting one KITTI frame (docs/method.md §10: decoding a PNG ≈ 8 ms, a .bin ≈ 0.1
// ms).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <opencv2/core.hpp>

#include "core/io/drive.h"
#include "core/io/image.h"
#include "core/score/projection.h"
#include "core/viz/overlay.h"

namespace stcalib {
namespace {

const std::string kDrive =
    std::string(STCALIB_SHARED_DATA_DIR) + "/kitti/2011_09_26/2011_09_26_drive_0013_sync";

bool OpenKitti(benchmark::State& state, Drive* drive) {
  if (!std::filesystem::is_directory(kDrive)) {
    state.SkipWithError(("shared KITTI data not found at " + kDrive).c_str());
    return false;
  }
  const Status status = OpenDrive(kDrive, "", drive);
  if (!status.ok()) state.SkipWithError(status.message().c_str());
  return status.ok();
}

void BM_ReadVelodyneBin(benchmark::State& state) {
  Drive drive;
  if (!OpenKitti(state, &drive)) return;
  for (auto _ : state) {
    LidarScan scan;
    benchmark::DoNotOptimize(ReadVelodyneBin(drive.VelodynePath(0), &scan).ok());
  }
}
BENCHMARK(BM_ReadVelodyneBin)->Unit(benchmark::kMillisecond);

void BM_DecodePng(benchmark::State& state) {
  Drive drive;
  if (!OpenKitti(state, &drive)) return;
  for (auto _ : state) {
    cv::Mat image;
    benchmark::DoNotOptimize(ReadImage(drive.ImagePath(0), &image).ok());
  }
}
BENCHMARK(BM_DecodePng)->Unit(benchmark::kMillisecond);

void BM_OpenDrive(benchmark::State& state) {
  Drive drive;
  if (!OpenKitti(state, &drive)) return;
  for (auto _ : state) benchmark::DoNotOptimize(OpenDrive(kDrive, "", &drive).ok());
}
BENCHMARK(BM_OpenDrive)->Unit(benchmark::kMillisecond);

void BM_ProjectFrame(benchmark::State& state) {
  Drive drive;
  if (!OpenKitti(state, &drive)) return;
  LidarScan scan;
  if (!drive.LoadScan(0, &scan).ok()) return state.SkipWithError("cannot read scan");
  const CameraModel camera =
      MakeCameraModel(drive.camera, drive.camera.image_width, drive.camera.image_height);
  for (auto _ : state) {
    benchmark::DoNotOptimize(ProjectPoints(camera, drive.T_camera_lidar, scan.points_lidar));
  }
  state.SetItemsProcessed(state.iterations() * scan.size());
}
BENCHMARK(BM_ProjectFrame)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace stcalib
