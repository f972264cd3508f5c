// Convergence verdict (core/online/convergence.h): a polish that does not converge refuses the
// claim; the independent check on texture-suppressed maps refuses a KITTI estimate 3° off that
// the plain maps' rules would have accepted.
#include "core/online/convergence.h"

#include <gtest/gtest.h>

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

// The texture trap of method.md §10 and its cure: on the shared KITTI frames the clipped
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
