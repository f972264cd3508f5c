// Line features against simulated truth and the KITTI calibration (issue 4).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <random>
#include <utility>

#include "core/features/ground.h"
#include "core/features/image_features.h"
#include "core/features/lidar_frame.h"
#include "core/features/lidar_rings.h"
#include "core/features/projection_filter.h"
#include "core/io/drive.h"
#include "core/motion/drive_motion.h"
#include "core/score/alignment.h"
#include "core/sim/simulator.h"
#include "core/types/calibration.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

using sim::Simulator;
using sim::SimulatorOptions;

LidarPoseFunction TruthPose(const Simulator& s) {
  return [&s](double t) { return s.trajectory().T_world_imu(t) * s.T_lidar_imu().inverse(); };
}

// Image `frame` of the shared KITTI drive; empty, with a failure recorded, when it cannot be read.
cv::Mat KittiImage(size_t frame) {
  Drive drive;
  cv::Mat image;
  const ::testing::AssertionResult opened = testing::OpenKittiDrive(&drive);
  if (!opened) {
    ADD_FAILURE() << opened.message();
    return image;
  }
  const Status status = drive.LoadImage(frame, &image);
  if (!status.ok()) ADD_FAILURE() << status.message();
  return image;
}

TEST(ImageFeatures, RectangleGivesExactDistanceAndIdt) {
  cv::Mat image(120, 200, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::rectangle(image, cv::Rect(60, 40, 80, 40), cv::Scalar(255, 255, 255), cv::FILLED);
  ImageFeatureOptions options;
  options.basin_px = 10;
  options.precise_distance = true;
  const ImageFeatures f = ExtractImageFeatures(image, options);
  ASSERT_FALSE(f.empty());
  EXPECT_EQ(f.edge_mask.size(), image.size());
  // On the rectangle's left side the distance is 0 and the IDT near 255; 30 px away, beyond the
  // basin, the IDT is 0 and the capped distance is the basin.
  int on_edge_u = -1;
  for (int u = 55; u < 66; ++u) {
    if (f.edge_mask.at<uint8_t>(60, u)) on_edge_u = u;
  }
  ASSERT_GE(on_edge_u, 0);
  EXPECT_EQ(f.distance_raw_px.at<float>(60, on_edge_u), 0.0f);
  EXPECT_GT(f.idt.at<float>(60, on_edge_u), 200.0f);
  EXPECT_NEAR(f.distance_raw_px.at<float>(60, on_edge_u - 7), 7.0f, 0.5f);
  EXPECT_EQ(f.idt.at<float>(60, 20), 0.0f);
  EXPECT_NEAR(f.distance_px.at<float>(60, 20), 10.0f, 1e-3);
  EXPECT_EQ(f.idt.type(), CV_32F);
  EXPECT_EQ(f.distance_px.type(), CV_32F);
}

// The chamfer transform is OpenCV's DIST_L2 / DIST_MASK_3 transform, bit for bit: on random
// masks of several sizes and densities (single rows and columns, one pixel, none) and on the
// Canny edges of a KITTI frame.
TEST(ImageFeatures, ChamferDistanceEqualsOpenCvsThreeByThreeTransform) {
  auto expect_equal = [](const cv::Mat& edges, const std::string& what) {
    cv::Mat ours, theirs;
    ChamferDistance(edges, &ours);
    cv::distanceTransform(edges == 0, theirs, cv::DIST_L2, cv::DIST_MASK_3);
    ASSERT_EQ(ours.type(), CV_32F) << what;
    ASSERT_EQ(ours.size(), edges.size()) << what;
    cv::Mat differs = ours != theirs;
    EXPECT_EQ(cv::countNonZero(differs), 0) << what;
  };
  cv::RNG rng(7);
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(1, 37), cv::Size(53, 1), cv::Size(61, 29),
                              cv::Size(200, 120), cv::Size(333, 77)}) {
    for (const double density : {0.0, 0.001, 0.02, 0.3}) {
      cv::Mat uniform(size, CV_32F);
      rng.fill(uniform, cv::RNG::UNIFORM, 0.0, 1.0);
      cv::Mat edges = uniform < density;
      if (density > 0 && cv::countNonZero(edges) == 0) edges.at<uint8_t>(size.height / 2, 0) = 255;
      expect_equal(edges, std::to_string(size.width) + "x" + std::to_string(size.height) +
                              " at density " + std::to_string(density));
    }
  }
  STCALIB_REQUIRE_KITTI();
  const cv::Mat image = KittiImage(0);
  ASSERT_FALSE(image.empty());
  const ImageFeatures f = ExtractImageFeatures(image, ImageFeatureOptions());
  ASSERT_GT(f.edge_pixels, 5000);
  expect_equal(f.edge_mask, "KITTI frame 0's edges");
}

