// Calibration on a simulated drive with exact truth: search, refinement, health, time-offset
// profile and the online calibrator (issue 5). One drive is simulated once and every stage is
// checked on it, so this stays a few seconds long.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <tuple>

#include "core/online/frame_prefetcher.h"
#include "core/online/frame_source.h"
#include "core/online/online_calibrator.h"
#include "core/refine/refine.h"
#include "core/search/adaptive_grid_search.h"
#include "core/search/hypothesis_lattice.h"
#include "core/sim/simulator.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

// A frame with image edges and maps but (here) no LiDAR points, stamped at `time_s`.
std::shared_ptr<CalibrationFrame> BareFrame(int index, double time_s) {
  auto frame = std::make_shared<CalibrationFrame>();
  frame->index = index;
  frame->camera_time_s = time_s;
  frame->camera.width = 64;
  frame->camera.height = 32;
  frame->image.edge_pixels = 100;
  for (int kind = 0; kind < 2; ++kind) {
    frame->distance_px[kind] = cv::Mat::zeros(32, 64, CV_32F);
    frame->gray_map[kind] = cv::Mat::zeros(32, 64, CV_32F);
    frame->score_maps[kind].push_back(frame->gray_map[kind]);
  }
  return frame;
}

// The dynamic filter's window holds the camera's horizontal field of view: KITTI's camera looks
// along the LiDAR's x axis, and its half field of view is atan(max(cx, W − cx)/fx) = 41.2°. The
// same camera turned to look along the LiDAR's y axis moves the window by 90°.
TEST(FrameSource, CameraAzimuthWindowHoldsTheFieldOfView) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  const CameraCalibration& camera = drive.camera;
  const double fx = camera.P_rect(0, 0), cx = camera.P_rect(0, 2);
  const double half_fov_deg = std::atan(std::max(cx, camera.image_width - cx) / fx) * 180.0 / M_PI;
  EXPECT_NEAR(half_fov_deg, 41.2, 0.1);
  const Eigen::Vector2d ahead = CameraAzimuthWindowDeg(
      camera, camera.image_width, camera.image_height, drive.T_camera_lidar, 20);
  EXPECT_NEAR(ahead.x(), 0.0, 1.0);
  EXPECT_NEAR(ahead.y(), half_fov_deg + 20, 1.0);
  const Rigid3d sideways =
      drive.T_camera_lidar *
      MakeRigid(ExpSO3(Eigen::Vector3d(0, 0, -M_PI / 2)), Eigen::Vector3d::Zero());
  const Eigen::Vector2d side =
      CameraAzimuthWindowDeg(camera, camera.image_width, camera.image_height, sideways, 20);
  EXPECT_NEAR(side.x(), 90.0, 1.0);
  EXPECT_NEAR(side.y(), ahead.y(), 1e-6);
  // Looking straight up: no azimuth window holds the view, so the whole sweep is judged.
  const Rigid3d up = drive.T_camera_lidar *
                     MakeRigid(ExpSO3(Eigen::Vector3d(0, M_PI / 2, 0)), Eigen::Vector3d::Zero());
  EXPECT_EQ(CameraAzimuthWindowDeg(camera, camera.image_width, camera.image_height, up, 20).y(),
            0.0);
  // The frame source applies it; a negative margin judges the whole sweep.
  std::unique_ptr<DriveFrameSource> source;
  ASSERT_TRUE(DriveFrameSource::Create(&drive, FrameSourceOptions(), &source).ok());
  EXPECT_NEAR(source->dynamic_options().roi_half_angle_deg, ahead.y(), 1e-9);
  FrameSourceOptions whole;
  whole.view_margin_deg = -1;
  ASSERT_TRUE(DriveFrameSource::Create(&drive, whole, &source).ok());
  EXPECT_EQ(source->dynamic_options().roi_half_angle_deg, 0.0);
}

// A loaded frame scores on the band-pass IDTs and keeps neither the texture-suppressed nor the
// plain IDTs: TextureSuppressedMap and PlainIdt give them back, bit for bit the image features'.
TEST(FrameSource, SuppressedAndPlainIdtsComeBackBitForBit) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  const FrameSourceOptions options;
  const std::vector<std::shared_ptr<const CalibrationFrame>> frames =
      testing::LoadCalibrationFrames(drive, options, {3});
  ASSERT_EQ(frames.size(), 1u);
  const CalibrationFrame& frame = *frames[0];
  ASSERT_TRUE(frame.score_maps_bandpass);
  cv::Mat image;
  ASSERT_TRUE(drive.LoadImage(3, &image).ok());
  const ImageFeatures features = ExtractImageFeatures(image, options.ImageOptions());
  for (int kind = 0; kind < 2; ++kind) {
    EXPECT_TRUE(frame.image.oriented[kind].idt_suppressed.empty()) << "released, kind " << kind;
    const cv::Mat derived = TextureSuppressedMap(frame, kind);
    const cv::Mat& expected = features.oriented[kind].idt_suppressed;
    ASSERT_FALSE(expected.empty());
    ASSERT_EQ(derived.size(), expected.size());
    EXPECT_EQ(cv::norm(derived, expected, cv::NORM_INF), 0.0) << "kind " << kind;
    EXPECT_GT(cv::norm(derived, cv::NORM_INF), 0.0);
    // The plain IDT (the gray rate's map) likewise, from the distance map.
    EXPECT_TRUE(frame.gray_map[kind].empty()) << "released, kind " << kind;
    const cv::Mat plain = PlainIdt(frame, kind);
    const cv::Mat& expected_plain = features.oriented[kind].idt;
    ASSERT_EQ(plain.size(), expected_plain.size());
    EXPECT_EQ(cv::norm(plain, expected_plain, cv::NORM_INF), 0.0) << "kind " << kind;
    EXPECT_GT(cv::norm(plain, cv::NORM_INF), 0.0);
  }
}

// The prefetcher (calibrate's loader thread) returns the frames in order, each the same as a
// direct load on the caller's thread.
TEST(FramePrefetcher, ReturnsTheFramesInOrderAsADirectLoadDoes) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  const std::vector<std::shared_ptr<const CalibrationFrame>> direct =
      testing::LoadCalibrationFrames(drive, FrameSourceOptions(), {3, 4, 5});
  ASSERT_EQ(direct.size(), 3u);
  std::unique_ptr<DriveFrameSource> source;
  ASSERT_TRUE(DriveFrameSource::Create(&drive, FrameSourceOptions(), &source).ok());
  FramePrefetcher prefetcher(source.get(), 3, 5);
  FramePrefetcher::Loaded loaded;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(prefetcher.Next(&loaded));
    EXPECT_EQ(loaded.index, 3 + k);
    ASSERT_TRUE(loaded.cameras[0].status.ok()) << loaded.cameras[0].status.message();
    EXPECT_EQ(loaded.cameras[0].frame->camera_time_s, direct[k]->camera_time_s);
    EXPECT_EQ(loaded.cameras[0].frame->e0_s, direct[k]->e0_s);
    ASSERT_EQ(loaded.cameras[0].frame->size(), direct[k]->size());
    EXPECT_EQ(loaded.cameras[0].frame->points_lidar, direct[k]->points_lidar);
    for (int kind = 0; kind < 2; ++kind) {
      EXPECT_EQ(cv::norm(loaded.cameras[0].frame->score_maps[kind].back(),
                         direct[k]->score_maps[kind].back(), cv::NORM_INF),
                0.0);
    }
  }
  EXPECT_FALSE(prefetcher.Next(&loaded));
}

