// Convergence verdict (core/online/convergence.h): a polish that does not converge refuses the
// claim; the independent check on texture-suppressed maps refuses a KITTI estimate 3° off that
// the plain maps' rules would have accepted.
#include "core/online/convergence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/online/frame_source.h"
#include "core/search/adaptive_grid_search.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

// After a polish: the polished verdict when it converged; a converged online estimate whose
// polish does not converge is refused, with the polish's reason; a refusal stays one.
TEST(Convergence, PolishThatDoesNotConvergeRefusesTheClaim) {
  ConvergenceVerdict online;
  online.converged = true;
  online.reason = "converged";
  online.estimate.time_offset_s = 0.01;
  ConvergenceVerdict polished;
  polished.converged = false;
  polished.reason = "not converged: the last frames' score peaks +0.50 deg away on roll_deg";
  polished.estimate.time_offset_s = 0.02;

  const ConvergenceVerdict refused = VerdictAfterPolish(online, polished);
  EXPECT_FALSE(refused.converged);
  EXPECT_EQ(refused.reason,
            "not converged: refined over its last frames, the estimate does not converge (the "
            "last frames' score peaks +0.50 deg away on roll_deg)");
  EXPECT_EQ(refused.estimate.time_offset_s, 0.01);  // the online estimate, not the polished one

  polished.converged = true;
  polished.reason = "converged";
  const ConvergenceVerdict taken = VerdictAfterPolish(online, polished);
  EXPECT_TRUE(taken.converged);
  EXPECT_EQ(taken.estimate.time_offset_s, 0.02);

  online.converged = false;
  online.reason = "not converged: still moving (0.400 deg over the last 3 frames)";
  polished.converged = false;
  const ConvergenceVerdict kept = VerdictAfterPolish(online, polished);
  EXPECT_FALSE(kept.converged);
  EXPECT_EQ(kept.reason, online.reason);
}

// A verdict whose refinement's covariance gives every rotation axis `rotation_std_rad`, every
// translation axis `translation_std_m` and δ 0.4 ms, all observable, and whose polish measured
// the pair (δ, forward translation) along `forward_camera` with these stds.
ConvergenceVerdict VerdictWithCovariance(double rotation_std_rad, double translation_std_m,
                                         const Eigen::Vector3d& forward_camera,
                                         double forward_std_m, double time_offset_std_s) {
  ConvergenceVerdict verdict;
  RefineResult& refine = verdict.refine;
  refine.covariance_ok = true;
  for (int k = 0; k < kNumAxes; ++k) {
    refine.std_dev[k] = k < 3 ? rotation_std_rad : k < 6 ? translation_std_m : 0.0004;
    refine.observable[k] = true;
  }
  TimeForwardPair& pair = verdict.time_forward;
  pair.measured = true;
  pair.forward_camera = forward_camera;
  pair.forward_std_m = forward_std_m;
  pair.time_offset_std_s = time_offset_std_s;
  return verdict;
}

// Each sweep enters the local maps of `shared_sweep_frames` frames, so the refinement counts its
// points that many times: the reported covariance stds grow by √ of it (here 4: twice); the
// polish's pair (δ, forward translation) and the rotation jackknife's floor stand as measured.
TEST(Convergence, ReportedStdCountsEachSweepOnce) {
  ConvergenceVerdict verdict =
      VerdictWithCovariance(0.03, 0.01, Eigen::Vector3d::UnitZ(), 0.02, 0.005);
  const ReportedUncertainty once = ReportUncertainty(verdict, true, 0.04);
  verdict.shared_sweep_frames = 4;
  const ReportedUncertainty four = ReportUncertainty(verdict, true, 0.04);
  for (int k = 0; k < 5; ++k) {  // camera z is along travel (the pair's), δ the pair's
    ASSERT_TRUE(once.has_std[k] && four.has_std[k]) << kAxisNames[k];
    EXPECT_NEAR(four.std_dev[k], 2 * once.std_dev[k], 1e-12) << kAxisNames[k];
  }
  // Along travel: the across part doubled, the pair's forward std as it was.
  EXPECT_NEAR(four.std_dev[5], std::sqrt(0.02 * 0.02 + 0.02 * 0.02), 1e-12);
  EXPECT_NEAR(four.std_dev[6], 0.005, 1e-12);
  verdict.rotation_jackknife.frames = 12;
  verdict.rotation_jackknife.std[0] = 0.5;
  const ReportedUncertainty floored = ReportUncertainty(verdict, true, 0.04);
  EXPECT_DOUBLE_EQ(floored.std_dev[0], 0.5);
  EXPECT_DOUBLE_EQ(floored.std_dev[1], four.std_dev[1]);
}