// The features' IDT comes from the smoothed capped distance by the affine map (one blur for both):
// it equals InverseDistanceTransform of the raw distance up to float rounding, unsplit and per
// orientation, and the capped distance stays within [0, basin].
TEST(ImageFeatures, IdtIsTheAffineImageOfTheSmoothedCappedDistance) {
  STCALIB_REQUIRE_KITTI();
  const cv::Mat image = KittiImage(3);
  ASSERT_FALSE(image.empty());
  ImageFeatureOptions options;
  options.split_orientation = true;
  const ImageFeatures f = ExtractImageFeatures(image, options);
  ASSERT_FALSE(f.empty());
  auto max_difference = [&](const cv::Mat& idt, const cv::Mat& raw) {
    const cv::Mat reference =
        InverseDistanceTransform(raw, options.basin_px, options.smoothing_sigma_px);
    double worst = 0, peak = 0;
    cv::minMaxLoc(cv::abs(idt - reference), nullptr, &worst);
    cv::minMaxLoc(reference, nullptr, &peak);
    EXPECT_GT(peak, 200.0);  // edges present: the comparison is not between flat maps
    return worst;
  };
  EXPECT_LT(max_difference(f.idt, f.distance_raw_px), 1e-3);
  EXPECT_LT(max_difference(f.oriented[0].idt, f.distance_vertical_raw_px), 1e-3);
  EXPECT_LT(max_difference(f.oriented[1].idt, f.distance_horizontal_raw_px), 1e-3);
  double low = 0, high = 0;
  cv::minMaxLoc(f.oriented[0].distance_px, &low, &high);
  EXPECT_GE(low, 0.0);
  EXPECT_LE(high, options.basin_px + 1e-3);
}