// A frame that fails to load comes back in its place with the error naming its file; the frames
// around it load.
TEST(FramePrefetcher, ReturnsAFrameThatFailsWithItsError) {
  testing::ScopedTempDir tmp;
  const std::string drive_dir = testing::MakeTinyDrive(tmp.path(), 3);
  const std::string bin = drive_dir + "/velodyne_points/data/0000000001.bin";
  std::filesystem::resize_file(bin, 10);
  Drive drive;
  const Status opened = OpenDrive(drive_dir, "", &drive);
  ASSERT_TRUE(opened.ok()) << opened.message();
  FrameSourceOptions options;
  options.local_map.sweeps = 1;
  std::unique_ptr<DriveFrameSource> source;
  const Status created = DriveFrameSource::Create(&drive, options, &source);
  ASSERT_TRUE(created.ok()) << created.message();
  FramePrefetcher prefetcher(source.get(), 0, 2);
  std::vector<FramePrefetcher::Loaded> all(3);
  for (FramePrefetcher::Loaded& loaded : all) ASSERT_TRUE(prefetcher.Next(&loaded));
  EXPECT_TRUE(all[0].cameras[0].status.ok()) << all[0].cameras[0].status.message();
  EXPECT_FALSE(all[1].cameras[0].status.ok());
  EXPECT_THAT(all[1].cameras[0].status.message(), ::testing::HasSubstr(bin));
  EXPECT_EQ(all[1].index, 1);
  EXPECT_TRUE(all[2].cameras[0].status.ok()) << all[2].cameras[0].status.message();
}

// Fault injection at the calibrator itself: frames that go back in time, repeat a stamp, carry
// NaN motion or have no image edges are refused with the reason, and the estimate stays.
TEST(OnlineCalibrator, RefusesBadFramesAndKeepsTheEstimate) {
  CalibrationState start;
  start.T_camera_lidar =
      MakeRigid(ExpSO3(Eigen::Vector3d(0.1, -0.2, 0.3)), Eigen::Vector3d(0.1, 0.2, -0.3));
  start.time_offset_s = 0.01;
  OnlineCalibrator calibrator(OnlineCalibratorOptions(), start);
  FrameReport r = calibrator.AddFrame(BareFrame(0, 1.0));
  EXPECT_FALSE(r.skipped);
  EXPECT_NE(r.reason.find("too few LiDAR edge points"), std::string::npos) << r.reason;
  r = calibrator.AddFrame(BareFrame(1, 1.0));  // duplicated stamp
  EXPECT_TRUE(r.skipped);
  EXPECT_NE(r.reason.find("duplicated or out of order"), std::string::npos) << r.reason;
  r = calibrator.AddFrame(BareFrame(2, 0.9));  // out of order
  EXPECT_TRUE(r.skipped);
  auto nan_motion = BareFrame(3, 1.1);
  nan_motion->twist.linear_m_s.x() = std::numeric_limits<double>::quiet_NaN();
  r = calibrator.AddFrame(nan_motion);
  EXPECT_TRUE(r.skipped);
  EXPECT_NE(r.reason.find("non-finite"), std::string::npos) << r.reason;
  auto black = BareFrame(4, 1.2);
  black->image.edge_pixels = 0;
  r = calibrator.AddFrame(black);
  EXPECT_TRUE(r.skipped);
  EXPECT_NE(r.reason.find("no image edges"), std::string::npos) << r.reason;
  // Good data again: taken (in time order after the last good frame).
  r = calibrator.AddFrame(BareFrame(5, 1.3));
  EXPECT_FALSE(r.skipped) << r.reason;
  EXPECT_TRUE(calibrator.state().T_camera_lidar.isApprox(start.T_camera_lidar));
  EXPECT_EQ(calibrator.state().time_offset_s, start.time_offset_s);
}

// BareFrame with four edge points 5 m ahead that project into its image at the identity
// calibration, the second one a fold; point i lies at x = 0.1 i.
std::shared_ptr<CalibrationFrame> FrameWithAFold(int index, double time_s) {
  auto frame = BareFrame(index, time_s);
  frame->camera.P_rect << 10, 0, 32, 0, 0, 10, 16, 0, 0, 0, 1, 0;
  for (int i = 0; i < 4; ++i) {
    frame->points_lidar.push_back(Eigen::Vector3d(0.1 * i, 0, 5));
    frame->kinds.push_back(i % 2 ? EdgeKind::kHorizontal : EdgeKind::kVertical);
    frame->offset_rates.push_back(Eigen::Vector3d(0, 0, i));
  }
  frame->folds = {0, 1, 0, 0};
  return frame;
}

// WithoutFolds drops the fold points with their kinds and rates, in order; a frame without
// folds is returned as it is.
TEST(OnlineCalibrator, WithoutFoldsDropsFoldsWithTheirEntries) {
  auto frame = FrameWithAFold(0, 1.0);
  const auto kept = WithoutFolds(std::shared_ptr<const CalibrationFrame>(frame));
  ASSERT_EQ(kept->size(), 3u);
  EXPECT_THAT(kept->folds, ::testing::ElementsAre(0, 0, 0));
  std::vector<int> index;
  for (size_t k = 0; k < 3; ++k) {
    const int i = static_cast<int>(std::lround(10 * kept->points_lidar[k].x()));
    index.push_back(i);
    EXPECT_EQ(kept->offset_rates[k].z(), i);
    EXPECT_EQ(kept->kinds[k], i % 2 ? EdgeKind::kHorizontal : EdgeKind::kVertical);
  }
  EXPECT_THAT(index, ::testing::ElementsAre(0, 2, 3));
  std::shared_ptr<const CalibrationFrame> none = frame;
  frame->folds = {0, 0, 0, 0};
  EXPECT_EQ(WithoutFolds(none).get(), none.get());
  frame->folds.clear();  // no flags at all
  EXPECT_EQ(WithoutFolds(none).get(), none.get());
}

// What the calibrator's window holds of a frame with a fold: kKeep all four points, kDrop three;
// kDropWhenTracking four as long as it acquires.
TEST(OnlineCalibrator, FoldsInTheWindowFollowTheOption) {
  using Folds = OnlineCalibratorOptions::Folds;
  for (const auto& [folds, points] : {std::tuple{Folds::kKeep, 4u}, std::tuple{Folds::kDrop, 3u},
                                      std::tuple{Folds::kDropWhenTracking, 4u}}) {
    OnlineCalibratorOptions options;
    options.folds = folds;
    OnlineCalibrator calibrator(options, CalibrationState());
    const FrameReport r = calibrator.AddFrame(FrameWithAFold(0, 1.0));
    EXPECT_NE(r.reason.find("too few LiDAR edge points"), std::string::npos) << r.reason;
    ASSERT_EQ(calibrator.RecentFrames().size(), 1u);
    EXPECT_EQ(calibrator.RecentFrames()[0]->size(), points) << FoldsName(folds);
    EXPECT_EQ(calibrator.SearchWindow()[0], calibrator.RecentFrames()[0].get());
  }
  OnlineCalibratorOptions::Folds parsed = OnlineCalibratorOptions::Folds::kKeep;
  EXPECT_TRUE(ParseFolds("drop_when_tracking", &parsed));
  EXPECT_EQ(parsed, OnlineCalibratorOptions::Folds::kDropWhenTracking);
  EXPECT_FALSE(ParseFolds("sometimes", &parsed));
  EXPECT_EQ(parsed, OnlineCalibratorOptions::Folds::kDropWhenTracking);
}