// The reported std and observability along the direction of travel come from the polish's solve
// with δ and the forward translation both free, not from the tracking refinement that holds the
// forward translation with its prior (KITTI: 1 mm there against 4-7 cm with both free).
TEST(Convergence, ReportedUncertaintyAlongTravelIsThePolishsWithBothFree) {
  // Camera: z forward.
  ConvergenceVerdict verdict =
      VerdictWithCovariance(0.03, 0.001, Eigen::Vector3d(0.0, 0.1, 1.0).normalized(), 0.06, 0.006);
  RefineResult& refine = verdict.refine;
  TimeForwardPair& pair = verdict.time_forward;
  const double share_y = pair.forward_camera.y() * pair.forward_camera.y();
  const double share_z = pair.forward_camera.z() * pair.forward_camera.z();

  // Not separated: δ and z rest on the forward translation's prior.
  ReportedUncertainty held = ReportUncertainty(verdict, true, 0.04);
  EXPECT_NEAR(held.std_dev[5], std::sqrt(1e-6 + share_z * 0.06 * 0.06), 1e-12);
  EXPECT_GT(held.std_dev[5], 0.059);
  EXPECT_FALSE(held.observable[5]);
  EXPECT_NEAR(held.std_dev[4], std::sqrt(1e-6 + share_y * 0.06 * 0.06), 1e-12);
  EXPECT_TRUE(held.observable[4]);  // across the direction of travel: the verdict's
  EXPECT_DOUBLE_EQ(held.std_dev[3], 0.001);
  EXPECT_TRUE(held.observable[3]);
  EXPECT_DOUBLE_EQ(held.std_dev[6], 0.006);
  EXPECT_FALSE(held.observable[6]);  // verdict.time_offset_observable
  for (int k = 0; k < 3; ++k) {
    EXPECT_DOUBLE_EQ(held.std_dev[k], 0.03);
    EXPECT_TRUE(held.observable[k]);
  }
  for (int k = 0; k < kNumAxes; ++k) EXPECT_TRUE(held.has_std[k]) << k;

  // Separated, with a forward std under the threshold: z observable, at that std.
  pair.separated = true;
  pair.forward_std_m = 0.02;
  verdict.time_offset_observable = true;
  const ReportedUncertainty separated = ReportUncertainty(verdict, true, 0.04);
  EXPECT_NEAR(separated.std_dev[5], std::sqrt(1e-6 + share_z * 0.02 * 0.02), 1e-12);
  EXPECT_TRUE(separated.observable[5]);
  EXPECT_TRUE(separated.observable[6]);
  // Separated but wider than the threshold: not observable either.
  pair.forward_std_m = 0.05;
  EXPECT_FALSE(ReportUncertainty(verdict, true, 0.04).observable[5]);
  // A diagonal direction of travel (no axis over half of it): the axis it lies most along.
  pair.forward_camera = Eigen::Vector3d(0.6, 0.0, 0.8);
  pair.forward_std_m = 0.06;
  pair.separated = false;
  const ReportedUncertainty diagonal = ReportUncertainty(verdict, true, 0.04);
  EXPECT_FALSE(diagonal.observable[5]);
  EXPECT_TRUE(diagonal.observable[3]);  // x: the verdict's, its std grown by 0.36 of the forward
  EXPECT_NEAR(diagonal.std_dev[3], std::sqrt(1e-6 + 0.36 * 0.06 * 0.06), 1e-12);

  // No polish measured the pair: no std along travel to give, and nothing observable there.
  pair = TimeForwardPair();
  verdict.time_offset_observable = false;
  refine.forward_camera = Eigen::Vector3d::UnitZ();
  const ReportedUncertainty unmeasured = ReportUncertainty(verdict, true, 0.04);
  EXPECT_FALSE(unmeasured.has_std[5]);
  EXPECT_FALSE(unmeasured.observable[5]);
  EXPECT_FALSE(unmeasured.has_std[6]);
  EXPECT_TRUE(unmeasured.has_std[4]);
  EXPECT_DOUBLE_EQ(unmeasured.std_dev[4], 0.001);

  // δ not estimated: the refinement's own numbers throughout.
  const ReportedUncertainty fixed_time = ReportUncertainty(verdict, false, 0.04);
  EXPECT_DOUBLE_EQ(fixed_time.std_dev[5], 0.001);
  EXPECT_TRUE(fixed_time.observable[5]);
}

