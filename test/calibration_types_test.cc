#include <gtest/gtest.h>

#include <random>

#include "core/types/calibration.h"

namespace stcalib {
namespace {

TEST(CalibrationError, PerturbationIsRecoveredPerAxis) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-3.0, 3.0), offset(-0.1, 0.1);
  Eigen::Matrix3d R;
  R << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  CalibrationState reference;
  reference.T_camera_lidar = MakeRigid(R, Eigen::Vector3d(0.0, -0.08, -0.27));
  reference.time_offset_s = 0.01;
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d rpy_deg(angle(rng), angle(rng), angle(rng));
    const Eigen::Vector3d dt(offset(rng), offset(rng), offset(rng));
    CalibrationState estimate = reference;
    estimate.T_camera_lidar = PerturbTcameraLidar(reference.T_camera_lidar, rpy_deg, dt);
    estimate.time_offset_s = 0.03;
    const CalibrationError e = ComputeCalibrationError(estimate, reference);
    EXPECT_NEAR(e.roll_deg, rpy_deg.x(), 1e-9);
    EXPECT_NEAR(e.pitch_deg, rpy_deg.y(), 1e-9);
    EXPECT_NEAR(e.yaw_deg, rpy_deg.z(), 1e-9);
    EXPECT_NEAR(e.rotation_deg, rpy_deg.norm(), 1e-9);
    EXPECT_LT((e.translation_m - dt).norm(), 1e-12);
    EXPECT_NEAR(e.time_offset_s, 0.02, 1e-15);
  }
}

TEST(CalibrationError, RotationErrorOfKnownAngle) {
  const Eigen::Matrix3d a = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d b = Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(RotationErrorDeg(a, b), 0.5 * 180 / M_PI, 1e-9);
  EXPECT_NEAR(RotationErrorDeg(a, a), 0.0, 1e-6);
}

}  // namespace
}  // namespace stcalib
