// Several cameras around one LiDAR (docs/method.md §7, "Several cameras"): the shared LiDAR pass,
// the azimuth window over several views, and the camera-to-camera check.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/io/drive.h"
#include "core/io/kitti_calib.h"
#include "core/online/frame_source.h"
#include "core/online/rig_check.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

TEST(AzimuthWindowUnion, HoldsEveryWindowAndNoMore) {
  // One window is itself.
  EXPECT_EQ(AzimuthWindowUnionDeg({Eigen::Vector2d(10, 40)}), Eigen::Vector2d(10, 40));
  // Two overlapping ones: [−30, 50] and [20, 80] → centre 25, half 55.
  const Eigen::Vector2d both = AzimuthWindowUnionDeg({{10, 40}, {50, 30}});
  EXPECT_NEAR(both.x(), 25, 0.5);
  EXPECT_NEAR(both.y(), 55, 0.5);
  // Across ±180°: [150, 210] and [−170, −110] → [150, 250], centre −160, half 50.
  const Eigen::Vector2d wrapped = AzimuthWindowUnionDeg({{180, 30}, {-140, 30}});
  EXPECT_NEAR(std::remainder(wrapped.x() - (-160), 360), 0, 0.5);
  EXPECT_NEAR(wrapped.y(), 50, 0.5);
  // Far apart ones span the gap between them the short way round: [−20, 20] and [70, 110].
  const Eigen::Vector2d apart = AzimuthWindowUnionDeg({{0, 20}, {90, 20}});
  EXPECT_NEAR(apart.x(), 45, 0.5);
  EXPECT_NEAR(apart.y(), 65, 0.5);
  // A whole sweep, or windows that leave no gap, are the whole sweep.
  EXPECT_EQ(AzimuthWindowUnionDeg({{0, 20}, {0, 0}}).y(), 0);
  EXPECT_EQ(AzimuthWindowUnionDeg({{0, 100}, {180, 100}}).y(), 0);
}