// The translation may end at most max_sigmas of its prior's sigma from the start on each axis:
// the axis furthest beyond that limit is named with its signed move; within it, or with the
// limit off, none is. Options with a negative or NaN limit are refused.
TEST(Convergence, TranslationMovedBeyondItsPriorIsNamed) {
  CalibrationState start;
  start.T_camera_lidar.translation() = Eigen::Vector3d(-0.004, -0.076, -0.272);
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  // The KITTI wrong-δ run's move: 12.4 cm on x, 1.6 cm on y, against 2 x 5 cm.
  const CalibrationState sideways = Step(start, zero, Eigen::Vector3d(-0.124, 0.016, 0.001), 0);
  TranslationMove moved = TranslationMoveBeyondPrior(start, sideways, 2.0, 0.05);
  EXPECT_EQ(moved.axis, 0);
  EXPECT_NEAR(moved.move_m, -0.124, 1e-12);
  // Two axes beyond the limit: the larger move is named.
  const CalibrationState two = Step(start, zero, Eigen::Vector3d(0.11, 0.0, -0.13), 0);
  moved = TranslationMoveBeyondPrior(start, two, 2.0, 0.05);
  EXPECT_EQ(moved.axis, 2);
  EXPECT_NEAR(moved.move_m, -0.13, 1e-12);
  // The largest good simulated run's move (7.8 cm on y) is within the limit; so is 9.9 cm.
  EXPECT_EQ(TranslationMoveBeyondPrior(start, Step(start, zero, Eigen::Vector3d(0, 0.078, 0), 0),
                                       2.0, 0.05)
                .axis,
            -1);
  EXPECT_EQ(TranslationMoveBeyondPrior(start, Step(start, zero, Eigen::Vector3d(0.099, 0, 0), 0),
                                       2.0, 0.05)
                .axis,
            -1);
  // A wider prior, or the limit off, accepts the sideways move; rotation and δ do not count.
  EXPECT_EQ(TranslationMoveBeyondPrior(start, sideways, 2.0, 0.1).axis, -1);
  EXPECT_EQ(TranslationMoveBeyondPrior(start, sideways, 0.0, 0.05).axis, -1);
  const CalibrationState turned = Step(start, Eigen::Vector3d(0.05, -0.05, 0.05), zero, 0.1);
  EXPECT_EQ(TranslationMoveBeyondPrior(start, turned, 2.0, 0.05).axis, -1);

  ConvergenceOptions options;
  EXPECT_TRUE(options.Validate().ok());
  options.max_translation_move_sigmas = -1;
  EXPECT_FALSE(options.Validate().ok());
  EXPECT_NE(options.Validate().message().find("max_translation_move_sigmas"), std::string::npos);
  options.max_translation_move_sigmas = std::nan("");
  EXPECT_FALSE(options.Validate().ok());
  options.max_translation_move_sigmas = 0;
  EXPECT_TRUE(options.Validate().ok());
  options.min_final_health = 1.5;
  EXPECT_FALSE(options.Validate().ok());
}

// The translation axes across travel report at least the refinements' spread about the
// estimate, and are not observable once it reaches the threshold; the axis along travel keeps
// the polish's numbers; without updates the covariance stands.
TEST(Convergence, ReportedTranslationStdIsAtLeastTheRefinementsSpread) {
  ConvergenceVerdict verdict =
      VerdictWithCovariance(0.03, 0.008, Eigen::Vector3d::UnitZ(), 0.02, 0.002);
  TimeForwardPair& pair = verdict.time_forward;
  pair.separated = true;
  verdict.time_offset_observable = true;
  const ReportedUncertainty plain = ReportUncertainty(verdict, true, 0.04);
  EXPECT_DOUBLE_EQ(plain.std_dev[3], 0.008);
  EXPECT_TRUE(plain.observable[4]);

  // KITTI from ±5 cm, seed 2: the windows' optima 4.2 and 5.6 cm about the estimate.
  verdict.refinement_spread_m = Eigen::Vector3d(0.042, 0.056, 0.003);
  verdict.refinement_spread_updates = 10;
  const ReportedUncertainty wide = ReportUncertainty(verdict, true, 0.04);
  EXPECT_DOUBLE_EQ(wide.std_dev[3], 0.042);
  EXPECT_DOUBLE_EQ(wide.std_dev[4], 0.056);
  EXPECT_FALSE(wide.observable[3]);
  EXPECT_FALSE(wide.observable[4]);
  EXPECT_NEAR(wide.std_dev[5], std::sqrt(0.008 * 0.008 + 0.02 * 0.02), 1e-12);  // along travel
  EXPECT_TRUE(wide.observable[5]);
  // A spread under the covariance's std changes nothing; one under the threshold keeps the axis.
  verdict.refinement_spread_m = Eigen::Vector3d(0.005, 0.025, 0.0);
  const ReportedUncertainty narrow = ReportUncertainty(verdict, true, 0.04);
  EXPECT_DOUBLE_EQ(narrow.std_dev[3], 0.008);
  EXPECT_DOUBLE_EQ(narrow.std_dev[4], 0.025);
  EXPECT_TRUE(narrow.observable[4]);
  // δ not estimated: every translation axis, the one along travel too.
  verdict.refinement_spread_m = Eigen::Vector3d(0.0, 0.0, 0.05);
  const ReportedUncertainty fixed_time = ReportUncertainty(verdict, false, 0.04);
  EXPECT_DOUBLE_EQ(fixed_time.std_dev[5], 0.05);
  EXPECT_FALSE(fixed_time.observable[5]);
  EXPECT_TRUE(fixed_time.observable[3]);
  // No pair measured: the axes across travel still widen.
  pair = TimeForwardPair();
  verdict.refinement_spread_m = Eigen::Vector3d(0.06, 0.0, 0.0);
  EXPECT_FALSE(ReportUncertainty(verdict, true, 0.04).observable[3]);
}

