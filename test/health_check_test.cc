// Health check (docs/method.md §7): KITTI's own calibration holds; 0.5° and 1° off are told apart.
#include "core/online/health_check.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "core/online/frame_source.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

std::vector<std::shared_ptr<const CalibrationFrame>> LoadKittiFrames(const Drive& drive, int n) {
  FrameSourceOptions options;
  options.suppress_texture = true;
  std::vector<int> indices(n);
  for (int i = 0; i < n; ++i) indices[i] = i;
  return testing::LoadCalibrationFrames(drive, options, indices);
}

// A rotation of `deg` about a random axis (the seed picks it).
CalibrationState RotatedBy(const CalibrationState& state, double deg, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  const Eigen::Vector3d axis(normal(rng), normal(rng), normal(rng));
  return Step(state, axis.normalized() * deg * M_PI / 180.0, Eigen::Vector3d::Zero(), 0.0);
}

TEST(HealthCheck, KittiCalibrationHoldsAndOneDegreeOffIsCaught) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  const auto frames = LoadKittiFrames(drive, static_cast<int>(drive.NumFrames()));
  CalibrationState kitti;
  kitti.T_camera_lidar = drive.T_camera_lidar;
  const HealthCheckOptions options;
  const HealthCheckResult good = CheckCalibrationHealth(frames, kitti, options);
  std::printf("KITTI calibration: %s\n", good.reason.c_str());
  ASSERT_TRUE(good.decided);
  EXPECT_TRUE(good.holds);
  EXPECT_GE(good.mean_health, 0.9);
  EXPECT_LT(good.mean_neighbour_gain, options.max_neighbour_gain);
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const HealthCheckResult half =
        CheckCalibrationHealth(frames, RotatedBy(kitti, 0.5, seed), options);
    const HealthCheckResult off =
        CheckCalibrationHealth(frames, RotatedBy(kitti, 1.0, seed), options);
    std::printf(
        "axis seed %u: health / best neighbour: 0.5 deg off %.3f / %+.3f, 1 deg off %.3f / %+.3f\n",
        seed, half.mean_health, half.mean_neighbour_gain, off.mean_health, off.mean_neighbour_gain);
    ASSERT_TRUE(off.decided);
    EXPECT_FALSE(off.holds) << off.reason;
    EXPECT_LT(off.mean_health, good.mean_health);
    EXPECT_GT(off.mean_neighbour_gain, 1.5 * good.mean_neighbour_gain);
    EXPECT_LT(half.mean_health, good.mean_health);
  }
}

TEST(HealthCheck, NoEdgesGivesNoVerdict) {
  auto frame = std::make_shared<CalibrationFrame>();
  frame->camera.width = 100;
  frame->camera.height = 50;
  const HealthCheckResult r =
      CheckCalibrationHealth({frame, frame, frame}, CalibrationState(), HealthCheckOptions());
  EXPECT_FALSE(r.decided);
  EXPECT_FALSE(r.holds);
  EXPECT_NE(r.reason.find("no verdict"), std::string::npos) << r.reason;
  ASSERT_EQ(r.windows.size(), 1u);
  EXPECT_NE(r.windows[0].note.find("too few LiDAR edge points"), std::string::npos);
}

}  // namespace
}  // namespace stcalib