TEST(ImageFeatures, RegionOfInterestMatchesTheFullImageInside) {
  cv::Mat image(120, 200, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::rectangle(image, cv::Rect(60, 60, 80, 40), cv::Scalar(255, 255, 255), cv::FILLED);
  cv::rectangle(image, cv::Rect(20, 5, 30, 20), cv::Scalar(255, 255, 255), cv::FILLED);
  ImageFeatureOptions options;
  options.precise_distance = true;
  const ImageFeatures whole = ExtractImageFeatures(image, options);
  options.region_of_interest = cv::Rect(0, 40, 200, 80);
  const ImageFeatures part = ExtractImageFeatures(image, options);
  EXPECT_EQ(part.idt.size(), image.size());
  // The upper rectangle is outside the region: no edges there.
  EXPECT_EQ(cv::countNonZero(part.edge_mask(cv::Rect(0, 0, 200, 40))), 0);
  EXPECT_GT(cv::countNonZero(whole.edge_mask(cv::Rect(0, 0, 200, 40))), 0);
  // Inside, near the lower rectangle, the maps agree.
  EXPECT_EQ(part.distance_raw_px.at<float>(80, 50), whole.distance_raw_px.at<float>(80, 50));
  EXPECT_NEAR(part.idt.at<float>(80, 58), whole.idt.at<float>(80, 58), 1.0);
}

TEST(ImageFeatures, BlackImageGivesEmptyFeaturesNotACrash) {
  ImageFeatureOptions options;
  const ImageFeatures f = ExtractImageFeatures(cv::Mat::zeros(50, 80, CV_8UC3), options);
  EXPECT_TRUE(f.empty());
  EXPECT_EQ(cv::countNonZero(f.idt), 0);
  EXPECT_TRUE(ExtractImageFeatures(cv::Mat(), options).empty());
  // Split by orientation: the oriented maps exist and are flat.
  options.split_orientation = true;
  const ImageFeatures split = ExtractImageFeatures(cv::Mat::zeros(50, 80, CV_8UC3), options);
  for (const OrientedMaps& m : split.oriented) {
    EXPECT_EQ(m.idt.size(), cv::Size(80, 50));
    EXPECT_EQ(cv::countNonZero(m.idt_bandpass), 0);
    EXPECT_EQ(cv::countNonZero(m.idt_suppressed), 0);
    EXPECT_EQ(cv::countNonZero(m.distance_px != options.basin_px), 0);
  }
}

// Without the unsplit maps (as the frame source asks, reading only the oriented ones) the
// oriented maps are the same bit for bit, and the unsplit ones are left empty.
TEST(ImageFeatures, OrientedMapsAloneEqualThoseBesideTheUnsplitOnes) {
  cv::Mat image(120, 200, CV_8UC3, cv::Scalar::all(60));
  cv::rectangle(image, cv::Rect(50, 30, 60, 50), cv::Scalar::all(200), cv::FILLED);
  cv::line(image, cv::Point(120, 100), cv::Point(190, 20), cv::Scalar::all(220), 2);
  ImageFeatureOptions options;
  options.split_orientation = true;
  const ImageFeatures both = ExtractImageFeatures(image, options);
  options.unsplit_maps = false;
  const ImageFeatures alone = ExtractImageFeatures(image, options);
  ASSERT_FALSE(alone.empty());
  for (const cv::Mat* m : {&alone.distance_raw_px, &alone.idt, &alone.idt_suppressed,
                           &alone.idt_bandpass, &alone.distance_px}) {
    EXPECT_TRUE(m->empty());
  }
  EXPECT_FALSE(both.idt.empty());
  EXPECT_EQ(cv::norm(alone.distance_vertical_raw_px, both.distance_vertical_raw_px, cv::NORM_INF),
            0);
  EXPECT_EQ(
      cv::norm(alone.distance_horizontal_raw_px, both.distance_horizontal_raw_px, cv::NORM_INF), 0);
  for (int o = 0; o < 2; ++o) {
    const OrientedMaps &a = alone.oriented[o], &b = both.oriented[o];
    EXPECT_EQ(cv::norm(a.idt, b.idt, cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(a.idt_bandpass, b.idt_bandpass, cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(a.idt_suppressed, b.idt_suppressed, cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(a.distance_px, b.distance_px, cv::NORM_INF), 0);
  }
}

// The band-pass map (BandPass) averages to zero over dense texture, so moving points into a
// textured region gains nothing; the clipped map (SuppressTexture) keeps the positive half-wave
// and rewards it. An isolated edge is a positive peak in both.
TEST(ImageFeatures, BandPassIsZeroMeanOnTextureAndPeaksOnAnIsolatedEdge) {
  cv::Mat image(240, 320, CV_8UC3, cv::Scalar::all(90));
  cv::RNG rng(7);
  for (int k = 0; k < 120; ++k) {  // "foliage" on the left: small leaves, edges every few pixels
    const cv::Point c(rng.uniform(0, 160), rng.uniform(60, 180));
    cv::circle(image, c, rng.uniform(2, 5), cv::Scalar::all(rng.uniform(0, 2) ? 20 : 200),
               cv::FILLED);
  }
  cv::rectangle(image, cv::Rect(230, 80, 40, 80), cv::Scalar::all(220), cv::FILLED);  // isolated
  ImageFeatureOptions options;
  const ImageFeatures f = ExtractImageFeatures(image, options);
  ASSERT_FALSE(f.empty());
  // Clipped form = max(0, band-pass).
  cv::Mat clipped;
  cv::max(f.idt_bandpass, 0.0, clipped);
  EXPECT_LT(cv::norm(clipped, f.idt_suppressed, cv::NORM_INF), 1e-3);
  const cv::Rect inner(40, 90, 80, 60);  // well inside the texture
  const double bandpass_mean = cv::mean(f.idt_bandpass(inner))[0];
  const double clipped_mean = cv::mean(f.idt_suppressed(inner))[0];
  const double idt_mean = cv::mean(f.idt(inner))[0];
  std::printf("texture: IDT mean %.1f, clipped %.1f, band-pass %.1f\n", idt_mean, clipped_mean,
              bandpass_mean);
  // Measured: IDT 215, clipped 10.5, band-pass 0.1 grey levels.
  EXPECT_LT(std::abs(bandpass_mean), 0.02 * idt_mean);
  EXPECT_GT(clipped_mean, 5.0);
  EXPECT_LT(std::abs(bandpass_mean), 0.2 * clipped_mean);
  // On the isolated rectangle's left side (x = 230), the band-pass value is a clear peak.
  EXPECT_GT(f.idt_bandpass.at<float>(120, 230), 0.3 * 255);
  EXPECT_GT(f.idt_bandpass.at<float>(120, 230), f.idt_bandpass.at<float>(120, 200) + 50);
}

TEST(ImageFeatures, LineDetectorsFindSegmentsOnKitti) {
  STCALIB_REQUIRE_KITTI();
  const cv::Mat image = KittiImage(0);
  ASSERT_FALSE(image.empty());
  for (auto detector :
       {ImageFeatureOptions::Detector::kLsd, ImageFeatureOptions::Detector::kFastLine}) {
    ImageFeatureOptions options;
    options.detector = detector;
    const ImageFeatures f = ExtractImageFeatures(image, options);
    EXPECT_GT(f.segments.size(), 200u);
    EXPECT_GT(f.edge_pixels, 5000);
    for (const cv::Vec4f& s : f.segments) {  // full-size coordinates
      EXPECT_LE(std::max(s[0], s[2]), image.cols);
      EXPECT_LE(std::max(s[1], s[3]), image.rows);
    }
  }
}

// A vertical step between columns c−1 and c has its edge at x = c − 0.5 (pixel centres at
// integers). LSD run at half resolution must report it there too: the coordinates of the
// reduced image are mapped back centre to centre, not just scaled.
TEST(ImageFeatures, LsdSegmentsKeepPixelCentresAtReducedScale) {
  for (double scale : {1.0, 0.5}) {
    double sum = 0;
    int found = 0;
    for (int column = 100; column < 104; ++column) {
      cv::Mat image(200, 300, CV_8UC1, cv::Scalar(40));
      image(cv::Rect(column, 0, 300 - column, 200)).setTo(200);
      ImageFeatureOptions options;
      options.detector = ImageFeatureOptions::Detector::kLsd;
      options.line_scale = scale;
      const ImageFeatures f = ExtractImageFeatures(image, options);
      for (const cv::Vec4f& s : f.segments) {
        if (std::abs(s[3] - s[1]) < 100 || std::abs(s[2] - s[0]) > 1) continue;  // the long one
        const double error = 0.5 * (s[0] + s[2]) - (column - 0.5);
        std::printf("scale %.1f edge x=%.1f: segment x error %+.2f px\n", scale, column - 0.5,
                    error);
        EXPECT_LT(std::abs(error), 0.75);
        sum += error;
        ++found;
      }
    }
    ASSERT_EQ(found, 4) << "scale " << scale;
    EXPECT_LT(std::abs(sum / found), 0.3) << "scale " << scale;
  }
}

// The ring splitter's and the edge detector's wrapped azimuth step is std::remainder's, bit for
// bit, over 200k random pairs of azimuths and the wrap's extremes.
TEST(LidarRings, WrappedAzimuthStepIsTheRemainderBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> azimuth(static_cast<float>(-M_PI),
                                                static_cast<float>(M_PI));
  std::vector<std::pair<float, float>> pairs = {
      {-3.14159f, 3.14159f}, {3.14159f, -3.14159f}, {0.0f, 0.0f}, {-1e-7f, 1e-7f}};
  for (int i = 0; i < 200000; ++i) pairs.emplace_back(azimuth(rng), azimuth(rng));
  int wrapped = 0;
  for (const auto& [from, to] : pairs) {
    const double expected = std::remainder(to - from, 2 * M_PI);
    ASSERT_EQ(WrappedAzimuthStep(from, to), expected) << from << " -> " << to;
    if (std::abs(to - from) > M_PI) ++wrapped;
  }
  EXPECT_GT(wrapped, 40000);  // a quarter of random pairs wrap
}

TEST(LidarRings, KittiFramesHaveSixtyFourRingsTopToBottom) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive));
  for (size_t frame : {0u, 9u, 17u, 29u}) {
    LidarScan scan;
    ASSERT_TRUE(drive.LoadScan(frame, &scan).ok());
    const ScanRings rings = SplitIntoRings(scan.points_lidar);
    EXPECT_EQ(rings.num_rings(), 64) << "frame " << frame;
    // KITTI stores lasers from the top beam down.
    for (int k = 0; k < rings.num_rings(); ++k) EXPECT_EQ(rings.order_by_elevation[k], k);
    // Within a laser, time runs from +T/2 .. −T/2 as the azimuth goes round counter-clockwise.
    const std::vector<double> t = PointTimesFromAzimuth(rings, 0.1036);
    for (double ti : t) {
      EXPECT_LE(std::abs(ti), 0.0518 + 1e-6);
    }
  }
}

TEST(LidarRings, SimulatedRingsAndTimesMatchTruthExactly) {
  SimulatorOptions options;
  options.seed = 12;
  options.frames = 3;
  const Simulator s(options);
  const sim::SimulatedSweep sweep = s.SimulateSweep(1);
  const ScanRings rings = SplitIntoRings(sweep.scan.points_lidar);
  ASSERT_EQ(rings.num_rings(), 64);
  const std::vector<double> t = PointTimesFromAzimuth(rings, s.SweepDuration());
  size_t wrong_ring = 0;
  double worst_time = 0;
  for (size_t i = 0; i < sweep.scan.size(); ++i) {
    wrong_ring += rings.ring[i] != sweep.ring[i];
    worst_time = std::max(worst_time, std::abs(t[i] - (sweep.point_time_s[i] - s.LidarMidTime(1))));
  }
  EXPECT_EQ(wrong_ring, 0u);
  EXPECT_LT(worst_time, 1e-6);
  EXPECT_NEAR(rings.azimuth_step_rad, 0.09 * M_PI / 180, 1e-5);
}

// True depth discontinuity within `radius` of a point: rays through the point shifted by ±radius
// sideways and up/down (the simulator's own scene as oracle) meet a surface at another depth.
bool NearTrueEdge(const Simulator& s, const sim::AzimuthIndex& index, const Eigen::Vector3d& origin,
                  const Eigen::Vector3d& p_world, double t, double radius) {
  const double max_range = 130;
  sim::RayHit centre;
  const Eigen::Vector3d dir = (p_world - origin).normalized();
  if (!s.scene().Intersect(index, origin, dir, t, max_range, &centre)) return true;
  const Eigen::Vector3d side = dir.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d up = side.cross(dir).normalized();
  const double r = (p_world - origin).norm();
  for (const Eigen::Vector3d& offset : {side, Eigen::Vector3d(-side), up, Eigen::Vector3d(-up)}) {
    const Eigen::Vector3d d = ((origin + dir * r + offset * radius) - origin).normalized();
    sim::RayHit hit;
    if (!s.scene().Intersect(index, origin, d, t, max_range, &hit)) return true;
    if (std::abs(hit.range - centre.range) > 0.3) return true;
  }
  return false;
}

// Calls `visit` on frames 4 and 15 of simulated 20-frame drives, seeds 3 and 8.
void ForEachSimulatedSweep(
    const std::function<void(const Simulator&, uint64_t, int, const sim::SimulatedSweep&)>& visit) {
  for (uint64_t seed : {3u, 8u}) {
    SimulatorOptions options;
    options.seed = seed;
    options.frames = 20;
    const Simulator s(options);
    for (int frame : {4, 15}) visit(s, seed, frame, s.SimulateSweep(frame));
  }
}

TEST(LidarEdges, SimulatedEdgePointsLieOnTrueGeometricEdges) {
  size_t total = 0, near_edge = 0;
  ForEachSimulatedSweep([&](const Simulator& s, uint64_t seed, int frame,
                            const sim::SimulatedSweep& sweep) {
    const LidarFrameFeatures f =
        ComputeLidarFrameFeatures(sweep.scan, s.LidarMidTime(frame), s.SweepDuration(),
                                  TruthPose(s), {}, LidarFeatureOptions());
    ASSERT_GT(f.edges.size(), 500u);
    const double t_mid = s.LidarMidTime(frame);
    const Rigid3d T_mid = TruthPose(s)(t_mid);
    const sim::AzimuthIndex index =
        s.scene().BuildIndex(T_mid.translation().head<2>(), t_mid - 0.06, t_mid + 0.06, 1.5, 130);
    size_t frame_near = 0;
    for (size_t k = 0; k < f.edges.size(); ++k) {
      const int i = f.edges.source_index[k];
      const double t = sweep.point_time_s[i];
      const Rigid3d T = TruthPose(s)(t);
      frame_near += NearTrueEdge(s, index, T.translation(), T * sweep.scan.points_lidar[i], t, 0.2);
    }
    std::printf("seed %llu frame %d: %zu edge points, %.1f%% within 0.2 m of a true edge\n",
                static_cast<unsigned long long>(seed), frame, f.edges.size(),
                100.0 * frame_near / f.edges.size());
    total += f.edges.size();
    near_edge += frame_near;
  });
  EXPECT_GE(static_cast<double>(near_edge) / total, 0.80);
}

// Folds (LidarEdgeOptions) against the simulator's scene. Within a few metres of depth a fold is
// an object's own corner, not its outline: the beam above it, cast at the same capture time,
// meets the same object as the fold's own return (its top, or a face behind the corner on that
// object: a car's cabin behind its bonnet). Unbounded (the default), the folds also take outlines
// whose beam above meets a background at their height.
// Both with the folds left at their corners (fold_top_depth_m = 0).
TEST(LidarEdges, FoldsAreCornersOfTheirOwnObject) {
  size_t folds = 0, same_object = 0, horizontal = 0, unbounded = 0;
  LidarFeatureOptions corners, all_corners;
  corners.edges.fold_max_depth_m = 3.0;
  corners.edges.fold_top_depth_m = 0;
  all_corners.edges.fold_top_depth_m = 0;
  ForEachSimulatedSweep([&](const Simulator& s, uint64_t, int frame,
                            const sim::SimulatedSweep& sweep) {
    const LidarFrameFeatures f = ComputeLidarFrameFeatures(
        sweep.scan, s.LidarMidTime(frame), s.SweepDuration(), TruthPose(s), {}, corners);
    ASSERT_EQ(f.edges.fold.size(), f.edges.size());
    const LidarFrameFeatures all_folds = ComputeLidarFrameFeatures(
        sweep.scan, s.LidarMidTime(frame), s.SweepDuration(), TruthPose(s), {}, all_corners);
    ASSERT_EQ(all_folds.edges.size(), f.edges.size());  // the same edges, more of them folds
    for (size_t k = 0; k < f.edges.size(); ++k) {
      ASSERT_TRUE(!f.edges.fold[k] || all_folds.edges.fold[k]);
      unbounded += all_folds.edges.fold[k];
    }
    const double t_mid = s.LidarMidTime(frame);
    const sim::AzimuthIndex index = s.scene().BuildIndex(
        TruthPose(s)(t_mid).translation().head<2>(), t_mid - 0.06, t_mid + 0.06, 1.5, 130);
    for (size_t k = 0; k < f.edges.size(); ++k) {
      horizontal += f.edges.kind[k] == EdgeKind::kHorizontal;
      if (!f.edges.fold[k]) continue;
      ++folds;
      ASSERT_EQ(f.edges.kind[k], EdgeKind::kHorizontal);
      const int i = f.edges.source_index[k];
      const int rank = f.rings.elevation_rank[f.rings.ring[i]] - 1;  // the beam above
      ASSERT_GE(rank, 0);
      const double elevation = f.rings.ring_elevation_rad[f.rings.order_by_elevation[rank]];
      const double azimuth = f.rings.azimuth_rad[i];
      const Eigen::Vector3d up_lidar(std::cos(elevation) * std::cos(azimuth),
                                     std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      const double t = sweep.point_time_s[i];
      const Rigid3d T = TruthPose(s)(t);
      sim::RayHit own, above;
      const bool hit_own =
          s.scene().Intersect(index, T.translation(),
                              T.linear() * sweep.scan.points_lidar[i].normalized(), t, 130, &own);
      const bool hit_above =
          s.scene().Intersect(index, T.translation(), T.linear() * up_lidar, t, 130, &above);
      same_object += hit_own && hit_above && own.object >= 0 && above.object == own.object;
    }
  });
  std::printf(
      "%zu folds within 3 m among %zu horizontal edge points, %zu on their own object; %zu "
      "unbounded\n",
      folds, horizontal, same_object, unbounded);
  ASSERT_GT(folds, 20u);
  EXPECT_GT(unbounded, folds);
  EXPECT_GE(static_cast<double>(same_object) / folds, 0.9);
}

// Elevation [rad] of a direction in the LiDAR frame.
double Elevation(const Eigen::Vector3d& d) { return std::atan2(d.z(), d.head<2>().norm()); }

// A fold moved to its top's far side (LidarEdgeOptions::fold_top_depth_m, the default) lies at
// the top's outline, where a corner left in place lies below it. Oracle: the simulator's scene.
// From the top (the fold's own return when moved, the beam above a corner otherwise), rays at the
// same azimuth are cast upward in 0.005° steps while they meet the same object at the top's
// height (±0.1 m); the outline is where they stop. The edge point's elevation is compared with
// it. Measured: moved, mean error −0.07° (|error| 0.12°, quartiles −0.18..+0.04°; the beams
// are 0.42° apart); at the corners −0.49° (0.49°, −0.63..−0.29°).
TEST(LidarEdges, FoldsMovedToTheFarSideOfTheirTopLieOnItsOutline) {
  LidarEdgeOptions moved_options, corner_options;
  ASSERT_GT(moved_options.fold_top_depth_m, 0);
  corner_options.fold_top_depth_m = 0;
  struct Errors {
    double sum = 0, abs_sum = 0;
    std::vector<double> all;
    size_t count() const { return all.size(); }
  } moved, corners;
  ForEachSimulatedSweep([&](const Simulator& s, uint64_t, int frame,
                            const sim::SimulatedSweep& sweep) {
    const LidarFrameFeatures f = ComputeLidarFrameFeatures(sweep.scan, s.LidarMidTime(frame),
                                                           s.SweepDuration(), TruthPose(s), {}, {});
    // Edges in capture-time geometry (not de-skewed), ground left out as the features do.
    std::vector<PointUse> use(f.scan.size(), PointUse::kUse);
    for (size_t i = 0; i < use.size(); ++i) {
      if (f.ground[i]) use[i] = PointUse::kGround;
    }
    const double t_mid = s.LidarMidTime(frame);
    const sim::AzimuthIndex index = s.scene().BuildIndex(
        TruthPose(s)(t_mid).translation().head<2>(), t_mid - 0.06, t_mid + 0.06, 1.5, 130);
    for (const bool move : {true, false}) {
      const LidarEdges edges = ExtractLidarEdges(f.scan, f.rings, f.point_time_s, &use,
                                                 move ? moved_options : corner_options);
      Errors& errors = move ? moved : corners;
      for (size_t k = 0; k < edges.size(); ++k) {
        if (!edges.fold[k]) continue;
        const int i = edges.source_index[k];
        const Eigen::Vector3d& q = f.scan.points_lidar[i];
        const double azimuth = std::atan2(q.y(), q.x());
        double elevation = Elevation(q);
        if (!move) {  // the beam above the corner
          const int rank = f.rings.elevation_rank[f.rings.ring[i]] - 1;
          ASSERT_GE(rank, 0);
          elevation = f.rings.ring_elevation_rad[f.rings.order_by_elevation[rank]];
        }
        const double t = sweep.point_time_s[i];
        const Rigid3d T = TruthPose(s)(t);
        auto cast = [&](double e, sim::RayHit* hit) {
          const Eigen::Vector3d d(std::cos(e) * std::cos(azimuth), std::cos(e) * std::sin(azimuth),
                                  std::sin(e));
          return s.scene().Intersect(index, T.translation(), T.linear() * d, t, 130, hit);
        };
        sim::RayHit top;
        if (!cast(elevation, &top) || top.object < 0) continue;
        const double top_z = (T.inverse() * top.point_world).z();
        const double step = 0.005 * M_PI / 180;
        double e = elevation;
        for (int n = 0; n < 600; ++n) {
          sim::RayHit hit;
          if (!cast(e + step, &hit) || hit.object != top.object ||
              std::abs((T.inverse() * hit.point_world).z() - top_z) > 0.1) {
            break;
          }
          e += step;
        }
        const double error_deg = (Elevation(edges.points_lidar[k]) - (e + step / 2)) * 180 / M_PI;
        errors.sum += error_deg;
        errors.abs_sum += std::abs(error_deg);
        errors.all.push_back(error_deg);
      }
    }
  });
  ASSERT_GT(moved.count(), 20u);
  ASSERT_GT(corners.count(), 20u);
  for (auto* e : {&moved, &corners}) std::sort(e->all.begin(), e->all.end());
  auto quartiles = [](const Errors& e) {
    return std::to_string(e.all[e.count() / 4]) + ".." + std::to_string(e.all[3 * e.count() / 4]);
  };
  const double moved_mean = moved.sum / moved.count(), moved_abs = moved.abs_sum / moved.count();
  const double corner_mean = corners.sum / corners.count();
  const double corner_abs = corners.abs_sum / corners.count();
  std::printf(
      "%zu folds moved: elevation error mean %+.3f deg, |error| %.3f deg, quartiles %s; %zu at "
      "corners: %+.3f deg, %.3f deg, %s\n",
      moved.count(), moved_mean, moved_abs, quartiles(moved).c_str(), corners.count(), corner_mean,
      corner_abs, quartiles(corners).c_str());
  EXPECT_LT(std::abs(moved_mean), 0.1);
  EXPECT_LT(moved_abs, 0.2);
  EXPECT_LT(corner_mean, -0.15);  // the bias the move removes
}

// Select and Append carry every per-point field with its point; a field out of step with the
// points is a programmer error.
TEST(LidarEdges, SelectAndAppendCarryEveryField) {
  LidarEdges edges;
  for (int i = 0; i < 4; ++i) {
    edges.points_lidar.push_back(Eigen::Vector3d(i, 0, 0));
    edges.time_s.push_back(0.01 * i);
    edges.kind.push_back(i % 2 ? EdgeKind::kHorizontal : EdgeKind::kVertical);
    edges.source_index.push_back(100 + i);
    edges.offset_rate.push_back(Eigen::Vector3d(0, 0, i));
    edges.fold.push_back(i == 3 ? 1 : 0);
    edges.sweep_age.push_back(0);
  }
  LidarEdges picked = edges.Select({3, 0});
  picked.Append(edges.Select({1}));
  ASSERT_EQ(picked.size(), 3u);
  const int expected[] = {3, 0, 1};
  for (size_t k = 0; k < 3; ++k) {
    const int i = expected[k];
    EXPECT_EQ(picked.points_lidar[k].x(), i);
    EXPECT_EQ(picked.time_s[k], 0.01 * i);
    EXPECT_EQ(picked.kind[k], i % 2 ? EdgeKind::kHorizontal : EdgeKind::kVertical);
    EXPECT_EQ(picked.source_index[k], 100 + i);
    EXPECT_EQ(picked.offset_rate[k].z(), i);
    EXPECT_EQ(picked.fold[k], i == 3 ? 1 : 0);
  }
  EXPECT_TRUE(edges.Select({}).empty());
  LidarEdges broken = edges;
  broken.time_s.pop_back();
  EXPECT_DEATH(broken.Select({0}), "one entry per point");
  EXPECT_DEATH(picked.Append(broken), "one entry per point");
  EXPECT_DEATH(edges.Select({4}), "index 4");
}

TEST(Ground, PlaneSeparatesSimulatedGroundLabels) {
  SimulatorOptions options;
  options.seed = 5;
  options.frames = 10;
  const Simulator s(options);
  const sim::SimulatedSweep sweep = s.SimulateSweep(6);
  GroundOptions ground_options;
  const GroundPlane plane = FitGroundPlane(sweep.scan.points_lidar, ground_options);
  ASSERT_TRUE(plane.valid);
  // The LiDAR is 1.73 m above the road (0.93 m IMU height + 0.80 m).
  EXPECT_NEAR(plane.offset, 1.73, 0.1);
  const std::vector<uint8_t> mask =
      GroundMask(sweep.scan.points_lidar, plane, ground_options.band_m);
  size_t true_positive = 0, labelled = 0, masked = 0;
  for (size_t i = 0; i < mask.size(); ++i) {
    const bool ground = sweep.labels[i] == static_cast<uint8_t>(PointLabel::kGround);
    labelled += ground;
    masked += mask[i];
    true_positive += ground && mask[i];
  }
  // Precision: the band also takes the bottom 25 cm of walls, poles and trunks.
  EXPECT_GT(static_cast<double>(true_positive) / masked, 0.93);
  EXPECT_GT(static_cast<double>(true_positive) / labelled, 0.90);  // recall
}

TEST(ProjectionFilter, DropsIsolatedPointsOnly) {
  const std::vector<Eigen::Vector2d> pixels = {{10, 10},  {15, 14},    {100, 100},
                                               {300, 40}, {307.9, 40}, {500, 500}};
  const std::vector<bool> keep = KeepNonIsolated(pixels, 8.0);
  EXPECT_THAT(keep, ::testing::ElementsAre(true, true, false, true, true, false));
  EXPECT_THAT(KeepNonIsolated({{1, 1}}, 8.0), ::testing::ElementsAre(false));
}

TEST(LidarEdges, EmptyAndDegenerateInputGiveEmptyFeatures) {
  const LidarScan empty;
  const LidarFrameFeatures f = ComputeLidarFrameFeatures(
      empty, 0.0, 0.1, [](double) { return Rigid3d::Identity(); }, {}, LidarFeatureOptions());
  EXPECT_TRUE(f.edges.empty());
  EXPECT_EQ(f.rings.num_rings(), 0);
  // Every point behind the camera: nothing projects, nothing aligns, nothing crashes.
  CameraModel camera;
  camera.P_rect << 700, 0, 600, 0, 0, 700, 180, 0, 0, 0, 1, 0;
  camera.width = 1200;
  camera.height = 360;
  std::vector<Eigen::Vector3d> behind(100, Eigen::Vector3d(0, 0, -5));
  const auto projected = ProjectPoints(camera, Rigid3d::Identity(), behind);
  EXPECT_TRUE(projected.empty());
  const AlignmentStats stats = MeasureAlignment(projected, cv::Mat::zeros(360, 1200, CV_32F), 3, 8);
  EXPECT_EQ(stats.kept, 0);
  EXPECT_EQ(stats.rate, 0.0);
}

// Alignment rate on KITTI with the drive's calibration and with 2° of rotation error per axis.
// The plain rate (any Canny edge within 3 px) hardly moves on this tree-lined street: foliage
// puts an edge within 3 px of almost any point. The orientation-aware rate (vertical LiDAR edges
// against near-vertical image edges, horizontal against horizontal) drops clearly.
TEST(Alignment, KittiRateDropsWithTwoDegreesOfError) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  DriveMotion motion;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive, &motion));
  ImageFeatureOptions image_options;
  image_options.split_orientation = true;
  image_options.precise_distance = true;
  const std::vector<size_t> frames = {0, 7, 14, 21, 29};
  const char* kAxis[] = {"roll", "pitch", "yaw"};
  double plain_true = 0, oriented_true = 0;
  Eigen::Vector3d plain_off = Eigen::Vector3d::Zero(), oriented_off = Eigen::Vector3d::Zero();
  for (size_t frame : frames) {
    cv::Mat image;
    ASSERT_TRUE(drive.LoadImage(frame, &image).ok());
    const ImageFeatures image_features = ExtractImageFeatures(image, image_options);
    LidarFrameFeatures lidar;
    ASSERT_TRUE(LoadLidarFrameFeatures(drive, motion, frame, LidarFeatureOptions(), &lidar).ok());
    const CameraModel camera = MakeCameraModel(drive.camera, image.cols, image.rows);
    const Rigid3d T_motion = RelativeLidarPose(
        motion.PoseFunction(), motion.Seconds(drive.camera_stamps_ns[frame]), lidar.stamp_s);
    auto rates = [&](const Rigid3d& T_camera_lidar) {
      const auto projected =
          ProjectPoints(camera, T_camera_lidar * T_motion, lidar.edges.points_lidar);
      return Eigen::Vector2d(
          MeasureAlignment(projected, image_features.distance_raw_px, 3.0, 8.0).rate,
          MeasureOrientedAlignment(projected, lidar.edges.kind,
                                   image_features.distance_vertical_raw_px,
                                   image_features.distance_horizontal_raw_px, 3.0, 8.0)
              .rate);
    };
    const Eigen::Vector2d truth = rates(drive.T_camera_lidar);
    plain_true += truth.x() / frames.size();
    oriented_true += truth.y() / frames.size();
    std::printf("frame %2zu: plain %.1f%% oriented %.1f%% with KITTI's calibration", frame,
                100 * truth.x(), 100 * truth.y());
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
      rpy[axis] = 2.0;
      const Eigen::Vector2d off =
          rates(PerturbTcameraLidar(drive.T_camera_lidar, rpy, Eigen::Vector3d::Zero()));
      plain_off[axis] += off.x() / frames.size();
      oriented_off[axis] += off.y() / frames.size();
      std::printf("; %s +2: %.1f%% / %.1f%%", kAxis[axis], 100 * off.x(), 100 * off.y());
    }
    std::printf("\n");
  }
  std::printf(
      "mean: plain %.1f%% (roll %.1f, pitch %.1f, yaw %.1f); oriented %.1f%% (roll %.1f, "
      "pitch %.1f, yaw %.1f)\n",
      100 * plain_true, 100 * plain_off[0], 100 * plain_off[1], 100 * plain_off[2],
      100 * oriented_true, 100 * oriented_off[0], 100 * oriented_off[1], 100 * oriented_off[2]);
  EXPECT_GT(oriented_true, 0.55);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LT(plain_off[axis], plain_true) << kAxis[axis];
    EXPECT_LT(oriented_off[axis], oriented_true - 0.05) << kAxis[axis];
  }
  EXPECT_LT(oriented_off.mean(), oriented_true - 0.07);
}

}  // namespace
}  // namespace stcalib
