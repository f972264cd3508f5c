// One online update (issue 5): search + refine over the window, on KITTI frames, in steady state
// (the calibrator already tracking), and the whole per-frame path including the features.
// Goal (issue 53): ≤ 50 ms per frame in calibrate, ≤ 20 ms per tracking frame, on one core.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>

#include "core/online/frame_prefetcher.h"
#include "core/online/frame_source.h"
#include "core/online/online_calibrator.h"
#include "core/search/adaptive_grid_search.h"
#include "core/search/hypothesis_lattice.h"
#include "core/types/calibration.h"

namespace stcalib {
namespace {

// The frame source as `stcalib calibrate` sets it up with the defaults.
FrameSourceOptions CalibrateSourceOptions() { return FrameSourceOptions(); }

// A new frame source (its sweep cache empty) that has loaded frames [0, n), each handed to
// `use` (may be empty): the untimed start of a benchmark cycle over later frames.
Status StartCycle(size_t n, const std::function<void(std::shared_ptr<CalibrationFrame>)>& use,
                  std::unique_ptr<DriveFrameSource>* source);

struct Fixture {
  Drive drive;
  std::unique_ptr<DriveFrameSource> source;
  std::vector<std::shared_ptr<const CalibrationFrame>> frames;
  bool ok = false;
  Fixture() {
    cv::setNumThreads(1);
    const std::string dir =
        std::string(STCALIB_SHARED_DATA_DIR) + "/kitti/2011_09_26/2011_09_26_drive_0013_sync";
    if (!std::filesystem::is_directory(dir) || !OpenDrive(dir, "", &drive).ok()) return;
    if (!DriveFrameSource::Create(&drive, CalibrateSourceOptions(), &source).ok()) return;
    for (size_t i = 0; i < 12; ++i) {
      auto f = std::make_shared<CalibrationFrame>();
      if (!source->Load(i, f.get()).ok()) return;
      frames.push_back(f);
    }
    ok = true;
  }
};

Fixture& Kitti() {
  static Fixture* fixture = new Fixture();
  return *fixture;
}

// KITTI's own calibration, δ = 0.
CalibrationState KittiCalibration() {
  CalibrationState calibration;
  calibration.T_camera_lidar = Kitti().drive.T_camera_lidar;
  return calibration;
}

// The first n loaded frames.
std::vector<const CalibrationFrame*> FirstFrames(int64_t n) {
  std::vector<const CalibrationFrame*> frames;
  for (int64_t i = 0; i < n; ++i) frames.push_back(Kitti().frames[i].get());
  return frames;
}

void BM_OnlineUpdate(benchmark::State& state) {
  if (!Kitti().ok) return state.SkipWithError("shared KITTI data not found");
  const CalibrationState initial = KittiCalibration();
  OnlineCalibratorOptions options;
  options.refine_frames = static_cast<int>(state.range(0));
  options.tracking_update_every = 1;  // one update per iteration
  OnlineCalibrator calibrator(options, initial);
  // Warm up on every loaded frame: the acquisition (rotation grid on each frame) ends once the
  // grid agrees with the estimate on a full refinement window; from then on it tracks.
  for (const auto& frame : Kitti().frames) calibrator.AddFrame(frame);
  size_t next = 8;
  double camera_time_s = Kitti().frames.back()->camera_time_s;
  int coarse = 0;
  for (auto _ : state) {
    // The frames cycle; each gets a later stamp, or the calibrator would refuse it as out of
    // order (the copy shares the images and maps).
    state.PauseTiming();
    auto frame = std::make_shared<CalibrationFrame>(*Kitti().frames[next]);
    camera_time_s += 0.1;
    frame->camera_time_s = camera_time_s;
    state.ResumeTiming();
    const FrameReport report = calibrator.AddFrame(frame);
    if (report.skipped) return state.SkipWithError(report.reason.c_str());
    coarse += report.from_hypotheses;
    next = next + 1 < Kitti().frames.size() ? next + 1 : 8;
  }
  state.SetLabel("refine over " + std::to_string(state.range(0)) + " frames, search over 3" +
                 (coarse > 0 ? ", " + std::to_string(coarse) + " coarse (acquiring or lost)" : ""));
}
BENCHMARK(BM_OnlineUpdate)->Arg(3)->Arg(10)->Unit(benchmark::kMillisecond);

// The start `stcalib calibrate --perturb_rot_deg=2 --seed=1` gives on KITTI: 2° on each axis.
CalibrationState KittiStartTwoDegreesOff() {
  CalibrationState start = KittiCalibration();
  start.T_camera_lidar =
      PerturbTcameraLidar(start.T_camera_lidar, Eigen::Vector3d(2, -2, 2), Eigen::Vector3d::Zero());
  return start;
}

// One acquiring frame: the calibrator, started 2° off, has taken frames [0, N); the timed
// AddFrame of frame N scores the frame once over the lattice, refines and judges the best
// hypotheses, then searches and refines the estimate. Counters: the frame's search (hypotheses
// included) and refinement [ms].
void BM_AcquiringFrame(benchmark::State& state) {
  if (!Kitti().ok) return state.SkipWithError("shared KITTI data not found");
  const size_t n = static_cast<size_t>(state.range(0));
  OnlineCalibrator warm(OnlineCalibratorOptions(), KittiStartTwoDegreesOff());
  for (size_t i = 0; i < n; ++i) warm.AddFrame(Kitti().frames[i]);
  double search_ms = 0, refine_ms = 0;
  bool acquiring = true;
  for (auto _ : state) {
    state.PauseTiming();
    OnlineCalibrator calibrator = warm;
    state.ResumeTiming();
    const FrameReport report = calibrator.AddFrame(Kitti().frames[n], /*update_now=*/true);
    search_ms += report.search_ms;
    refine_ms += report.refine_ms;
    acquiring = acquiring && report.acquiring;
  }
  state.counters["search_ms"] = search_ms / state.iterations();
  state.counters["refine_ms"] = refine_ms / state.iterations();
  state.SetLabel(std::string(acquiring ? "acquiring" : "NOT acquiring") + ", frame " +
                 std::to_string(n) + " after " + std::to_string(n) + " frames");
}
BENCHMARK(BM_AcquiringFrame)->Arg(5)->Arg(11)->Unit(benchmark::kMillisecond);

// Tracking frames as `calibrate` runs them (an update every tracking_update_every frames, the
// health score on the others), after the acquisition on the loaded frames; the frames cycle with
// later stamps. The mean over the cycle; the counter `updates` is the share that updated;
// median_ms and max_ms per frame, and where the slowest frame's time went (max_search_ms,
// max_refine_ms, max_was_lost: it searched coarse to fine from a lost estimate).
void BM_TrackingFrame(benchmark::State& state) {
  if (!Kitti().ok) return state.SkipWithError("shared KITTI data not found");
  OnlineCalibrator calibrator(OnlineCalibratorOptions(), KittiCalibration());
  size_t next = 0;
  double camera_time_s = Kitti().frames.front()->camera_time_s - 0.1;
  // The loaded frames in a cycle, each with a later stamp (the copy shares the images and maps):
  // the calibrator would refuse a frame out of order.
  auto next_frame = [&]() {
    auto frame = std::make_shared<CalibrationFrame>(*Kitti().frames[next]);
    camera_time_s += 0.1;
    frame->camera_time_s = camera_time_s;
    next = next + 1 < Kitti().frames.size() ? next + 1 : 0;
    return frame;
  };
  // Until the acquisition ends (a full refinement window on which the grid agrees).
  for (int k = 0; k < 60 && (k < 3 || calibrator.acquiring()); ++k)
    calibrator.AddFrame(next_frame());
  if (calibrator.acquiring()) return state.SkipWithError("still acquiring after 60 frames");
  int updates = 0, acquiring = 0;
  std::vector<double> frame_ms;  // each frame's AddFrame [ms]
  FrameReport worst;             // the slowest frame's report: where its time went
  double worst_ms = -1;
  for (auto _ : state) {
    state.PauseTiming();
    auto frame = next_frame();
    state.ResumeTiming();
    const auto start = std::chrono::steady_clock::now();
    const FrameReport report = calibrator.AddFrame(frame);
    frame_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    if (report.skipped) return state.SkipWithError(report.reason.c_str());
    if (frame_ms.back() > worst_ms) {
      worst_ms = frame_ms.back();
      worst = report;
    }
    updates += report.ran_update();
    acquiring += report.acquiring;
  }
  std::sort(frame_ms.begin(), frame_ms.end());
  state.counters["updates"] = static_cast<double>(updates) / state.iterations();
  state.counters["median_ms"] = frame_ms[frame_ms.size() / 2];
  state.counters["max_ms"] = frame_ms.back();
  state.counters["max_search_ms"] = worst.search_ms;
  state.counters["max_refine_ms"] = worst.refine_ms;
  state.counters["max_was_lost"] = worst.from_hypotheses ? 1 : 0;
  state.SetLabel(acquiring > 0 ? std::to_string(acquiring) + " frames acquiring" : "tracking");
}
BENCHMARK(BM_TrackingFrame)->Unit(benchmark::kMillisecond);

// The whole `calibrate` loop on the shared drive (its 30 frames, from 2° off): frames loaded one
// ahead on a second thread (FramePrefetcher), each added to the calibrator. Reported per frame;
// counters: the mean search and refinement per frame [ms] and the frames that updated.
void BM_CalibrateLoopPerFrame(benchmark::State& state) {
  if (!Kitti().ok) return state.SkipWithError("shared KITTI data not found");
  const int frames = static_cast<int>(Kitti().drive.NumFrames());
  double search_ms = 0, refine_ms = 0;
  int updates = 0;
  for (auto _ : state) {
    std::unique_ptr<DriveFrameSource> source;
    if (!DriveFrameSource::Create(&Kitti().drive, CalibrateSourceOptions(), &source).ok()) {
      return state.SkipWithError("frame source");
    }
    OnlineCalibrator calibrator(OnlineCalibratorOptions(), KittiStartTwoDegreesOff());
    FramePrefetcher prefetcher(source.get(), 0, frames - 1);
    FramePrefetcher::Loaded loaded;
    while (prefetcher.Next(&loaded)) {
      if (!loaded.cameras[0].status.ok())
        return state.SkipWithError(loaded.cameras[0].status.message().c_str());
      const FrameReport report =
          calibrator.AddFrame(std::move(loaded.cameras[0].frame), loaded.index == frames - 1);
      search_ms += report.search_ms;
      refine_ms += report.refine_ms;
      updates += report.ran_update();
    }
  }
  const double per_frame = 1.0 / (static_cast<double>(state.iterations()) * frames);
  state.counters["frames"] = frames;
  state.counters["search_ms"] = search_ms * per_frame;
  state.counters["refine_ms"] = refine_ms * per_frame;
  state.counters["updates"] = updates * per_frame;
  state.counters["per_frame"] = benchmark::Counter(
      static_cast<double>(frames),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CalibrateLoopPerFrame)->Unit(benchmark::kMillisecond)->Iterations(2);

// One frame scored once over the acquisition's lattice: what every acquiring frame adds. Arg 0:
// the default start uncertainty (±3°, ±5 cm, ±30 ms); 1: ±5°, ±20 cm, ±100 ms. Counters: points
// read and hypotheses scored; the inner loop is vectorised (ScoreFrameOnLattice's clones), so
// `ns_per_sample` (ns per point and hypothesis) shows whether a wide vector unit ran it.
void BM_LatticeFrame(benchmark::State& state) {
  if (!Kitti().ok) return state.SkipWithError("shared KITTI data not found");
  HypothesisLattice lattice;
  const StartUncertainty span =
      state.range(0) == 0 ? StartUncertainty() : StartUncertainty{5.0, 0.2, 0.1};
  if (!HypothesisLattice::Create(KittiStartTwoDegreesOff(), span, LatticeSteps(), &lattice).ok()) {
    return state.SkipWithError("lattice");
  }
  const auto frame = PruneToImage(*Kitti().frames[5], KittiStartTwoDegreesOff(),
                                  OnlineCalibratorOptions().point_margin);
  const int points = std::min<int>(frame->size(), Acquisition::kLatticePoints);
  std::vector<float> scores;
  for (auto _ : state) {
    ScoreFrameOnLattice(*frame, lattice, 0.2, Acquisition::kLatticePoints, &scores);
    benchmark::DoNotOptimize(scores.data());
  }
  state.counters["points"] = points;
  state.counters["hypotheses"] = static_cast<double>(lattice.size());
  state.counters["ns_per_sample"] = benchmark::Counter(
      static_cast<double>(points) * lattice.size() * 1e-9,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LatticeFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The health score (docs/method.md §7): 728 neighbours of the estimate scored over N frames; an
// online update measures it before and after, and every 6-DoF search step scores as many.
// The frames are pruned to the image as the calibrator's window is: every point then projects
// and is sampled (over the whole sweep most points fall behind the camera and cost nothing, which
// made this benchmark read 3.3 ms where the calibrator spent 10 ms).
void BM_HealthScore(benchmark::State& state) {
  if (!Kitti().ok) return state.SkipWithError("shared KITTI data not found");
  const CalibrationState initial = KittiCalibration();
  std::vector<std::shared_ptr<const CalibrationFrame>> pruned;
  std::vector<const CalibrationFrame*> frames;
  for (const CalibrationFrame* frame : FirstFrames(state.range(0))) {
    pruned.push_back(PruneToImage(*frame, initial, OnlineCalibratorOptions().point_margin));
    frames.push_back(pruned.back().get());
  }
  WindowScorer scorer(frames, ScoreOptions());
  for (auto _ : state) benchmark::DoNotOptimize(HealthScore(&scorer, initial));
  state.SetLabel("728 neighbours over " + std::to_string(state.range(0)) +
                 " frames pruned to the image");
}
BENCHMARK(BM_HealthScore)->Arg(3)->Unit(benchmark::kMillisecond);

// The joint refinement (Ceres, rotation + translation + δ, with the covariance) over N frames
// from the estimate, as while tracking.
void BM_Refine(benchmark::State& state) {
  if (!Kitti().ok) return state.SkipWithError("shared KITTI data not found");
  const CalibrationState initial = KittiCalibration();
  const std::vector<const CalibrationFrame*> frames = FirstFrames(state.range(0));
  const RefineOptions options = WithSharedSettings(OnlineCalibratorOptions()).refine;
  int iterations = 0;
  for (auto _ : state) {
    const RefineResult r = Refine(frames, initial, initial, initial, options);
    iterations = r.iterations;
  }
  state.SetLabel(std::to_string(state.range(0)) + " frames, " + std::to_string(iterations) +
                 " iterations");
}
BENCHMARK(BM_Refine)->Arg(3)->Arg(12)->Unit(benchmark::kMillisecond);

// The whole per-frame path with the defaults (20-frame refinement): image and LiDAR features
// with the local map, then the online calibrator (an update on every n-th frame while tracking,
// n the benchmark's argument), for each new frame of the drive.
// Each cycle starts a new frame source and calibrator and runs them, untimed, through frames
// 0-21 (the acquisition ends within them); frames 22-29 are then timed as a drive's new frames:
// each computes its own sweep's features (the earlier sweeps cached, as in a run) and updates
// the tracking calibrator. (Frames cycled through one source read their sweeps from its cache
// from the second cycle on: the sweep cache keeps every sweep that is not older than its
// newest, so the earlier version of this benchmark measured cached sweeps after its first
// cycle, about 25 ms less per frame.)
void BM_WholeFrame(benchmark::State& state) {
  if (!Kitti().ok) return state.SkipWithError("shared KITTI data not found");
  constexpr size_t kFirstTimed = 22;
  if (Kitti().drive.NumFrames() <= kFirstTimed) return state.SkipWithError("too few frames");
  OnlineCalibratorOptions options;
  options.tracking_update_every = static_cast<int>(state.range(0));
  std::unique_ptr<DriveFrameSource> source;
  std::unique_ptr<OnlineCalibrator> calibrator;
  size_t next = Kitti().drive.NumFrames();
  int coarse = 0;
  for (auto _ : state) {
    if (next == Kitti().drive.NumFrames()) {
      state.PauseTiming();
      calibrator = std::make_unique<OnlineCalibrator>(options, KittiCalibration());
      const Status started = StartCycle(
          kFirstTimed, [&](std::shared_ptr<CalibrationFrame> f) { calibrator->AddFrame(f); },
          &source);
      if (!started.ok()) return state.SkipWithError(started.message().c_str());
      next = kFirstTimed;
      state.ResumeTiming();
    }
    auto frame = std::make_shared<CalibrationFrame>();
    if (!source->Load(next++, frame.get()).ok()) return state.SkipWithError("load");
    const FrameReport report = calibrator->AddFrame(frame);
    if (report.skipped) return state.SkipWithError(report.reason.c_str());
    coarse += report.from_hypotheses;
  }
  state.SetLabel(
      "features + update every " + std::to_string(options.tracking_update_every) +
      " frame(s) while tracking, refine over 20 frames" +
      (coarse > 0 ? ", " + std::to_string(coarse) + " coarse (acquiring or lost)" : std::string()));
}
// Arg: tracking_update_every (3, the default; 1, an update on every frame).
BENCHMARK(BM_WholeFrame)->Arg(3)->Arg(1)->Unit(benchmark::kMillisecond);

Status StartCycle(size_t n, const std::function<void(std::shared_ptr<CalibrationFrame>)>& use,
                  std::unique_ptr<DriveFrameSource>* source) {
  STCALIB_RETURN_IF_ERROR(
      DriveFrameSource::Create(&Kitti().drive, CalibrateSourceOptions(), source));
  for (size_t i = 0; i < n; ++i) {
    auto frame = std::make_shared<CalibrationFrame>();
    STCALIB_RETURN_IF_ERROR((*source)->Load(i, frame.get()));
    if (use) use(frame);
  }
  return Status::Ok();
}

// Image features, LiDAR features and local map for each new frame of frames 12-29, the sweeps
// before it cached as in a run: each cycle starts a new frame source and loads frames 0-11
// untimed (see BM_WholeFrame on why one source cannot cycle).
void BM_FrameFeatures(benchmark::State& state) {
  if (!Kitti().ok) return state.SkipWithError("shared KITTI data not found");
  constexpr size_t kFirstTimed = 12;
  std::unique_ptr<DriveFrameSource> source;
  size_t frame = Kitti().drive.NumFrames();
  for (auto _ : state) {
    if (frame == Kitti().drive.NumFrames()) {
      state.PauseTiming();
      const Status started = StartCycle(kFirstTimed, {}, &source);
      if (!started.ok()) return state.SkipWithError(started.message().c_str());
      frame = kFirstTimed;
      state.ResumeTiming();
    }
    CalibrationFrame f;
    benchmark::DoNotOptimize(source->Load(frame++, &f).ok());
  }
  state.SetLabel("includes PNG decoding (~9 ms, see io_benchmark)");
}
BENCHMARK(BM_FrameFeatures)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace stcalib
