// The calibration check (docs/method.md §7, "Checking a calibration"): KITTI's own calibration
// holds on the shared frames, 1° off is off, and too little evidence cannot tell.
#include "core/online/calibration_check.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "core/online/frame_source.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

std::vector<std::shared_ptr<const CalibrationFrame>> LoadKittiFrames(const Drive& drive,
                                                                     int first, int n) {
  FrameSourceOptions options;
  options.local_map.sweeps = kCheckLocalMapSweeps;  // as `stcalib check` reads them
  std::vector<int> indices(n);
  for (int i = 0; i < n; ++i) indices[i] = first + i;
  return testing::LoadCalibrationFrames(drive, options, indices);
}

CalibrationState RotatedAbout(const CalibrationState& state, const Eigen::Vector3d& axis,
                              double deg) {
  CalibrationState rotated = state;
  rotated.T_camera_lidar =
      PerturbTcameraLidar(state.T_camera_lidar, axis.normalized() * deg, Eigen::Vector3d::Zero());
  return rotated;
}

TEST(CalibrationCheck, KittiCalibrationHoldsAndOneDegreeOffIsOff) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  const auto frames = LoadKittiFrames(drive, 0, static_cast<int>(drive.NumFrames()));
  CalibrationState kitti;
  kitti.T_camera_lidar = drive.T_camera_lidar;
  const CalibrationCheckOptions options;
  const CalibrationCheckResult good = CheckCalibration(frames, kitti, options);
  std::printf("KITTI calibration: %s\n", good.reason.c_str());
  EXPECT_EQ(good.answer, CheckAnswer::kHolds) << good.reason;
  EXPECT_EQ(good.blocks, static_cast<int>(frames.size()));  // single sweeps: blocks of one frame
  EXPECT_NEAR(good.t_quantile, StudentT99(good.blocks - 1), 1e-12);
  EXPECT_LT(good.rotation_offset_deg, 0.5);
  for (int axis = 0; axis < 3; ++axis) EXPECT_TRUE(good.axes[axis].resolved) << axis;
  // 1° about diagonal axes (as `check --perturb_rot_deg=0.577` moves it): off, and the optimum
  // found lies nearer KITTI's calibration than the moved one. (The refinement is local: from 1°
  // off it comes back part of the way, docs/results.md#check.)
  for (const Eigen::Vector3d& axis : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, 1),
                                      Eigen::Vector3d(-1, 1, 1), Eigen::Vector3d(1, 1, -1)}) {
    const CalibrationState moved = RotatedAbout(kitti, axis, 1.0);
    const CalibrationCheckResult off = CheckCalibration(frames, moved, options);
    std::printf("1 deg about (%g, %g, %g): %s\n", axis.x(), axis.y(), axis.z(),
                off.reason.c_str());
    EXPECT_EQ(off.answer, CheckAnswer::kOff) << off.reason;
    EXPECT_GT(off.rotation_offset_deg, 0.5);
    EXPECT_LT(ComputeCalibrationError(off.optimum, kitti).rotation_deg, 0.8);
  }
}

TEST(CalibrationCheck, TooFewFramesCannotTell) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  CalibrationState kitti;
  kitti.T_camera_lidar = drive.T_camera_lidar;
  const CalibrationCheckResult two =
      CheckCalibration(LoadKittiFrames(drive, 0, 2), kitti, CalibrationCheckOptions());
  EXPECT_EQ(two.answer, CheckAnswer::kCannotTell);
  EXPECT_EQ(two.blocks, 2);
  EXPECT_NE(two.reason.find("at least 3 needed"), std::string::npos) << two.reason;
}

TEST(CalibrationCheck, NoEdgesCannotTell) {
  auto frame = std::make_shared<CalibrationFrame>();
  frame->camera.width = 100;
  frame->camera.height = 50;
  const CalibrationCheckResult r =
      CheckCalibration({frame, frame, frame, frame}, CalibrationState(), CalibrationCheckOptions());
  EXPECT_EQ(r.answer, CheckAnswer::kCannotTell);
  EXPECT_EQ(r.frames_used, 0);
  EXPECT_NE(r.reason.find("0 of 4 frames"), std::string::npos) << r.reason;
}

// Student's t: the tabulated one-sided 99 % quantiles, and the normal's 2.326 in the limit.
TEST(CalibrationCheck, StudentQuantiles) {
  EXPECT_NEAR(StudentT99(1), 31.821, 1e-9);
  EXPECT_NEAR(StudentT99(2), 6.965, 1e-9);
  EXPECT_NEAR(StudentT99(9), 2.821, 1e-9);
  EXPECT_NEAR(StudentT99(30), 2.457, 0.01);
  EXPECT_NEAR(StudentT99(40), 2.423, 0.01);
  EXPECT_NEAR(StudentT99(100000), 2.326, 0.001);
  for (int dof = 1; dof < 60; ++dof) EXPECT_GT(StudentT99(dof), StudentT99(dof + 1)) << dof;
}

}  // namespace
}  // namespace stcalib
