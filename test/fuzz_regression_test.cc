// Every input the fuzzers ever broke a reader with (test/fuzz/regressions/<reader>/), run through
// the same checks as the fuzz targets: an error naming the file, or only finite, valid numbers.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/io/kitti_calib.h"
#include "core/io/timestamps.h"
#include "test/fuzz/readers.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

TEST(FuzzRegressions, EveryKeptInputGivesAnErrorOrAValidResult) {
  const std::filesystem::path root = STCALIB_FUZZ_REGRESSIONS_DIR;
  ASSERT_TRUE(std::filesystem::is_directory(root)) << root;
  int inputs = 0;
  for (const char* reader : fuzz::kReaders) {
    const std::filesystem::path dir = root / reader;
    if (!std::filesystem::is_directory(dir)) continue;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
      // CheckReader aborts on a broken promise, which fails the test binary.
      EXPECT_TRUE(fuzz::CheckReader(reader, entry.path().string())) << reader;
      ++inputs;
    }
  }
  EXPECT_GE(inputs, 3);
}

TEST(FuzzRegressions, TimestampYearsThatOverflowNanosecondsAreRejected) {
  StampNs stamp = 0;
  EXPECT_FALSE(ParseKittiTimestamp("2811-09-26 13:10:51.106324297", &stamp));
  EXPECT_FALSE(ParseKittiTimestamp("1011-09-26 13:10:51.1", &stamp));
  EXPECT_TRUE(ParseKittiTimestamp("2199-09-26 13:10:51.1", &stamp));
  EXPECT_GT(stamp, 0);
}

TEST(FuzzRegressions, KittiRotationsAreMovedToTheNearestRotation) {
  STCALIB_REQUIRE_KITTI();
  // KITTI's printed R is ~1e-7 from orthonormal: accepted, then made exact.
  Rigid3d T;
  ASSERT_TRUE(ReadVeloToCam(testing::KittiCalibDir() + "/calib_velo_to_cam.txt", &T).ok());
  const Eigen::Matrix3d R = T.linear();
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(R(0, 1), -0.9999704, 1e-3);
}

}  // namespace
}  // namespace stcalib