// KITTI's image_02 and image_03: one calibration file, two projections; the rig's transform
// between their rectified frames is the 0.54 m baseline, parallel.
TEST(RigCheck, KittiColourCamerasAreTheBaselineApart) {
  STCALIB_REQUIRE_KITTI_STEREO();
  Drive left, right;
  ASSERT_TRUE(OpenDrive(testing::KittiStereoDriveDir(), "", &left, "image_02").ok());
  const Status open = OpenDrive(testing::KittiStereoDriveDir(), "", &right, "image_03");
  ASSERT_TRUE(open.ok()) << open.message();
  Eigen::MatrixXd P3;
  ASSERT_TRUE(right.camera.file.GetMatrix("P_rect_03", 3, 4, &P3).ok());
  EXPECT_EQ((right.camera.P_rect - P3).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(right.camera.image_width, 1226);
  // KITTI's cameras all project from camera 0's frame: one extrinsic.
  EXPECT_TRUE(right.T_camera_lidar.isApprox(left.T_camera_lidar, 1e-12));
  EXPECT_EQ(right.ImagePath(4), testing::KittiStereoDriveDir() + "/image_03/data/0000000004.png");

  RigCamera a, b;
  a.name = "image_02";
  b.name = "image_03";
  a.claimed = b.claimed = true;
  a.T_camera_lidar = left.T_camera_lidar;
  b.T_camera_lidar = right.T_camera_lidar;
  a.T_rectified_camera = RectifiedFromCamera(left.camera);
  b.T_rectified_camera = RectifiedFromCamera(right.camera);
  a.has_std.fill(true);
  b.has_std.fill(true);
  a.std_dev.fill(0.1);
  b.std_dev.fill(0.2);
  CameraPairCheck pair = CompareCameraPair(a, b);
  ASSERT_TRUE(pair.compared);
  // P_rect_02 and P_rect_03 of 2011_09_30 put the cameras 0.532 m apart along x.
  const Eigen::Vector3d t_rig = pair.T_to_from_rig.translation();
  EXPECT_NEAR(t_rig.x(), -0.532, 0.005);
  EXPECT_NEAR(t_rig.norm(), 0.532, 0.005);
  EXPECT_LT(RotationErrorDeg(pair.T_to_from_rig.linear(), Eigen::Matrix3d::Identity()), 1e-9);
  EXPECT_NEAR(pair.rotation_deg, 0, 1e-9);
  EXPECT_NEAR(pair.translation_m, 0, 1e-12);
  EXPECT_NEAR(pair.rotation_std_deg, std::sqrt(3 * (0.01 + 0.04)), 1e-12);
  // image_03's estimate 0.2° off in yaw and 3 cm off along x: the pair says so.
  b.T_camera_lidar = PerturbTcameraLidar(right.T_camera_lidar, Eigen::Vector3d(0, 0, 0.2),
                                         Eigen::Vector3d(0.03, 0, 0));
  pair = CompareCameraPair(a, b);
  EXPECT_NEAR(pair.rotation_deg, 0.2, 1e-6);
  EXPECT_NEAR(pair.translation_m, 0.03, 0.003);
  EXPECT_TRUE(pair.consistent);
  // 1.5° off with estimates that claim 0.05° each: one of them is wrong.
  a.std_dev.fill(0.05);
  b.std_dev.fill(0.05);
  b.T_camera_lidar = PerturbTcameraLidar(right.T_camera_lidar, Eigen::Vector3d(0, 1.5, 0),
                                         Eigen::Vector3d::Zero());
  pair = CompareCameraPair(a, b);
  EXPECT_NEAR(pair.rotation_deg, 1.5, 1e-6);
  EXPECT_FALSE(pair.consistent);
  // Not both claimed: nothing compared.
  b.claimed = false;
  EXPECT_FALSE(CompareCameraPair(a, b).compared);
}

// One LiDAR pass for two cameras: each camera's frame carries the same local map and its own
// image, stamps and motion; the first camera's is what a single-camera load gives.
TEST(DriveFrameSource, TwoCamerasShareOneLidarPass) {
  STCALIB_REQUIRE_KITTI_STEREO();
  Drive left, right;
  ASSERT_TRUE(OpenDrive(testing::KittiStereoDriveDir(), "", &left, "image_02").ok());
  ASSERT_TRUE(OpenDrive(testing::KittiStereoDriveDir(), "", &right, "image_03").ok());
  std::unique_ptr<DriveFrameSource> both, single;
  ASSERT_TRUE(DriveFrameSource::Create({&left, &right}, FrameSourceOptions(), &both).ok());
  ASSERT_TRUE(DriveFrameSource::Create(&left, FrameSourceOptions(), &single).ok());
  for (size_t frame : {0u, 1u, 2u}) {
    std::vector<CameraFrameLoad> loads;
    both->LoadCameras(frame, &loads);
    ASSERT_EQ(loads.size(), 2u);
    for (const CameraFrameLoad& load : loads)
      ASSERT_TRUE(load.status.ok()) << load.status.message();
    CalibrationFrame alone;
    ASSERT_TRUE(single->Load(frame, &alone).ok());
    const CalibrationFrame& f2 = *loads[0].frame;
    const CalibrationFrame& f3 = *loads[1].frame;
    EXPECT_GT(f2.size(), 1000u);
    EXPECT_EQ(f2.points_lidar, alone.points_lidar);
    EXPECT_EQ(f3.points_lidar, alone.points_lidar);
    EXPECT_EQ(f2.e0_s, alone.e0_s);
    EXPECT_EQ(cv::norm(f2.score_maps[0].back(), alone.score_maps[0].back(), cv::NORM_INF), 0.0);
    // image_03 is its own image: its size and its projection.
    EXPECT_EQ(f3.camera.width, 1226);
    EXPECT_TRUE(f3.camera.P_rect == right.camera.P_rect);
    EXPECT_GT(cv::norm(f3.score_maps[0].back()(cv::Rect(0, 0, 1000, 300)),
                       f2.score_maps[0].back()(cv::Rect(0, 0, 1000, 300)), cv::NORM_L1),
              0.0);
  }
}

// A frame of image_03 moved into a rig frame turned and shifted from its own projects a point of
// the rig frame exactly where the camera's own model projects the point moved into its frame.
TEST(RigCheck, InRigFrameProjectsThroughTheRigTransform) {
  CalibrationFrame frame;
  frame.camera.P_rect << 700, 0, 600, -330, 0, 700, 180, 2, 0, 0, 1, 0.003;
  frame.camera.R_rect_00 = ExpSO3(Eigen::Vector3d(0.01, -0.02, 0.005));
  frame.camera.width = 1226;
  frame.camera.height = 370;
  frame.e0_s = 0.01;
  const Rigid3d T_camera_rig =
      MakeRigid(ExpSO3(Eigen::Vector3d(0.1, 1.4, -0.05)), Eigen::Vector3d(0.3, -0.1, 0.8));
  const CalibrationFrame moved = InRigFrame(frame, T_camera_rig, 0.02);
  EXPECT_DOUBLE_EQ(moved.e0_s, 0.03);
  int projected = 0;
  for (const Eigen::Vector3d& p_rig :
       {Eigen::Vector3d(8, 1, 3), Eigen::Vector3d(-2, 0.5, 12), Eigen::Vector3d(5, -1, -4)}) {
    Eigen::Vector2d own, rig;
    double depth_own, depth_rig;
    const bool in_own = frame.camera.Project(T_camera_rig * p_rig, &own, &depth_own);
    const bool in_rig = moved.camera.Project(p_rig, &rig, &depth_rig);
    ASSERT_EQ(in_own, in_rig);
    if (!in_own) continue;
    ++projected;
    EXPECT_LT((own - rig).norm(), 1e-9);
  }
  EXPECT_GE(projected, 1);
}

// A camera whose drive is not the first's (other frames) is refused by name.
TEST(DriveFrameSource, RefusesCamerasOfAnotherDrive) {
  STCALIB_REQUIRE_KITTI_STEREO();
  STCALIB_REQUIRE_KITTI();
  Drive left, other;
  ASSERT_TRUE(OpenDrive(testing::KittiStereoDriveDir(), "", &left, "image_02").ok());
  ASSERT_TRUE(OpenDrive(testing::KittiDriveDir(), "", &other, "image_02").ok());
  std::unique_ptr<DriveFrameSource> source;
  const Status status = DriveFrameSource::Create({&left, &other}, FrameSourceOptions(), &source);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::HasSubstr("camera image_02"));
  EXPECT_THAT(status.message(), ::testing::HasSubstr("one drive"));
}

}  // namespace
}  // namespace stcalib
