// Per-stage cost of the line features on a KITTI frame (issue 4), one core (cv::setNumThreads(1)).
// The online per-frame path: image features + LiDAR base (rings, timing, de-skew, ground) +
// dynamic filter against cached earlier sweeps + edges. Decoding is reported on its own
// (io_benchmark): a live camera hands over decoded images.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <opencv2/core.hpp>

#include "core/features/image_features.h"
#include "core/features/lidar_frame.h"
#include "core/io/drive.h"
#include "core/motion/drive_motion.h"
#include "core/online/frame_source.h"
#include "core/pcl/registration.h"

namespace stcalib {
namespace {

struct KittiFixture {
  Drive drive;
  DriveMotion motion;
  cv::Mat image;
  std::vector<LidarScan> scans;  // frames 7..10
  bool ok = false;

  KittiFixture() {
    cv::setNumThreads(1);
    const std::string dir =
        std::string(STCALIB_SHARED_DATA_DIR) + "/kitti/2011_09_26/2011_09_26_drive_0013_sync";
    if (!std::filesystem::is_directory(dir)) return;
    if (!OpenDrive(dir, "", &drive).ok() || !DriveMotion::Create(drive, &motion).ok()) return;
    if (!drive.LoadImage(10, &image).ok()) return;
    for (size_t f = 7; f <= 10; ++f) {
      scans.emplace_back();
      if (!drive.LoadScan(f, &scans.back()).ok()) return;
    }
    ok = true;
  }
  double Stamp(size_t frame) const { return motion.Seconds(drive.lidar_stamps_ns[frame]); }
  LidarFrameFeatures Base(size_t frame) const {
    return ComputeLidarSweepBase(scans[frame - 7], Stamp(frame), SweepDurationSeconds(drive),
                                 motion.PoseFunction(), LidarFeatureOptions());
  }
};

const KittiFixture& Kitti() {
  static const KittiFixture* fixture = new KittiFixture();
  return *fixture;
}

#define REQUIRE_KITTI(state)                                                             \
  if (!Kitti().ok) {                                                                     \
    state.SkipWithError("shared KITTI data not found (../shared/data beside the repo)"); \
    return;                                                                              \
  }

void BM_ImageFeatures(benchmark::State& state) {
  REQUIRE_KITTI(state);
  ImageFeatureOptions options;
  options.detector = static_cast<ImageFeatureOptions::Detector>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(ExtractImageFeatures(Kitti().image, options));
  state.SetLabel(state.range(0) == 0   ? "canny"
                 : state.range(0) == 1 ? "lsd (half size)"
                                       : "fld (half size)");
}
BENCHMARK(BM_ImageFeatures)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

// As the online frame source asks for them (FrameSourceOptions::ImageOptions: the oriented maps
// only), as `stcalib calibrate` runs with the defaults.
void BM_ImageFeaturesAsOnline(benchmark::State& state) {
  REQUIRE_KITTI(state);
  const ImageFeatureOptions options = FrameSourceOptions().ImageOptions();
  for (auto _ : state) benchmark::DoNotOptimize(ExtractImageFeatures(Kitti().image, options));
}
BENCHMARK(BM_ImageFeaturesAsOnline)->Unit(benchmark::kMillisecond);

// The rows LiDAR points can reach (below the top beam at +2°, with margin), as the online path
// uses them: rows 110..374 of the 375.
void BM_ImageFeaturesLidarRows(benchmark::State& state) {
  REQUIRE_KITTI(state);
  ImageFeatureOptions options;
  options.region_of_interest = cv::Rect(0, 110, Kitti().image.cols, Kitti().image.rows - 110);
  for (auto _ : state) benchmark::DoNotOptimize(ExtractImageFeatures(Kitti().image, options));
}
BENCHMARK(BM_ImageFeaturesLidarRows)->Unit(benchmark::kMillisecond);

void BM_RingsAndTimes(benchmark::State& state) {
  REQUIRE_KITTI(state);
  for (auto _ : state) {
    const ScanRings rings = SplitIntoRings(Kitti().scans[3].points_lidar);
    benchmark::DoNotOptimize(PointTimesFromAzimuth(rings, 0.1036));
  }
}
BENCHMARK(BM_RingsAndTimes)->Unit(benchmark::kMillisecond);

void BM_Deskew(benchmark::State& state) {
  REQUIRE_KITTI(state);
  const ScanRings rings = SplitIntoRings(Kitti().scans[3].points_lidar);
  const std::vector<double> times = PointTimesFromAzimuth(rings, 0.1036);
  for (auto _ : state) {
    benchmark::DoNotOptimize(DeskewToStamp(Kitti().scans[3].points_lidar, times, Kitti().Stamp(10),
                                           Kitti().motion.PoseFunction()));
  }
}
BENCHMARK(BM_Deskew)->Unit(benchmark::kMillisecond);

void BM_Ground(benchmark::State& state) {
  REQUIRE_KITTI(state);
  const GroundOptions options;
  for (auto _ : state) {
    const GroundPlane plane = FitGroundPlane(Kitti().scans[3].points_lidar, options);
    benchmark::DoNotOptimize(GroundMask(Kitti().scans[3].points_lidar, plane, options.band_m));
  }
}
BENCHMARK(BM_Ground)->Unit(benchmark::kMillisecond);

void BM_LidarEdges(benchmark::State& state) {
  REQUIRE_KITTI(state);
  const LidarFrameFeatures base = Kitti().Base(10);
  std::vector<PointUse> use(base.scan.size(), PointUse::kUse);
  for (size_t i = 0; i < use.size(); ++i) {
    if (base.ground[i]) use[i] = PointUse::kGround;
  }
  const LidarEdgeOptions options;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        ExtractLidarEdges(base.scan, base.rings, base.point_time_s, &use, options));
  }
}
BENCHMARK(BM_LidarEdges)->Unit(benchmark::kMillisecond);

