// Producing infer_cloud for one image (issue 6): the paired sweep carried to the image time by
// the motion model. Must stay far under the 100 ms frame period.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "core/features/lidar_frame.h"
#include "core/io/drive.h"
#include "core/motion/drive_motion.h"
#include "core/motion/motion_model.h"

namespace stcalib {
namespace {

void BM_InferCloud(benchmark::State& state) {
  const std::string dir =
      std::string(STCALIB_SHARED_DATA_DIR) + "/kitti/2011_09_26/2011_09_26_drive_0013_sync";
  Drive drive;
  DriveMotion motion;
  if (!std::filesystem::is_directory(dir) || !OpenDrive(dir, "", &drive).ok() ||
      !DriveMotion::Create(drive, &motion).ok()) {
    state.SkipWithError("shared KITTI data not found");
    return;
  }
  LidarFeatureOptions options;
  options.remove_dynamic = false;
  SweepCache cache(drive, motion, options);
  const LidarFrameFeatures* sweep;
  if (!cache.Base(8, &sweep).ok()) return state.SkipWithError("cannot read sweep");
  const double t_image = motion.Seconds(drive.camera_stamps_ns[9]);
  const double capture = sweep->stamp_s;  // δ = 0 for KITTI; the delay is in the stamps only
  std::vector<Eigen::Vector3d> out(sweep->deskewed.size());
  for (auto _ : state) {
    // Tv from the oxts trajectory (integrated over the gap), applied to every point.
    const Rigid3d Tv = RelativeLidarPose(motion.PoseFunction(), t_image, capture);
    for (size_t i = 0; i < out.size(); ++i) out[i] = Tv * sweep->deskewed[i];
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * out.size());
}
BENCHMARK(BM_InferCloud)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace stcalib
