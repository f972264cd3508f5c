// ApproximateTime pairing and the temporal evaluation (issue 6).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <set>

#include "core/eval/approximate_time.h"
#include "core/eval/temporal_eval.h"
#include "core/sim/simulator.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

constexpr StampNs kMs = 1000000;

TEST(ApproximateTime, PairsDelayedDecimatedLidarWithNearestImages) {
  // Images at 10 Hz; LiDAR at 5 Hz (every second sweep), stamped 0.1 s late, sweeps 10.5 ms
  // before their images.
  std::vector<StampNs> images, lidar;
  for (int i = 0; i < 30; ++i) images.push_back(1000 * kMs + i * 100 * kMs + 10 * kMs + kMs / 2);
  for (int k = 0; k < 30; k += 2) lidar.push_back(1000 * kMs + k * 100 * kMs + 100 * kMs);
  const auto pairs = PairApproximateTime(images, lidar);
  ASSERT_GE(pairs.size(), lidar.size() - 1);  // the last sweep may wait for a later image
  std::set<int> used_images, used_lidar;
  for (size_t p = 0; p < pairs.size(); ++p) {
    const auto [image, sweep] = pairs[p];
    EXPECT_TRUE(used_images.insert(image).second);
    EXPECT_TRUE(used_lidar.insert(sweep).second);
    // Nearest stamp: the image one frame after the sweep, 10.5 ms from the delayed stamp.
    EXPECT_EQ(image, 2 * sweep + 1);
    EXPECT_LE(std::llabs(images[image] - lidar[sweep]), 50 * kMs);
    if (p > 0) {
      EXPECT_GT(image, pairs[p - 1].first);
    }
  }
  // The output rate is that of the slower topic: half the images stay unpaired.
  EXPECT_EQ(pairs.size(), lidar.size());
}

TEST(ApproximateTime, ThreeTopicsPublishTheSmallestSpread) {
  ApproximateTimeSynchronizer sync(3);
  std::vector<std::vector<int>> published;
  auto add = [&](int topic, int index, StampNs t) {
    for (const auto& s : sync.Add(topic, index, t)) published.push_back(s);
  };
  add(0, 0, 100 * kMs);
  add(1, 0, 90 * kMs);
  add(1, 1, 104 * kMs);
  add(2, 0, 101 * kMs);
  add(0, 1, 200 * kMs);
  add(2, 1, 150 * kMs);
  add(1, 2, 210 * kMs);
  ASSERT_GE(published.size(), 1u);
  EXPECT_THAT(published[0], ::testing::ElementsAre(0, 1, 0));  // 104 ms beats 90 ms
}

TEST(TemporalEval, InferCloudBeatsFilterCloudOnASimulatedDrive) {
  testing::ScopedTempDir tmp;
  sim::SimulatorOptions sim_options;
  sim_options.seed = 6;
  sim_options.frames = 8;
  sim_options.time_offset_s = 0.02;
  std::string drive_dir;
  ASSERT_TRUE(sim::WriteSimulatedDrive(sim_options, tmp.path(), &drive_dir).ok());
  Drive drive;
  ASSERT_TRUE(OpenDrive(drive_dir, "", &drive).ok());
  TemporalEvalOptions options;
  options.drive_time_offset_s = 0.02;
  TemporalEvalResult result;
  const Status status = EvaluateTemporal(drive, options, &result);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_NEAR(result.time_offset_s, 0.02 - 0.1, 1e-12);
  ASSERT_GE(result.count[kFilterCloud], 3);
  ASSERT_EQ(result.count[kInferCloud], result.count[kFilterCloud]);
  EXPECT_GE(result.count[kInferCloudInterpolation], 2);
  const CloudMetrics& filter = result.mean[kFilterCloud];
  const CloudMetrics& infer = result.mean[kInferCloud];
  std::printf(
      "NN %.4f vs %.4f m (%.1f %% better); NDT iterations %.1f vs %.1f; ICP fitness (1 iteration) "
      "%.4f vs %.4f\n",
      infer.nn_dist_m, filter.nn_dist_m, 100 * (1 - infer.nn_dist_m / filter.nn_dist_m),
      infer.ndt_iters_001, filter.ndt_iters_001, infer.icp_fitness_1, filter.icp_fitness_1);
  EXPECT_LT(infer.nn_dist_m, 0.85 * filter.nn_dist_m);
  EXPECT_LT(infer.ndt_iters_001, filter.ndt_iters_001 / 4);
  // ICP fitness is reported, not asserted: PCL's score ignores pairs beyond the correspondence
  // distance, so a cloud displaced by more than that can score as well as an aligned one.
  for (const TemporalFrame& f : result.frames) {
    if (f.method == kFilterCloud) {
      EXPECT_NEAR(f.gap_s, -0.1105, 0.01);  // a sweep ~0.11 s old
    }
  }
}

TEST(TemporalEval, BadInputGetsAClearError) {
  testing::ScopedTempDir tmp;
  const std::string drive_dir = testing::MakeTinyDrive(tmp.path(), 3);
  Drive drive;
  ASSERT_TRUE(OpenDrive(drive_dir, "", &drive).ok());
  TemporalEvalResult result;
  Status status = EvaluateTemporal(drive, TemporalEvalOptions(), &result);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::HasSubstr("too few for a decimation of 2"));
  TemporalEvalOptions bad;
  bad.lidar_decimation = 0;
  EXPECT_FALSE(EvaluateTemporal(drive, bad, &result).ok());
  // No oxts: no motion model.
  const std::string longer = testing::MakeTinyDrive(tmp.path() + "/b", 6);
  std::filesystem::remove_all(longer + "/oxts");
  ASSERT_TRUE(OpenDrive(longer, "", &drive).ok());
  status = EvaluateTemporal(drive, TemporalEvalOptions(), &result);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::HasSubstr("no oxts"));
  // A gap in the oxts stamps.
  const std::string gapped = testing::MakeTinyDrive(tmp.path() + "/c", 6);
  std::vector<StampNs> stamps;
  ASSERT_TRUE(ReadTimestampsFile(gapped + "/oxts/timestamps.txt", &stamps).ok());
  for (size_t i = 3; i < stamps.size(); ++i) stamps[i] += 2000 * kMs;
  ASSERT_TRUE(WriteTimestampsFile(gapped + "/oxts/timestamps.txt", stamps).ok());
  ASSERT_TRUE(OpenDrive(gapped, "", &drive).ok());
  status = EvaluateTemporal(drive, TemporalEvalOptions(), &result);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::HasSubstr("gap"));
}

}  // namespace
}  // namespace stcalib