TEST(Convergence, SuppressedCheckRefusesAKittiFalseOptimumThePlainMapsLike) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  // Plain score maps (what configs/kitti.flags calibrated on until it switched to suppressed
  // ones; any drive may still be calibrated on them).
  FrameSourceOptions options;
  options.suppress_texture = false;
  const std::vector<std::shared_ptr<const CalibrationFrame>> plain =
      testing::LoadCalibrationFrames(drive, options, {21, 22, 23, 24, 25, 26, 27, 28, 29});
  ASSERT_EQ(plain.size(), 9u);
  std::vector<std::shared_ptr<const CalibrationFrame>> suppressed;
  for (const auto& frame : plain) {
    suppressed.push_back(WithSuppressedScoreMaps(*frame));
    ASSERT_EQ(suppressed.back()->score_maps[0].size(), 1u);
    ASSERT_EQ(suppressed.back()->size(), frame->size());
  }
  CalibrationState kitti;
  kitti.T_camera_lidar = drive.T_camera_lidar;
  // Where `stcalib calibrate --flagfile=configs/kitti.flags --suppress_texture=false
  // --perturb_rot_deg=2 --perturb_trans_m=0.05 --seed=4` ended before this check existed, and
  // claimed convergence: 3.0° from KITTI's calibration.
  const CalibrationState wrong = Step(kitti, Eigen::Vector3d(-2.40, -1.76, -0.30) * M_PI / 180.0,
                                      Eigen::Vector3d(0.05, -0.10, 0.10), 0.0);
  const HealthCheckOptions check;
  // The health the plain maps give, over the check's windows of 3 frames.
  double plain_wrong_health = 0;
  int windows = 0;
  for (size_t begin = 0; begin + check.window_frames <= plain.size();
       begin += check.window_frames) {
    std::vector<std::shared_ptr<const CalibrationFrame>> pruned;
    std::vector<const CalibrationFrame*> view;
    for (size_t k = begin; k < begin + check.window_frames; ++k) {
      pruned.push_back(PruneToImage(*plain[k], wrong, check.point_margin));
      view.push_back(pruned.back().get());
    }
    WindowScorer scorer(view, check.score);
    plain_wrong_health +=
        HealthScore(&scorer, wrong, check.rotation_step_deg, check.translation_step_m);
    ++windows;
  }
  plain_wrong_health /= windows;
  // The check scores the suppressed maps whatever maps its frames carry.
  const HealthCheckResult good = CheckCalibrationHealth(plain, kitti, check);
  const HealthCheckResult good_view = CheckCalibrationHealth(suppressed, kitti, check);
  const HealthCheckResult bad = CheckCalibrationHealth(plain, wrong, check);
  std::printf(
      "plain maps at the 3 deg estimate: health %.3f\nsuppressed, KITTI: %s\nsuppressed, 3 deg: "
      "%s\n",
      plain_wrong_health, good.reason.c_str(), bad.reason.c_str());
  ASSERT_TRUE(good.decided);
  ASSERT_TRUE(bad.decided);
  EXPECT_EQ(good.mean_health, good_view.mean_health);
  EXPECT_TRUE(good.holds);
  EXPECT_FALSE(bad.holds);
  EXPECT_GT(good.mean_health, bad.mean_health + 0.1);
  // The plain maps do not tell: the rule "final health ≥ 0.8" passed this estimate.
  EXPECT_GE(plain_wrong_health, 0.8);
}