// A tracking update takes tracking_gain of a small move (scatter) and all but
// tracking_max_lag_deg of a large one (a correction); the two agree where they meet, so the
// step grows continuously with the move.
TEST(OnlineCalibrator, TrackingRotationShareLagsALargeMoveByTheMaxLagOnly) {
  const double g = 0.3, lag = 0.3 * M_PI / 180.0;
  for (double move_deg : {0.0, 0.1, 0.3, 0.4}) {  // (1 − g)·move ≤ lag: the gain
    EXPECT_DOUBLE_EQ(TrackingRotationShare(g, move_deg * M_PI / 180.0, lag), g) << move_deg;
  }
  for (double move_deg : {0.5, 1.0, 3.0}) {  // the estimate ends exactly `lag` short
    const double move = move_deg * M_PI / 180.0;
    const double share = TrackingRotationShare(g, move, lag);
    EXPECT_GT(share, g) << move_deg;
    EXPECT_NEAR((1.0 - share) * move, lag, 1e-15) << move_deg;
  }
  const double meet = lag / (1.0 - g);  // 0.4286°: both rules give g
  EXPECT_NEAR(TrackingRotationShare(g, meet * (1 + 1e-9), lag), g, 1e-8);
  EXPECT_DOUBLE_EQ(TrackingRotationShare(g, 1.0, 0.0), g);      // no limit
  EXPECT_DOUBLE_EQ(TrackingRotationShare(1.0, 1.0, lag), 1.0);  // full steps stay full
}

// The refinement's loss: refine.loss while acquiring (kAcquiredLoss once acquired, which the
// stages' test below reaches); the names parse both ways.
TEST(OnlineCalibrator, AcquiredLossOnceAcquired) {
  OnlineCalibratorOptions options;
  options.refine.loss = RefineOptions::Loss::kCauchy;
  options.refine.loss_scale_px = 1.0;
  const OnlineCalibrator acquiring(options, CalibrationState());
  ASSERT_TRUE(acquiring.acquiring());
  EXPECT_EQ(acquiring.RefineOptionsInUse().loss, RefineOptions::Loss::kCauchy);
  EXPECT_EQ(acquiring.RefineOptionsInUse().loss_scale_px, 1.0);
  ASSERT_NE(kAcquiredLoss, RefineOptions::Loss::kCauchy);
  for (RefineOptions::Loss loss :
       {RefineOptions::Loss::kHuber, RefineOptions::Loss::kCauchy, RefineOptions::Loss::kTukey}) {
    RefineOptions::Loss parsed = RefineOptions::Loss::kHuber;
    EXPECT_TRUE(ParseLoss(LossName(loss), &parsed));
    EXPECT_EQ(parsed, loss);
  }
  RefineOptions::Loss parsed = RefineOptions::Loss::kCauchy;
  EXPECT_FALSE(ParseLoss("l2", &parsed));
  EXPECT_EQ(parsed, RefineOptions::Loss::kCauchy);
}

// The shared settings reach every stage: the calibrator scores and refines with its one
// horizontal-edge weight and its one δ bound, whatever the sub-structs held.
TEST(OnlineCalibrator, SharedSettingsReachScoreSearchAndRefine) {
  OnlineCalibratorOptions options;
  options.horizontal_weight = 0.35;
  options.time_offset_bound_s = 0.07;
  options.score.horizontal_weight = 0.9;
  options.refine.horizontal_weight = 0.1;
  const OnlineCalibrator calibrator(options, CalibrationState());
  EXPECT_EQ(calibrator.options().score.horizontal_weight, 0.35);
  EXPECT_EQ(calibrator.options().refine.horizontal_weight, 0.35);
  EXPECT_EQ(calibrator.options().search.time_offset_bound_s, 0.07);
  EXPECT_EQ(calibrator.options().refine.time_offset_bound_s, 0.07);
  // Out of [0, 1]: a user error, reported by Validate.
  options.horizontal_weight = 1.5;
  EXPECT_FALSE(options.Validate().ok());
  options.horizontal_weight = 0.35;
  ASSERT_TRUE(options.Validate().ok());
  options.tracking_update_every = 0;
  EXPECT_FALSE(options.Validate().ok());
}

// --init_uncertainty's figures: parsed with errors naming the text; a start within the defaults'
// bounds and priors leaves them as they are, a wider one widens the bounds (norms over three
// axes, holding the lattice's reach) and the priors to hold it, and the δ bound to reach around
// δ0.
TEST(OnlineCalibrator, StartUncertaintySetsTheBoundsAndPriors) {
  StartUncertainty u;
  ASSERT_TRUE(ParseStartUncertainty("5,0.2,0.1", &u).ok());
  EXPECT_EQ(u.rotation_deg, 5.0);
  EXPECT_EQ(u.translation_m, 0.2);
  EXPECT_EQ(u.time_offset_s, 0.1);
  EXPECT_EQ(StartUncertaintyText(u), "5,0.2,0.1");
  for (const char* bad : {"", "5,0.2", "5,0.2,0.1,1", "5,,0.1", "5,x,0.1", "-1,0.2,0.1",
                          "0,0.2,0.1", "5,nan,0.1", "5,0.2,0.1,"}) {
    const Status status = ParseStartUncertainty(bad, &u);
    EXPECT_FALSE(status.ok()) << bad;
    EXPECT_THAT(status.message(), ::testing::HasSubstr(std::string("--init_uncertainty=") + bad));
  }

  OnlineCalibratorOptions defaults;
  defaults.start_uncertainty = {2, 0.05, 0.03};
  const OnlineCalibratorOptions same = WithStartUncertainty(defaults, 0.0);
  EXPECT_EQ(same.search.max_translation_offset_m, defaults.search.max_translation_offset_m);
  EXPECT_EQ(same.search.translation_prior_sigma_m, defaults.search.translation_prior_sigma_m);
  EXPECT_EQ(same.refine.prior_sigma_translation_m, defaults.refine.prior_sigma_translation_m);
  EXPECT_EQ(same.refine.prior_sigma_time_s, defaults.refine.prior_sigma_time_s);
  EXPECT_EQ(same.time_offset_bound_s, defaults.time_offset_bound_s);

  OnlineCalibratorOptions wide_options;
  wide_options.start_uncertainty = {5, 0.2, 0.1};
  const OnlineCalibratorOptions widened = WithStartUncertainty(wide_options, -0.1);
  // A truth 5° off on each axis, 0.2 m on each, and δ 0.1 s beyond δ0 lies inside the bounds.
  CalibrationState start;
  CalibrationState truth =
      Step(start, Eigen::Vector3d(5, -5, 5) * M_PI / 180.0, Eigen::Vector3d(0.2, -0.2, 0.2), -0.2);
  start.time_offset_s = -0.1;
  EXPECT_FALSE(WithinBounds(truth, start, OnlineCalibratorOptions().search));
  EXPECT_TRUE(WithinBounds(truth, start, WithSharedSettings(widened).search));
  EXPECT_EQ(widened.refine.prior_sigma_translation_m, 0.2);
  EXPECT_EQ(widened.search.translation_prior_sigma_m, 0.2);
  EXPECT_EQ(widened.refine.prior_sigma_time_s, 0.1);
  EXPECT_EQ(widened.search.time_offset_prior_sigma_s, 0.1);
  EXPECT_GE(widened.time_offset_bound_s, 0.2);
  EXPECT_TRUE(widened.Validate().ok());
  wide_options.start_uncertainty.time_offset_s = 0;
  EXPECT_FALSE(wide_options.Validate().ok());
}

