#include "core/score/projection.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/io/drive.h"
#include "core/types/calibration.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

TEST(Projection, HandComputedPoint) {
  CameraModel camera;
  // R_rect_00: 90° about the camera z axis would be unusual; use a small known rotation instead:
  // identity here, so that the arithmetic below stays by hand.
  camera.P_rect << 700, 0, 600, 45, 0, 700, 170, 0.2, 0, 0, 1, 0.003;
  camera.width = 1242;
  camera.height = 375;
  // KITTI-like axes: camera x = −lidar y, camera y = −lidar z, camera z = lidar x.
  Eigen::Matrix3d R;
  R << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  const Rigid3d T_camera_lidar = MakeRigid(R, Eigen::Vector3d(0.1, -0.2, 0.0));
  // p_lidar (10, 1, -0.5) → p_camera (−1 + 0.1, 0.5 − 0.2, 10) = (−0.9, 0.3, 10)
  // h = (700·−0.9 + 600·10 + 45, 700·0.3 + 170·10 + 0.2, 10 + 0.003) = (5415, 1910.2, 10.003)
  const std::vector<ProjectedPoint> projected =
      ProjectPoints(camera, T_camera_lidar, {Eigen::Vector3d(10, 1, -0.5)});
  ASSERT_EQ(projected.size(), 1u);
  EXPECT_NEAR(projected[0].pixel.x(), 5415.0 / 10.003, 1e-9);
  EXPECT_NEAR(projected[0].pixel.y(), 1910.2 / 10.003, 1e-9);
  EXPECT_NEAR(projected[0].depth_m, 10.0, 1e-12);

  // Behind the camera, and outside the image: dropped.
  EXPECT_TRUE(ProjectPoints(camera, T_camera_lidar, {Eigen::Vector3d(-10, 1, -0.5)}).empty());
  EXPECT_TRUE(ProjectPoints(camera, T_camera_lidar, {Eigen::Vector3d(2, 30, 0)}).empty());
}

TEST(Projection, RectificationRotationIsApplied) {
  CameraModel camera;
  camera.P_rect << 100, 0, 50, 0, 0, 100, 50, 0, 0, 0, 1, 0;
  camera.width = 100;
  camera.height = 100;
  camera.R_rect_00 = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()).toRotationMatrix();
  Eigen::Vector2d pixel;
  double depth = 0;
  ASSERT_TRUE(camera.Project(Eigen::Vector3d(0, 0, 10), &pixel, &depth));
  // R_y(0.1)·(0,0,10) = (10 sin 0.1, 0, 10 cos 0.1) → u = 50 + 100·tan(0.1).
  EXPECT_NEAR(pixel.x(), 50 + 100 * std::tan(0.1), 1e-9);
  EXPECT_NEAR(pixel.y(), 50, 1e-9);
  EXPECT_NEAR(depth, 10 * std::cos(0.1), 1e-12);
}

// With KITTI's calibration, LiDAR points in the camera's field of view land in the image; with a
// grossly wrong extrinsic they do not.
TEST(Projection, KittiFrameZeroLandsInsideTheImage) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  cv::Mat image;
  LidarScan scan;
  ASSERT_TRUE(drive.LoadImage(0, &image).ok());
  ASSERT_TRUE(drive.LoadScan(0, &scan).ok());
  const CameraModel camera = MakeCameraModel(drive.camera, image.cols, image.rows);
  // In front: 5 m or more ahead, within ±35° of azimuth and −12°..+2° of elevation (inside the
  // camera's ±40° × −15°..+13° field of view, with margin).
  std::vector<Eigen::Vector3d> in_front;
  for (const auto& p : scan.points_lidar) {
    const double azimuth = std::atan2(p.y(), p.x()) * 180 / M_PI;
    const double elevation = std::atan2(p.z(), p.head<2>().norm()) * 180 / M_PI;
    if (p.x() > 5 && std::abs(azimuth) < 35 && elevation > -12 && elevation < 2) {
      in_front.push_back(p);
    }
  }
  ASSERT_GT(in_front.size(), 5000u);
  const double inside =
      static_cast<double>(ProjectPoints(camera, drive.T_camera_lidar, in_front).size()) /
      in_front.size();
  EXPECT_GT(inside, 0.95);

  const Rigid3d wrong =
      PerturbTcameraLidar(drive.T_camera_lidar, Eigen::Vector3d(0, 0, 90), Eigen::Vector3d::Zero());
  const double inside_wrong =
      static_cast<double>(ProjectPoints(camera, wrong, in_front).size()) / in_front.size();
  EXPECT_LT(inside_wrong, 0.05);
}

}  // namespace
}  // namespace stcalib