// The texture trap of docs/method.md §10 and its cure: on the shared KITTI frames the clipped
// texture-suppressed score still rises for degrees away from KITTI's calibration (moving points
// into foliage pays), the band-pass score peaks at the calibration on every rotation axis.
TEST(Score, KittiBandPassPeaksAtTheCalibrationTheClippedMapDoesNot) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  FrameSourceOptions options;
  options.suppress_texture = true;
  options.bandpass_score = true;
  CalibrationState kitti;
  kitti.T_camera_lidar = drive.T_camera_lidar;
  std::vector<int> every_second;
  for (size_t i = 0; i < drive.NumFrames(); i += 2) every_second.push_back(static_cast<int>(i));
  std::vector<std::shared_ptr<const CalibrationFrame>> bandpass, clipped;
  for (const auto& frame : testing::LoadCalibrationFrames(drive, options, every_second)) {
    // Points a little outside the image too: a band-pass map is near zero there on average.
    bandpass.push_back(PruneToImage(*frame, kitti, -0.1));
    clipped.push_back(WithSuppressedScoreMaps(*bandpass.back()));
  }
  auto view = [](const std::vector<std::shared_ptr<const CalibrationFrame>>& frames) {
    std::vector<const CalibrationFrame*> v;
    for (const auto& f : frames) v.push_back(f.get());
    return v;
  };
  WindowScorer bandpass_scorer(view(bandpass), ScoreOptions());
  WindowScorer clipped_scorer(view(clipped), ScoreOptions());
  double worst_clipped = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const RotationAxisProfile b = ProfileRotationAxis(&bandpass_scorer, kitti, axis, 4.0, 0.25);
    const RotationAxisProfile c = ProfileRotationAxis(&clipped_scorer, kitti, axis, 4.0, 0.25);
    std::printf("%s: band-pass peak %+.2f deg (second %.2f), clipped peak %+.2f deg\n",
                kAxisNames[axis], b.best_deg, b.second_peak_ratio, c.best_deg);
    EXPECT_LE(std::abs(b.best_deg), 0.5) << kAxisNames[axis];
    worst_clipped = std::max(worst_clipped, std::abs(c.best_deg));
  }
  EXPECT_GE(worst_clipped, 2.0);
}

}  // namespace
}  // namespace stcalib

namespace stcalib {
namespace {

// The rotation's block jackknife on KITTI frames 21-29 at KITTI's calibration: three blocks of
// three frames, a spread of a few hundredths to tenths of a degree; the same frame repeated
// leaves nothing to spread (every block left out keeps the same data); too few frames for two
// blocks measure nothing.
TEST(Convergence, RotationJackknifeOverBlocksOfFrames) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  const std::vector<std::shared_ptr<const CalibrationFrame>> loaded =
      testing::LoadCalibrationFrames(drive, FrameSourceOptions(),
                                     {21, 22, 23, 24, 25, 26, 27, 28, 29});
  ASSERT_EQ(loaded.size(), 9u);
  std::vector<const CalibrationFrame*> frames;
  for (const auto& frame : loaded) frames.push_back(frame.get());
  CalibrationState kitti;
  kitti.T_camera_lidar = drive.T_camera_lidar;
  RefineOptions options;
  options.loss = RefineOptions::Loss::kTukey;
  options.loss_scale_px = 5.0;
  const RefineJackknife spread = JackknifeRotation(frames, kitti, kitti, options, 3);
  EXPECT_EQ(spread.frames, 9);
  EXPECT_EQ(spread.blocks, 3);
  EXPECT_EQ(spread.failed, 0);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_GT(spread.std[axis], 1e-4) << axis;
    EXPECT_LT(spread.std[axis], 0.5) << axis;
  }
  const std::vector<const CalibrationFrame*> same(6, frames[4]);
  const RefineJackknife none = JackknifeRotation(same, kitti, kitti, options, 3);
  EXPECT_EQ(none.blocks, 2);
  EXPECT_LT(none.std.head<3>().norm(), 1e-6);
  EXPECT_EQ(JackknifeRotation({frames[0], frames[1], frames[2]}, kitti, kitti, options, 3).frames,
            0);
}

}  // namespace
}  // namespace stcalib