// Arg: ROI half angle in degrees (0 = all 360°).
void BM_DynamicFilter(benchmark::State& state) {
  REQUIRE_KITTI(state);
  const LidarFrameFeatures current = Kitti().Base(10), previous = Kitti().Base(9),
                           older = Kitti().Base(7);
  DynamicFilterOptions options;
  options.roi_half_angle_deg = static_cast<double>(state.range(0));
  const auto pose = Kitti().motion.PoseFunction();
  std::vector<ReferenceSweep> references(2);
  references[0].points = &previous.deskewed;
  references[0].ground = &previous.ground;
  references[0].T_current_reference = RelativeLidarPose(pose, current.stamp_s, previous.stamp_s);
  references[1].points = &older.deskewed;
  references[1].ground = &older.ground;
  references[1].T_current_reference = RelativeLidarPose(pose, current.stamp_s, older.stamp_s);
  references[1].check_visibility = true;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        DetectDynamicPoints(current.deskewed, current.ground, references, options));
  }
}
BENCHMARK(BM_DynamicFilter)->Arg(0)->Arg(50)->Unit(benchmark::kMillisecond);

void BM_LocalMapMergeOxts(benchmark::State& state) {
  REQUIRE_KITTI(state);
  LidarFrameFeatures f8 = Kitti().Base(8), f9 = Kitti().Base(9), f10 = Kitti().Base(10);
  for (LidarFrameFeatures* f : {&f8, &f9, &f10})
    FinishLidarFrameFeatures({}, LidarFeatureOptions(), f);
  const auto pose = Kitti().motion.PoseFunction();
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        MergeEdges(f10.edges, {{&f8.edges, RelativeLidarPose(pose, f10.stamp_s, f8.stamp_s),
                                RelativeLidarPoseRate(pose, f10.stamp_s, f8.stamp_s)},
                               {&f9.edges, RelativeLidarPose(pose, f10.stamp_s, f9.stamp_s),
                                RelativeLidarPoseRate(pose, f10.stamp_s, f9.stamp_s)}}));
  }
}
BENCHMARK(BM_LocalMapMergeOxts)->Unit(benchmark::kMillisecond);

void BM_LocalMapNdtOneSweep(benchmark::State& state) {
  REQUIRE_KITTI(state);
  const LidarFrameFeatures f9 = Kitti().Base(9), f10 = Kitti().Base(10);
  std::vector<Eigen::Vector3d> source, target;
  for (size_t i = 0; i < f9.deskewed.size(); ++i) {
    if (!f9.ground[i]) source.push_back(f9.deskewed[i]);
  }
  for (size_t i = 0; i < f10.deskewed.size(); ++i) {
    if (!f10.ground[i]) target.push_back(f10.deskewed[i]);
  }
  const Rigid3d initial = RelativeLidarPose(Kitti().motion.PoseFunction(), f10.stamp_s, f9.stamp_s);
  for (auto _ : state) {
    RegistrationResult result;
    benchmark::DoNotOptimize(RegisterNdt(source, target, initial, NdtOptions(), &result).ok());
  }
}
BENCHMARK(BM_LocalMapNdtOneSweep)->Unit(benchmark::kMillisecond);

// The whole per-frame online path with earlier sweeps' bases cached (as the online calibrator
// keeps them): image features, the new sweep's base, the dynamic filter in the camera's view and
// the edges.
void BM_OnlinePerFramePath(benchmark::State& state) {
  REQUIRE_KITTI(state);
  const LidarFrameFeatures previous = Kitti().Base(9), older = Kitti().Base(7);
  LidarFeatureOptions options;
  options.dynamic.roi_half_angle_deg = 50;
  const ImageFeatureOptions image_options;
  const auto pose = Kitti().motion.PoseFunction();
  const double stamp = Kitti().Stamp(10);
  for (auto _ : state) {
    benchmark::DoNotOptimize(ExtractImageFeatures(Kitti().image, image_options));
    LidarFrameFeatures f = ComputeLidarSweepBase(
        Kitti().scans[3], stamp, SweepDurationSeconds(Kitti().drive), pose, options);
    FinishLidarFrameFeatures({{&previous, RelativeLidarPose(pose, stamp, previous.stamp_s), false},
                              {&older, RelativeLidarPose(pose, stamp, older.stamp_s), true}},
                             options, &f);
    benchmark::DoNotOptimize(f.edges.size());
  }
}
BENCHMARK(BM_OnlinePerFramePath)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace stcalib
