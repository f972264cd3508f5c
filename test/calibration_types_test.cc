#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#if defined(__GLIBC__)
#include <malloc.h>
#endif
#if defined(__has_feature)
#define STCALIB_CLANG_SANITIZER                                           \
  (__has_feature(address_sanitizer) || __has_feature(memory_sanitizer) || \
   __has_feature(thread_sanitizer))
#else
#define STCALIB_CLANG_SANITIZER 0
#endif

#include "core/types/calibration.h"
#include "core/types/heap.h"

namespace stcalib {
namespace {

TEST(CalibrationError, PerturbationIsRecoveredPerAxis) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-3.0, 3.0), offset(-0.1, 0.1);
  CalibrationState reference;
  reference.T_camera_lidar = MakeRigid(NominalRcameraLidar(), Eigen::Vector3d(0.0, -0.08, -0.27));
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

TEST(MountRollPitchYaw, RecoversTheAnglesAndIsWellConditioned) {
  // The nominal mount: the LiDAR's forward axis is the camera's optical axis, its up the image's
  // up (camera −y).
  const Eigen::Matrix3d R_forward = NominalRcameraLidar();
  EXPECT_EQ(R_forward * Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ());
  EXPECT_EQ(R_forward * Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitY());
  EXPECT_EQ(R_forward * Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitX());
  EXPECT_LT(MountRollPitchYawDeg(R_forward).norm(), 1e-12);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-60.0, 60.0);
  auto rotation = [](const Eigen::Vector3d& rpy_deg) {
    const Eigen::Vector3d r = rpy_deg * M_PI / 180.0;
    return (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  };
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d rpy_deg(angle(rng), angle(rng), angle(rng));
    EXPECT_LT((MountRollPitchYawDeg(R_forward * rotation(rpy_deg)) - rpy_deg).norm(), 1e-9);
  }
  // A mount a degree or two off the nominal one: a small rotation about a LiDAR axis moves the
  // matching angle by about as much and the others hardly (Euler angles of R_camera_lidar itself
  // swing by tens of degrees there, at gimbal lock).
  const Eigen::Matrix3d R = R_forward * rotation(Eigen::Vector3d(0.8, -1.5, 1.2));
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d step = 0.1 * Eigen::Vector3d::Unit(axis);
    const Eigen::Vector3d moved =
        MountRollPitchYawDeg(PerturbTcameraLidar(MakeRigid(R, Eigen::Vector3d::Zero()), step,
                                                 Eigen::Vector3d::Zero())
                                 .linear()) -
        MountRollPitchYawDeg(R);
    EXPECT_LT((moved - step).norm(), 0.01) << "axis " << axis << ": " << moved.transpose();
  }
}

TEST(CalibrationError, RotationErrorOfKnownAngle) {
  const Eigen::Matrix3d a = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d b = Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(RotationErrorDeg(a, b), 0.5 * 180 / M_PI, 1e-9);
  EXPECT_NEAR(RotationErrorDeg(a, a), 0.0, 1e-6);
}

// A 24 MiB block (far above glibc's default 128 KiB mmap threshold, below the 32 MiB an older
// glibc allows as a fixed one) comes from the heap once RetainFreedHeapMemory() has run, and
// freeing it leaves its pages with the process instead of unmapping or trimming them.
TEST(Heap, RetainedLargeBlocksComeFromTheHeapAndStayAfterFree) {
#if defined(__SANITIZE_ADDRESS__) || STCALIB_CLANG_SANITIZER
  GTEST_SKIP() << "the sanitizer replaces the allocator (its mallopt does nothing)";
#elif defined(__GLIBC__)
#if __GLIBC_PREREQ(2, 33)  // mallinfo2
  ASSERT_TRUE(RetainFreedHeapMemory());
  constexpr size_t kBytes = size_t{24} << 20;
  const size_t mapped_before = mallinfo2().hblkhd;
  char* volatile block = static_cast<char*>(std::malloc(kBytes));
  ASSERT_NE(block, nullptr);
  block[kBytes - 1] = 1;
  EXPECT_EQ(mallinfo2().hblkhd, mapped_before) << "the block was mmapped";
  std::free(block);
  EXPECT_GE(mallinfo2().fordblks, kBytes) << "the freed block was returned to the kernel";
#else
  GTEST_SKIP() << "glibc before 2.33 has no mallinfo2";
#endif
#else
  GTEST_SKIP() << "not glibc 2.33 or later: RetainFreedHeapMemory() is not observable";
#endif
}

}  // namespace
}  // namespace stcalib