TEST(Calibration, StagesAgainstSimulatedTruth) {
  testing::ScopedTempDir tmp;
  sim::SimulatorOptions sim_options;
  sim_options.seed = 2;
  sim_options.frames = 12;
  sim_options.time_offset_s = 0.03;
  std::string drive_dir;
  ASSERT_TRUE(sim::WriteSimulatedDrive(sim_options, tmp.path(), &drive_dir).ok());
  const sim::Simulator simulator(sim_options);
  CalibrationState truth;
  truth.T_camera_lidar = simulator.T_camera_lidar();
  truth.time_offset_s = 0.03;

  Drive drive;
  ASSERT_TRUE(OpenDrive(drive_dir, "", &drive).ok());
  std::unique_ptr<DriveFrameSource> source;
  ASSERT_TRUE(DriveFrameSource::Create(&drive, FrameSourceOptions(), &source).ok());
  std::vector<std::shared_ptr<CalibrationFrame>> frames;
  for (size_t i = 0; i < drive.NumFrames(); ++i) {
    frames.push_back(std::make_shared<CalibrationFrame>());
    ASSERT_TRUE(source->Load(i, frames.back().get()).ok());
    EXPECT_NEAR(frames.back()->e0_s, -0.0105 - 0.03, 5e-4);  // stamps: LiDAR − camera
    EXPECT_GT(frames.back()->twist.linear_m_s.x(), 7.0);     // driving forward, LiDAR x
  }
  // The stages run on what the calibrator gives them: six frames pruned to the image at the
  // start (OnlineCalibrator::AddFrame does the same). On three frames the roll of this drive is
  // weak: whether the search ends 0.2 or 1.2 deg off in roll there depends on which
  // points the scorer's thinning keeps (measured over windows 2-4, 3-5, 4-6, pruned or not, 600
  // points or all). On six frames every such variant ends within the bounds asserted below.
  const CalibrationState start =
      Step(truth, Eigen::Vector3d(2, -2, 2) * M_PI / 180.0, Eigen::Vector3d::Zero(), -0.03);
  std::vector<std::shared_ptr<const CalibrationFrame>> pruned;
  std::vector<const CalibrationFrame*> window;
  for (int i = 2; i < 8; ++i) {
    pruned.push_back(PruneToImage(*frames[i], start, OnlineCalibratorOptions().point_margin));
    window.push_back(pruned.back().get());
  }
  WindowScorer scorer(window, ScoreOptions());

  // Health: a calibrated pair is a clear optimum of its neighbourhood, a wrong one is not.
  const double health_truth = HealthScore(&scorer, truth);
  const CalibrationState one_off =
      Step(truth, Eigen::Vector3d(0, 1, 1) * M_PI / 180.0, Eigen::Vector3d::Zero(), 0.0);
  const double health_off = HealthScore(&scorer, one_off);
  std::printf("health: truth %.3f, 1.4 deg off %.3f\n", health_truth, health_off);
  EXPECT_GT(health_truth, 0.9);
  EXPECT_LT(health_off, health_truth - 0.2);
  // The neighbourhood in one pass (what HealthScore and the search use) equals its neighbours
  // scored one by one, bit for bit, on the finest and on the coarsest map.
  for (int level : {-1, 0}) {
    const std::vector<Eigen::Matrix<double, 6, 1>>& directions = NeighbourDirections(true);
    ASSERT_EQ(directions.size(), 728u);
    std::vector<CalibrationState> neighbours;
    for (const Eigen::Matrix<double, 6, 1>& d : directions) {
      neighbours.push_back(Step(one_off, 0.01 * d.head<3>(), 0.03 * d.tail<3>(), 0.0));
    }
    const std::vector<ScoreValue> batch = scorer.EvaluateStates(neighbours, level);
    ASSERT_EQ(batch.size(), directions.size());
    for (size_t n = 0; n < directions.size(); ++n) {
      const ScoreValue single = scorer.Evaluate(neighbours[n], level);
      ASSERT_EQ(batch[n].score, single.score) << "level " << level << ", neighbour " << n;
      ASSERT_EQ(batch[n].projected, single.projected) << "level " << level << ", neighbour " << n;
      ASSERT_EQ(batch[n].weight_sum, single.weight_sum);
      ASSERT_EQ(batch[n].gray_rate, single.gray_rate);
    }
  }
  // The health cache: a window sliding one frame at a time with the estimate unchanged scores
  // only its newest frame, and every health and best gain equals the uncached one exactly; a
  // moved estimate, or a frame replaced at the same address by a later one, is scored afresh.
  {
    HealthScoreCache cache;
    auto frame_scorings = [&](const std::vector<const CalibrationFrame*>& w,
                              const CalibrationState& state) {
      const int before = cache.frames_scored();
      WindowScorer uncached(w, ScoreOptions()), cached(w, ScoreOptions());
      double gain = 0, cached_gain = 0;
      const double health = HealthScore(&uncached, state, 1.0, 0.05, &gain);
      EXPECT_EQ(HealthScore(&cached, state, 1.0, 0.05, &cached_gain, &cache), health);
      EXPECT_EQ(cached_gain, gain);
      return cache.frames_scored() - before;
    };
    EXPECT_EQ(frame_scorings({window[0], window[1], window[2]}, truth), 3);
    EXPECT_EQ(frame_scorings({window[1], window[2], window[3]}, truth), 1);
    EXPECT_EQ(frame_scorings({window[2], window[3], window[4]}, truth), 1);
    EXPECT_EQ(frame_scorings({window[2], window[3], window[4]}, one_off), 3);
    EXPECT_EQ(frame_scorings({window[3], window[4], window[5]}, one_off), 1);
    // A frame at the address of window[5] with a later stamp and other points.
    CalibrationFrame& reused = const_cast<CalibrationFrame&>(*pruned[5]);
    const CalibrationFrame saved = reused;
    reused = *pruned[0];
    reused.camera_time_s = saved.camera_time_s + 1.0;
    EXPECT_EQ(frame_scorings({window[3], window[4], window[5]}, one_off), 1);
    reused = saved;
  }

  // Search on the finest map from 0.6° on every axis (1.04°, within its peak's basin, where the
  // calibrator starts it from the best hypothesis): back to pitch and yaw within a few tenths;
  // roll, weak on these frames, within a degree, by horizontal-edge weight and thinning alone.
  for (const double w : {0.2, 0.35, 0.5}) {
    for (const int points : {600, 0}) {
      ScoreOptions variant;
      variant.horizontal_weight = w;
      variant.max_points_per_frame = points;
      WindowScorer variant_scorer(window, variant);
      const CalibrationState near_start =
          Step(truth, Eigen::Vector3d(0.6, -0.6, 0.6) * M_PI / 180.0, Eigen::Vector3d::Zero(), 0);
      const SearchResult result =
          AdaptiveGridSearch(&variant_scorer, near_start, near_start, AdaptiveGridSearchOptions());
      const CalibrationError error = ComputeCalibrationError(result.state, truth);
      std::printf("search from 1.04 deg, w %.2f, %d points: %s\n", w, points,
                  ToString(error).c_str());
      EXPECT_LT(error.rotation_deg, 1.1) << "w " << w << ", points " << points;
      EXPECT_LT(std::abs(error.pitch_deg), 0.2) << "w " << w << ", points " << points;
      EXPECT_LT(std::abs(error.yaw_deg), 0.1) << "w " << w << ", points " << points;
      EXPECT_GT(result.end.score, result.start.score);
    }
  }

  // The acquisition's lattice at ±5°, ±20 cm, ±100 ms around a start 3.5° off in rotation, 6 cm in
  // translation and δ0 30 ms off, none of them on a lattice point:
  // - one frame's score vector equals a direct evaluation: each thinned point projected by
  //   ProjectFramePoint (the scorer's projection) and read at its nearest coarse cell;
  // - the window's running sums equal the sum of its frames' vectors, a frame leaving subtracted;
  // - the best hypothesis lies within a step of the truth on every axis.
  {
    const CalibrationState lattice_start = Step(truth, Eigen::Vector3d(2.2, -1.8, 2.1) * M_PI / 180,
                                                Eigen::Vector3d(0.03, -0.03, 0.04), -0.03);
    const StartUncertainty wide{5, 0.2, 0.1};
    HypothesisLattice lattice;
    ASSERT_TRUE(HypothesisLattice::Create(lattice_start, wide, LatticeSteps(), &lattice).ok());
    const size_t expected = 11 * 15 * 5 * 5 * 3;  // rotations (x, y, z), δ, translations
    EXPECT_EQ(lattice.size(), expected);
    EXPECT_EQ(HypothesisLattice::CountFor(wide, LatticeSteps()), expected);
    EXPECT_EQ(HypothesisLattice::CountFor(StartUncertainty(), LatticeSteps()), 7u * 9 * 3 * 3 * 1);
    // Every rotation offset within the span lies within half a step of a lattice rotation on
    // each axis (corners and a few points inside).
    const Eigen::Vector3d steps_deg = LatticeSteps().rotation_deg;
    for (const Eigen::Vector3d& v :
         std::vector<Eigen::Vector3d>{Eigen::Vector3d(5, 5, 5), Eigen::Vector3d(-5, 4.6, -0.3),
                                      Eigen::Vector3d(1.1, -2.9, 4.99), Eigen::Vector3d(0, 0, 0)}) {
      double nearest = std::numeric_limits<double>::infinity();
      for (size_t r = 0; r < lattice.num_rotations(); ++r) {
        const Eigen::Vector3d offset_deg =
            lattice.RotationOffsetRad(r * lattice.num_time_offsets() * lattice.num_translations()) *
            180.0 / M_PI;
        nearest =
            std::min(nearest, (offset_deg - v).cwiseQuotient(steps_deg).cwiseAbs().maxCoeff());
      }
      EXPECT_LE(nearest, 0.5 + 1e-9) << v.transpose();
    }
    HypothesisLattice too_large;
    const Status refused =
        HypothesisLattice::Create(lattice_start, wide, LatticeSteps(), &too_large, 1000);
    EXPECT_FALSE(refused.ok());
    EXPECT_EQ(refused.message(), "a lattice of " + std::to_string(lattice.size()) +
                                     " hypotheses does not fit in memory (at most 1000): narrow "
                                     "the start uncertainty");
    // The calibrator's options refuse what the lattice refuses, with the same words.
    OnlineCalibratorOptions online;
    online.start_uncertainty = {60, 2, 1};
    const Status huge = online.Validate();
    EXPECT_FALSE(huge.ok());
    EXPECT_NE(huge.message().find("does not fit in memory (at most 4000000)"), std::string::npos)
        << huge.message();
    const CalibrationFrame& frame = *window[0];
    ASSERT_FALSE(frame.coarse_map[0].empty());
    std::vector<float> scores;
    ScoreFrameOnLattice(frame, lattice, 0.2, 256, &scores);
    ASSERT_EQ(scores.size(), lattice.size());
    const int scale = frame.coarse_map_scale;
    for (size_t h = 0; h < lattice.size(); h += 997) {
      const CalibrationState state = lattice.State(h);
      double direct = 0, magnitude = 0;
      const size_t n = frame.size(), keep = std::min<size_t>(n, 256);
      for (size_t k = 0; k < keep; ++k) {
        const size_t i = k * n / keep;
        Eigen::Vector2d pixel;
        if (!ProjectFramePoint(frame, state, i, &pixel)) continue;
        const cv::Mat& map = frame.coarse_map[frame.kinds[i] == EdgeKind::kHorizontal];
        const double offset = 1.5 - 0.5 * (scale - 1.0) / scale;
        const int u = std::clamp<int>(std::floor(pixel.x() / scale + offset), 0, map.cols - 1);
        const int v = std::clamp<int>(std::floor(pixel.y() / scale + offset), 0, map.rows - 1);
        const double w = frame.kinds[i] == EdgeKind::kHorizontal ? 0.2 : 0.8;
        direct += w * map.at<float>(v, u);
        magnitude += w * std::abs(map.at<float>(v, u));
      }
      // Float arithmetic: a point on a cell's border may read its neighbour.
      EXPECT_NEAR(scores[h], direct, 1e-3 * magnitude + 2 * 255.0) << "hypothesis " << h;
    }
    LatticeWindow lattice_window(3);
    std::vector<std::vector<float>> kept;
    for (size_t f = 0; f < window.size(); ++f) {
      std::vector<float> frame_scores;
      ScoreFrameOnLattice(*window[f], lattice, 0.2, 256, &frame_scores);
      kept.push_back(frame_scores);
      lattice_window.Add(window[f]->index, std::move(frame_scores));
    }
    EXPECT_EQ(lattice_window.frames(), 3);
    for (size_t h = 0; h < lattice.size(); h += 101) {
      const double sum = double(kept[3][h]) + kept[4][h] + kept[5][h];
      EXPECT_NEAR(lattice_window.sums()[h], sum, 1e-3 * (std::abs(sum) + 1)) << h;
    }
    // All six frames: the best hypothesis is the truth's lattice neighbour.
    LatticeWindow all(6);
    for (std::vector<float>& frame_scores : kept) all.Add(0, std::move(frame_scores));
    const std::vector<size_t> top = TopHypotheses(lattice, all.sums(), 3);
    ASSERT_EQ(top.size(), 3u);
    const CalibrationState best = lattice.State(top[0]);
    const Eigen::Vector3d rotation_offset_deg =
        LogSO3(best.T_camera_lidar.linear() * truth.T_camera_lidar.linear().transpose()) * 180 /
        M_PI;
    std::printf(
        "lattice: best hypothesis off the truth by (%.2f, %.2f, %.2f) deg about camera x, "
        "y, z, δ %+.1f ms\n",
        rotation_offset_deg.x(), rotation_offset_deg.y(), rotation_offset_deg.z(),
        1000 * (best.time_offset_s - truth.time_offset_s));
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE(std::abs(rotation_offset_deg[k]), LatticeSteps().rotation_deg[k]) << k;
    }
    EXPECT_LE(std::abs(best.time_offset_s - truth.time_offset_s), LatticeSteps().time_offset_s);
    // Distinct rotations: no two within one step of each other on every axis.
    for (size_t a = 0; a < top.size(); ++a) {
      for (size_t b = a + 1; b < top.size(); ++b) {
        const Eigen::Vector3i gap = lattice.RotationCell(lattice.RotationOf(top[a])) -
                                    lattice.RotationCell(lattice.RotationOf(top[b]));
        EXPECT_GE(gap.cwiseAbs().maxCoeff(), 2);
      }
    }
  }

  // Refinement over eight frames from a small error: closer to the truth, with a covariance.
  std::vector<const CalibrationFrame*> long_window;
  for (size_t i = 2; i < frames.size(); ++i) long_window.push_back(frames[i].get());
  const CalibrationState near = Step(truth, Eigen::Vector3d(0.3, -0.3, 0.3) * M_PI / 180.0,
                                     Eigen::Vector3d(0.02, -0.02, 0.0), 0.0);
  const RefineResult refine = Refine(long_window, near, near, truth, RefineOptions());
  ASSERT_TRUE(refine.usable) << refine.message;
  const CalibrationError refine_error = ComputeCalibrationError(refine.state, truth);
  std::printf("refine from %.3f deg: %s; std roll %.3f deg, time %.4f s, corr(δ, forward) %.2f\n",
              ComputeCalibrationError(near, truth).rotation_deg, ToString(refine_error).c_str(),
              refine.std_dev[0], refine.std_dev[6], refine.time_forward_correlation);
  // Measured: 0.41° (roll +0.41, a roll bias of the vertical edges on this drive; 0.58° on the
  // plain IDT).
  EXPECT_LT(refine_error.rotation_deg, 1.0);
  EXPECT_TRUE(refine.covariance_ok);
  EXPECT_LT(std::abs(refine_error.time_offset_s), 0.02);

  // The translation along the direction of travel only (the polish's first stage): it moves along
  // the last frame's LiDAR velocity in the camera frame and nowhere else, and its covariance is
  // of rank one along that direction.
  RefineOptions along_options;
  along_options.translation = RefineOptions::Translation::kAlongTravel;
  const RefineResult along = Refine(long_window, near, near, truth, along_options);
  ASSERT_TRUE(along.usable && along.covariance_ok) << along.message;
  const Eigen::Vector3d forward =
      (near.T_camera_lidar.linear() * long_window.back()->twist.linear_m_s).normalized();
  const Eigen::Vector3d moved =
      along.state.T_camera_lidar.translation() - near.T_camera_lidar.translation();
  std::printf("refine along travel: moved %.2f cm, forward std %.2f cm, δ std %.2f ms, corr %.2f\n",
              100 * moved.norm(), 100 * along.forward_std_m, 1000 * along.std_dev[6],
              along.time_forward_correlation);
  EXPECT_LT(moved.cross(forward).norm(), 1e-9);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(along.std_dev[3 + k], std::abs(forward[k]) * along.forward_std_m, 1e-9);
  }

  // δ profile: the best offset is near the truth.
  const TimeOffsetProfile profile = ProfileTimeOffset(&scorer, truth, 0.15, 0.0025);
  std::printf("time-offset profile: best %.4f s (truth 0.03), second peak ratio %.2f\n",
              profile.best_s, profile.second_peak_ratio);
  EXPECT_NEAR(profile.best_s, 0.03, 0.015);

  // The online calibrator over the drive from ±2° / ±5 cm / δ0 30 ms off, with the defaults but
  // for the refinement window (these are 12 frames).
  OnlineCalibratorOptions online_options;
  online_options.refine_frames = 10;
  const CalibrationState online_start = Step(truth, Eigen::Vector3d(-2, 2, -2) * M_PI / 180.0,
                                             Eigen::Vector3d(0.05, -0.05, 0.05), -0.03);
  // `calibrator` keeps the folds throughout (Folds::kKeep). Alongside, the same run dropping them
  // once acquired (Folds::kDropWhenTracking, the default): until the acquisition's last frame it
  // reads what `calibrator` reads and ends where it does; from the next frame on its windows
  // hold no fold, that frame updates at once (whatever tracking_update_every says: here never
  // again), and the health still reads the folds.
  ASSERT_EQ(online_options.folds, OnlineCalibratorOptions::Folds::kDropWhenTracking);
  online_options.folds = OnlineCalibratorOptions::Folds::kKeep;
  OnlineCalibrator calibrator(online_options, online_start);
  OnlineCalibratorOptions dropping_options = online_options;
  dropping_options.folds = OnlineCalibratorOptions::Folds::kDropWhenTracking;
  dropping_options.tracking_update_every = 1000;
  OnlineCalibrator dropping(dropping_options, online_start);
  auto count_folds = [](const auto& frames) {
    size_t folds = 0;
    for (const auto& f : frames) folds += std::count(f->folds.begin(), f->folds.end(), 1);
    return folds;
  };
  auto folds_read = [&](const OnlineCalibrator& c) { return count_folds(c.RecentFrames()); };
  int dropped_frames = 0;
  auto check_dropped = [&](const FrameReport& report) {
    SCOPED_TRACE("frame " + std::to_string(report.frame) + ": " + report.reason);
    EXPECT_EQ(folds_read(dropping), 0u);
    EXPECT_GT(count_folds(dropping.HealthWindow()), 0u);
    // From then on every window is read at kFoldFreeHorizontalWeight, the health's too, and
    // the refinement at the acquired loss.
    ASSERT_NE(kFoldFreeHorizontalWeight, dropping.options().horizontal_weight);
    EXPECT_EQ(dropping.ScoreOptionsInUse().horizontal_weight, kFoldFreeHorizontalWeight);
    EXPECT_EQ(dropping.RefineOptionsInUse().horizontal_weight, kFoldFreeHorizontalWeight);
    EXPECT_EQ(dropping.RefineOptionsInUse().loss, kAcquiredLoss);
    WindowScorer health_scorer(dropping.HealthWindow(), dropping.ScoreOptionsInUse());
    EXPECT_EQ(report.health, HealthScore(&health_scorer, dropping.state()));
    const bool first = dropped_frames++ == 0;
    EXPECT_EQ(report.reason.find("folds dropped, a full step") == 0,
              first && report.accepted && !report.from_hypotheses);
    if (first) {
      EXPECT_TRUE(report.ran_update());
    } else if (report.health_before >= dropping_options.lost_health) {
      EXPECT_FALSE(report.ran_update());  // tracking, next update in 1000 frames
    }
  };
  size_t folds_while_acquiring = 0;
  FrameReport last;
  for (size_t k = 0; k < frames.size(); ++k) {
    const CalibrationState before = calibrator.state();
    last = calibrator.AddFrame(frames[k]);
    const FrameReport dropped = dropping.AddFrame(frames[k]);
    if (dropped.acquiring) {  // acquiring when the frame arrived: the default's frames
      EXPECT_EQ(dropping.ScoreOptionsInUse().horizontal_weight,
                dropping.options().horizontal_weight);
      folds_while_acquiring += folds_read(dropping);
      EXPECT_EQ(folds_read(dropping), folds_read(calibrator)) << "frame " << k;
      EXPECT_TRUE(dropping.state().T_camera_lidar.matrix() ==
                  calibrator.state().T_camera_lidar.matrix())
          << "frame " << k;
    } else {
      check_dropped(dropped);
      EXPECT_GT(folds_read(calibrator), 0u) << "frame " << k;
    }
    if (static_cast<int>(k) + 1 < online_options.window_frames) {
      // One or two frames are not trusted with a jump: the window fills first.
      EXPECT_FALSE(last.accepted);
      EXPECT_NE(last.reason.find("window filling"), std::string::npos) << last.reason;
      EXPECT_TRUE(calibrator.state().T_camera_lidar.isApprox(before.T_camera_lidar));
    }
  }
  // The acquisition scored each frame once over its lattice while it acquired: its window holds
  // every frame that arrived until then (up to refine_frames).
  EXPECT_GT(calibrator.acquisition().frames(), online_options.window_frames - 1);
  EXPECT_LE(calibrator.acquisition().frames(), online_options.refine_frames);
  EXPECT_TRUE(calibrator.acquisition().dominance().dominant);
  EXPECT_GT(folds_while_acquiring, 0u);
  {
    auto later = std::make_shared<CalibrationFrame>(*frames.back());  // a tracking frame
    later->camera_time_s += 20.0;
    ASSERT_GT(std::count(later->folds.begin(), later->folds.end(), 1), 0);
    ASSERT_FALSE(dropping.acquiring());
    EXPECT_GT(dropped_frames, 0);  // the acquisition ended within the drive
    check_dropped(dropping.AddFrame(later));
    EXPECT_LT(ComputeCalibrationError(dropping.state(), truth).rotation_deg, 0.5);
  }
  const CalibrationError online_error = ComputeCalibrationError(calibrator.state(), truth);
  std::printf("online after %zu frames: %s, health %.2f\n", frames.size(),
              ToString(online_error).c_str(), last.health);
  EXPECT_LT(online_error.rotation_deg, 0.5);  // measured 0.22° (from 3.46°; plain IDT 0.45°)
  EXPECT_LT(online_error.translation_norm_m, 0.12);
  EXPECT_LT(std::abs(online_error.time_offset_s), 0.02);
  EXPECT_GT(last.health, 0.8);

  // Tracking cadence (tracking_update_every, default 3): once acquired, a healthy frame runs the
  // search and refinement on every third frame only; the frames between join the window and
  // keep the estimate; a disturbance (SetState) and `update_now` update at once. Replayed frames,
  // restamped.
  {
    ASSERT_EQ(online_options.tracking_update_every, 3);
    ASSERT_FALSE(calibrator.acquiring());
    OnlineCalibrator every_third = calibrator;
    double later_s = 20.0;
    auto replay = [&](size_t k) {
      auto again = std::make_shared<CalibrationFrame>(*frames[k]);
      again->camera_time_s += later_s;
      return again;
    };
    int updates = 0, lost = 0;
    std::string reasons;
    for (size_t k = 3; k < 12; ++k) {
      const CalibrationState before = every_third.state();
      const auto again = replay(k);
      const FrameReport r = every_third.AddFrame(again);
      EXPECT_EQ(every_third.RecentFrames().back()->camera_time_s, again->camera_time_s);  // joined
      lost += r.health_before < online_options.lost_health;
      updates += r.ran_update();
      reasons += r.reason.substr(0, 36) + "\n";
      if (!r.ran_update()) {
        EXPECT_NE(r.reason.find("tracking: healthy"), std::string::npos) << r.reason;
        EXPECT_TRUE(every_third.state().T_camera_lidar.matrix() == before.T_camera_lidar.matrix());
      }
    }
    const double error_every_third =
        ComputeCalibrationError(every_third.state(), truth).rotation_deg;
    std::printf("tracking cadence: %d updates in 9 frames, %.3f deg from the truth\n", updates,
                error_every_third);
    ASSERT_EQ(lost, 0) << reasons;
    EXPECT_EQ(updates, 3) << reasons;  // nine healthy frames: three updates
    // Measured 0.39° (0.22° before the replay; 0.51° updating on every frame: tracking drifts to
    // the refinement's optimum on these frames, roll-biased, see the disturbance below).
    EXPECT_LT(error_every_third, 0.5);
    // At once: the frame after a disturbance, and a frame asked to; each right after an update,
    // when the cadence alone would wait, and healthy (not lost, which updates anyway).
    later_s = 30.0;
    size_t k = 3;
    while (!every_third.AddFrame(replay(k++)).ran_update()) ASSERT_LT(k, 12u);
    every_third.SetState(Step(every_third.state(), Eigen::Vector3d(0.2, 0, 0) * M_PI / 180.0,
                              Eigen::Vector3d::Zero(), 0.0));
    const FrameReport disturbed = every_third.AddFrame(replay(k++));
    EXPECT_GE(disturbed.health_before, online_options.lost_health);
    EXPECT_TRUE(disturbed.ran_update()) << disturbed.reason;
    const FrameReport asked = every_third.AddFrame(replay(k++), /*update_now=*/true);
    EXPECT_GE(asked.health_before, online_options.lost_health);
    EXPECT_TRUE(asked.ran_update()) << asked.reason;
    const FrameReport waits = every_third.AddFrame(replay(k++));
    EXPECT_GE(waits.health_before, online_options.lost_health);
    EXPECT_FALSE(waits.ran_update()) << waits.reason;
  }

  // The paper's protocol, short: a 2° disturbance on each axis (3.5°) of the running estimate;
  // the last frames again (restamped later) bring it back.
  const CalibrationState settled = calibrator.state();
  calibrator.SetState(
      Step(settled, Eigen::Vector3d(2, -2, 2) * M_PI / 180.0, Eigen::Vector3d::Zero(), 0.0));
  std::vector<std::string> reasons;
  for (size_t k = frames.size() - 3; k < frames.size(); ++k) {
    auto again = std::make_shared<CalibrationFrame>(*frames[k]);
    again->camera_time_s += 10.0;
    const FrameReport r = calibrator.AddFrame(again);
    reasons.push_back(r.reason);
    if (k == frames.size() - 3) {
      // Lost after the acquisition: the rotation jumps to the chosen candidate, the translation
      // and δ move by tracking_gain only.
      EXPECT_TRUE(r.from_hypotheses);
      EXPECT_FALSE(r.acquiring);
      ASSERT_EQ(r.reason.rfind("refined", 0), 0u) << r.reason;
      const CalibrationState chosen =
          KeepObservableAxes(r.before, r.refine.state, r.refine.observable);
      EXPECT_LT(RotationErrorDeg(r.after.T_camera_lidar.linear(), chosen.T_camera_lidar.linear()),
                1e-9);
      const Eigen::Vector3d moved =
          r.after.T_camera_lidar.translation() - r.before.T_camera_lidar.translation();
      const Eigen::Vector3d offered =
          chosen.T_camera_lidar.translation() - r.before.T_camera_lidar.translation();
      EXPECT_GT(offered.norm(), 1e-4);
      EXPECT_LT((moved - online_options.tracking_gain * offered).norm(), 1e-12);
      EXPECT_NEAR(r.after.time_offset_s - r.before.time_offset_s,
                  online_options.tracking_gain * (chosen.time_offset_s - r.before.time_offset_s),
                  1e-12);
    }
    std::printf(
        "after the disturbance, frame %zu: %.3f deg from the settled estimate, %.3f deg "
        "from the truth (%s)\n",
        k,
        RotationErrorDeg(calibrator.state().T_camera_lidar.linear(),
                         settled.T_camera_lidar.linear()),
        ComputeCalibrationError(calibrator.state(), truth).rotation_deg, r.reason.c_str());
  }
  // Back from 3.5° to the refinement's optimum on these frames (measured 0.53° from the truth,
  // 0.33° from the settled estimate; the polish below lands at 0.51°, a roll bias of this short
  // drive): the settled estimate is a filtered one (tracking gain) that had not reached it.
  EXPECT_LT(ComputeCalibrationError(calibrator.state(), truth).rotation_deg, 0.6);
  EXPECT_LT(
      RotationErrorDeg(calibrator.state().T_camera_lidar.linear(), settled.T_camera_lidar.linear()),
      0.4);

  // Polish: a refinement over the refinement's frames from the estimate. On these ten frames the
  // forward translation and δ cannot be told apart, so both are held and it is a rotation-only
  // one. From two estimates 0.6° apart it lands on one optimum (the online estimate is a filtered
  // one; the polish takes it to where the refinement puts it), holding the translation and δ
  // exactly.
  const CalibrationState tracked = calibrator.state();
  std::vector<CalibrationState> polished;
  for (const Eigen::Vector3d& offset_deg :
       {Eigen::Vector3d(0.2, -0.2, 0.2), Eigen::Vector3d(-0.2, 0.2, -0.2)}) {
    calibrator.SetState(Step(tracked, offset_deg * M_PI / 180.0, Eigen::Vector3d::Zero(), 0.0));
    const CalibrationState before_polish = calibrator.state();
    const FrameReport polish = calibrator.Polish();
    ASSERT_TRUE(polish.accepted) << polish.reason;
    EXPECT_THAT(polish.reason, ::testing::HasSubstr("forward translation and δ held"));
    EXPECT_TRUE(polish.refine.covariance_ok);  // rotation only: translation and δ held
    for (int k = 3; k < kNumAxes; ++k) EXPECT_FALSE(polish.refine.observable[k]) << kAxisNames[k];
    // The pair was measured with both free, and not separated (measured: forward std 4.8 cm, δ
    // std 4.7 ms, correlation -0.99); that δ std covers the held δ's error (-3.8 ms).
    const TimeForwardPair& pair = polish.time_forward;
    std::printf("polish pair: δ std %.2f ms, forward std %.2f cm, correlation %+.2f\n",
                1000 * pair.time_offset_std_s, 100 * pair.forward_std_m, pair.correlation);
    EXPECT_TRUE(pair.measured);
    EXPECT_FALSE(pair.separated);
    EXPECT_GT(pair.forward_std_m, kPolishForwardStdM);
    EXPECT_LT(pair.correlation, -0.9);
    EXPECT_LE(std::abs(ComputeCalibrationError(calibrator.state(), truth).time_offset_s),
              3 * pair.time_offset_std_s);
    EXPECT_TRUE(polish.refine.observable[0] && polish.refine.observable[1] &&
                polish.refine.observable[2]);
    polished.push_back(calibrator.state());
    // The polish never lowers the window's score: its rotation is taken only where the score
    // agrees (the pair is held here, so the alternative is the online estimate itself).
    std::vector<const CalibrationFrame*> window;
    for (const auto& f : calibrator.RecentFrames()) window.push_back(f.get());
    WindowScorer scorer(window, calibrator.ScoreOptionsInUse());
    EXPECT_GE(scorer.Evaluate(calibrator.state(), -1).score,
              scorer.Evaluate(before_polish, -1).score);
    EXPECT_EQ(polish.reason.find("rotation kept") != std::string::npos,
              RotationErrorDeg(calibrator.state().T_camera_lidar.linear(),
                               before_polish.T_camera_lidar.linear()) == 0.0);
    EXPECT_EQ(calibrator.state().T_camera_lidar.translation(),
              before_polish.T_camera_lidar.translation());
    EXPECT_EQ(calibrator.state().time_offset_s, before_polish.time_offset_s);
    std::printf("polish from %.3f deg: %s\n",
                ComputeCalibrationError(before_polish, truth).rotation_deg,
                ToString(ComputeCalibrationError(calibrator.state(), truth)).c_str());
    EXPECT_LT(ComputeCalibrationError(calibrator.state(), truth).rotation_deg, 1.0);
  }
  EXPECT_LT(
      RotationErrorDeg(polished[0].T_camera_lidar.linear(), polished[1].T_camera_lidar.linear()),
      0.1);
  // While acquiring (a grid that has not yet agreed) there is nothing to polish.
  OnlineCalibrator acquiring(OnlineCalibratorOptions(), truth);  // the default ±3° grid
  const FrameReport not_yet = acquiring.Polish();
  EXPECT_FALSE(not_yet.accepted);
  EXPECT_NE(not_yet.reason.find("no frames"), std::string::npos) << not_yet.reason;
  acquiring.AddFrame(frames[0]);
  EXPECT_NE(acquiring.Polish().reason.find("still acquiring"), std::string::npos);

  // A frame with no LiDAR edges: the estimate is kept and the report says why.
  auto empty = std::make_shared<CalibrationFrame>(*frames.back());
  empty->ClearPoints();
  OnlineCalibratorOptions single;
  single.window_frames = 1;
  single.refine_frames = 1;
  OnlineCalibrator lonely(single, truth);
  const FrameReport report = lonely.AddFrame(empty);
  EXPECT_FALSE(report.accepted);
  EXPECT_NE(report.reason.find("too few"), std::string::npos) << report.reason;
  EXPECT_LT(ComputeCalibrationError(lonely.state(), truth).rotation_deg, 1e-6);
}

}  // namespace
}  // namespace stcalib
