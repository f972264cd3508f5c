// Dynamic-point removal, the oxts motion model, de-skew and the local map (issue 4).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include "core/features/fast_atan2.h"
#include "core/features/lidar_frame.h"
#include "core/motion/deskew.h"
#include "core/motion/drive_motion.h"
#include "core/motion/motion_model.h"
#include "core/motion/oxts_trajectory.h"
#include "core/score/alignment.h"
#include "core/sim/simulator.h"
#include "core/types/calibration.h"
#include "test/test_util.h"

namespace stcalib {
namespace {

using sim::Simulator;
using sim::SimulatorOptions;

// The LiDAR pose from the simulated oxts packets (what a real drive offers), in sim seconds.
struct OxtsMotion {
  explicit OxtsMotion(const Simulator& s) : sim(s) {
    std::vector<OxtsPacket> packets;
    std::vector<StampNs> stamps;
    for (int i = 0; i < s.options().frames; ++i) {
      packets.push_back(s.SimulateOxts(i));
      stamps.push_back(s.Timing(i).oxts_stamp_ns);
    }
    EXPECT_TRUE(OxtsTrajectory::Create(packets, stamps, &trajectory).ok());
  }
  Rigid3d operator()(double t_sim) const {
    return trajectory.T_world_imu(sim.start_stamp_ns() + SecondsToNs(t_sim)) *
           sim.T_lidar_imu().inverse();
  }
  const Simulator& sim;
  OxtsTrajectory trajectory;
};

// A simulated drive of `frames` frames from `seed`, otherwise the defaults.
SimulatorOptions SimOptions(uint64_t seed, int frames) {
  SimulatorOptions options;
  options.seed = seed;
  options.frames = frames;
  return options;
}

// The two earlier sweeps the dynamic filter compares a simulated frame with (the adjacent one
// and the one 0.3 s back, as LoadLidarFrameFeatures picks them), their bases in `bases`.
std::vector<ReferenceFeatures> SimulatedReferences(const Simulator& s, const OxtsMotion& motion,
                                                   int frame, const LidarFeatureOptions& options,
                                                   std::vector<LidarFrameFeatures>* bases) {
  bases->clear();
  for (int gap : {1, 3}) {
    bases->push_back(ComputeLidarSweepBase(s.SimulateSweep(frame - gap).scan,
                                           s.LidarMidTime(frame - gap), s.SweepDuration(), motion,
                                           options));
  }
  std::vector<ReferenceFeatures> references;
  for (int k = 0; k < 2; ++k) {
    ReferenceFeatures r;
    r.features = &(*bases)[k];
    r.T_current_reference = RelativeLidarPose(motion, s.LidarMidTime(frame), (*bases)[k].stamp_s);
    r.check_visibility = k == 1;
    references.push_back(r);
  }
  return references;
}

TEST(OxtsTrajectory, RelativePosesMatchTheSimulatedTruth) {
  const Simulator s(SimOptions(21, 30));
  const OxtsMotion motion(s);
  for (double t : {0.3, 1.234, 2.05, 2.9}) {
    for (double dt : {0.0105, 0.05, 0.1, -0.1}) {
      const Rigid3d truth =
          s.trajectory().T_world_imu(t).inverse() * s.trajectory().T_world_imu(t + dt);
      const Rigid3d estimate =
          (motion(t) * s.T_lidar_imu()).inverse() * (motion(t + dt) * s.T_lidar_imu());
      // Within the simulated GPS/INS noise (1 cm position, 0.01° attitude per packet).
      EXPECT_LT((estimate.translation() - truth.translation()).norm(), 0.05) << t << " " << dt;
      EXPECT_LT(RotationErrorDeg(estimate.linear(), truth.linear()), 0.1) << t << " " << dt;
    }
  }
}

TEST(OxtsTrajectory, SkipsStalePacketsAndReportsGaps) {
  std::vector<OxtsPacket> packets(4);
  OxtsTrajectory trajectory;
  EXPECT_FALSE(OxtsTrajectory::Create(packets, {1, 2}, &trajectory).ok());
  EXPECT_FALSE(OxtsTrajectory::Create({}, {}, &trajectory).ok());
  // Packet 2 repeats packet 1's stamp, packet 3 goes back: both skipped.
  const int64_t s = 1000000000;  // 1 s in ns
  ASSERT_TRUE(OxtsTrajectory::Create(packets, {0, s / 10, s / 10, s / 20}, &trajectory).ok());
  EXPECT_EQ(trajectory.size(), 2u);
  ASSERT_TRUE(
      OxtsTrajectory::Create(packets, {0, s / 10, 4 * s / 10, 5 * s / 10}, &trajectory).ok());
  EXPECT_EQ(trajectory.size(), 4u);
  EXPECT_NEAR(trajectory.GapAround(0.05), 0.1, 1e-9);
  EXPECT_NEAR(trajectory.GapAround(0.2), 0.3, 1e-9);   // inside the stall
  EXPECT_NEAR(trajectory.GapAround(0.7), 0.2, 1e-9);   // beyond the last packet
  EXPECT_NEAR(trajectory.GapAround(-0.1), 0.1, 1e-9);  // before the first
}

// Without oxts the motion comes from registering consecutive sweeps (constant velocity between
// them): it must follow the oxts motion, which sim_test checks against the simulated truth.
TEST(DriveMotion, ScanRegistrationFollowsTheOxtsMotion) {
  testing::ScopedTempDir tmp;
  sim::SimulatorOptions options;
  options.seed = 5;
  options.frames = 8;
  options.dynamic_objects = 0;
  std::string drive_dir;
  ASSERT_TRUE(sim::WriteSimulatedDrive(options, tmp.path(), &drive_dir).ok());
  Drive drive;
  ASSERT_TRUE(OpenDrive(drive_dir, "", &drive).ok());
  DriveMotion oxts, scans;
  ASSERT_TRUE(DriveMotion::Create(drive, &oxts).ok());
  const Status status = DriveMotion::CreateFromScans(drive, &scans);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(scans.source(), DriveMotion::Source::kScanRegistration);
  EXPECT_EQ(scans.failed_registrations(), 0);
  auto relative = [&](const DriveMotion& m, StampNs a, StampNs b) {
    return m.T_world_lidar(m.Seconds(a)).inverse() * m.T_world_lidar(m.Seconds(b));
  };
  for (size_t k = 1; k < drive.NumFrames(); ++k) {
    const StampNs a = drive.lidar_stamps_ns[k - 1], b = drive.lidar_stamps_ns[k];
    const Rigid3d truth = relative(oxts, a, b), estimate = relative(scans, a, b);
    const Rigid3d error = truth.inverse() * estimate;
    EXPECT_LT(error.translation().norm(), 0.05) << "sweep " << k;
    EXPECT_LT(LogSO3(error.linear()).norm() * 180 / M_PI, 0.2) << "sweep " << k;
    // Between stamps (the image time): the constant-velocity twist.
    const double t_mid = 0.5 * (scans.Seconds(a) + scans.Seconds(b));
    const LidarTwist twist_scans = TwistFromPoses(scans.PoseFunction(), t_mid);
    const LidarTwist twist_oxts = TwistFromPoses(oxts.PoseFunction(), oxts.Seconds((a + b) / 2));
    EXPECT_LT((twist_scans.linear_m_s - twist_oxts.linear_m_s).norm(), 0.5) << "sweep " << k;
  }
  EXPECT_DOUBLE_EQ(scans.GapAround(scans.Seconds(drive.lidar_stamps_ns[3])), 0.0);
}

TEST(Deskew, PureTranslationMovesEachPointByItsOwnTime) {
  // The LiDAR moves along x at 10 m/s: a point captured 0.05 s after the stamp moves +0.5 m.
  const LidarPoseFunction pose = [](double t) {
    return MakeRigid(Eigen::Matrix3d::Identity(), Eigen::Vector3d(10.0 * t, 0, 0));
  };
  const std::vector<Eigen::Vector3d> points = {{5, 0, 0}, {5, 1, 0}, {-3, 2, 1}};
  const std::vector<double> times = {-0.05, 0.0, 0.05};
  const auto out = DeskewToStamp(points, times, 1.0, pose);
  EXPECT_NEAR(out[0].x(), 4.5, 1e-3);
  EXPECT_NEAR(out[1].x(), 5.0, 1e-3);
  EXPECT_NEAR(out[2].x(), -2.5, 1e-3);
  EXPECT_NEAR(out[2].z(), 1.0, 1e-12);
}

struct DynamicCounts {
  size_t dynamic = 0, dynamic_removed = 0, static_points = 0, static_removed = 0;
};

TEST(DynamicFilter, RemovesMovingObjectsAndKeepsStructure) {
  DynamicCounts total;
  for (uint64_t seed : {1u, 2u, 9u}) {
    const Simulator s(SimOptions(seed, 30));
    const OxtsMotion motion(s);
    const LidarFeatureOptions feature_options;
    for (int frame : {3, 14, 27}) {
      std::vector<LidarFrameFeatures> bases;
      const std::vector<ReferenceFeatures> references =
          SimulatedReferences(s, motion, frame, feature_options, &bases);
      const double t = s.LidarMidTime(frame);
      const sim::SimulatedSweep sweep = s.SimulateSweep(frame);
      const LidarFrameFeatures f = ComputeLidarFrameFeatures(sweep.scan, t, s.SweepDuration(),
                                                             motion, references, feature_options);
      DynamicCounts c;
      for (size_t i = 0; i < sweep.scan.size(); ++i) {
        if (sweep.labels[i] == static_cast<uint8_t>(PointLabel::kDynamic)) {
          ++c.dynamic;
          c.dynamic_removed += f.dynamic.dynamic[i];
        } else if (sweep.labels[i] == static_cast<uint8_t>(PointLabel::kStatic)) {
          ++c.static_points;
          c.static_removed += f.dynamic.dynamic[i];
        }
      }
      std::printf("seed %llu frame %d: dynamic %zu, removed %.1f%%; static %zu, removed %.2f%%\n",
                  static_cast<unsigned long long>(seed), frame, c.dynamic,
                  100.0 * c.dynamic_removed / std::max<size_t>(c.dynamic, 1), c.static_points,
                  100.0 * c.static_removed / c.static_points);
      total.dynamic += c.dynamic;
      total.dynamic_removed += c.dynamic_removed;
      total.static_points += c.static_points;
      total.static_removed += c.static_removed;
    }
  }
  const double dynamic_rate = static_cast<double>(total.dynamic_removed) / total.dynamic;
  const double static_rate = static_cast<double>(total.static_removed) / total.static_points;
  std::printf("total: %.1f%% of %zu dynamic points removed, %.2f%% of %zu static points\n",
              100 * dynamic_rate, total.dynamic, 100 * static_rate, total.static_points);
  EXPECT_GT(total.dynamic, 2000u);
  EXPECT_GE(dynamic_rate, 0.90);
  EXPECT_LE(static_rate, 0.03);
}

// The camera-view window only saves work: every cluster that reaches into it is judged exactly
// as with the whole sweep (its points keep their verdicts, inside the window and out), and no
// cluster wholly outside it is removed. Checked with the window ahead and turned to the side.
TEST(DynamicFilter, ViewWindowJudgesItsClustersExactlyAsTheWholeSweep) {
  const Simulator s(SimOptions(2, 20));
  const OxtsMotion motion(s);
  const LidarFeatureOptions feature_options;
  int in_window_removed = 0, outside_removed_whole = 0;
  for (int frame : {4, 15}) {
    const double t = s.LidarMidTime(frame);
    std::vector<LidarFrameFeatures> bases;
    std::vector<ReferenceSweep> references;
    for (const ReferenceFeatures& r :
         SimulatedReferences(s, motion, frame, feature_options, &bases)) {
      references.push_back(
          {&r.features->deskewed, &r.features->ground, r.T_current_reference, r.check_visibility});
    }
    const LidarFrameFeatures current = ComputeLidarSweepBase(
        s.SimulateSweep(frame).scan, t, s.SweepDuration(), motion, feature_options);
    const DynamicFilterResult whole =
        DetectDynamicPoints(current.deskewed, current.ground, references, feature_options.dynamic);
    for (double center_deg : {0.0, 90.0}) {
      DynamicFilterOptions windowed = feature_options.dynamic;
      windowed.roi_center_azimuth_deg = center_deg;
      windowed.roi_half_angle_deg = 45;
      const DynamicFilterResult view =
          DetectDynamicPoints(current.deskewed, current.ground, references, windowed);
      ASSERT_EQ(view.dynamic.size(), whole.dynamic.size());
      for (size_t i = 0; i < whole.dynamic.size(); ++i) {
        const Eigen::Vector3d& p = current.deskewed[i];
        const double azimuth_deg = std::atan2(p.y(), p.x()) * 180.0 / M_PI;
        const bool inside = std::abs(std::remainder(azimuth_deg - center_deg, 360.0)) <= 45.0;
        if (inside) {
          ASSERT_EQ(view.dynamic[i], whole.dynamic[i]) << "frame " << frame << " point " << i;
          in_window_removed += view.dynamic[i];
        } else {
          // Outside: removed only with a cluster that reaches in, and then as with the whole.
          ASSERT_LE(view.dynamic[i], whole.dynamic[i]) << "frame " << frame << " point " << i;
          outside_removed_whole += whole.dynamic[i] && !view.dynamic[i];
        }
      }
    }
  }
  std::printf("removed inside the windows: %d points; outside, only by the whole sweep: %d\n",
              in_window_removed, outside_removed_whole);
  EXPECT_GT(in_window_removed, 50);      // the windows hold moving objects
  EXPECT_GT(outside_removed_whole, 50);  // and the window did leave clusters unjudged
}

// A car alone on an open road: no reference point lies near it, so its nearest neighbour is
// beyond τ and it is removed, even though the KD-tree is kept to the places a query can reach
// (here, none of the reference). The static block far behind keeps its points.
TEST(DynamicFilter, RemovesAMoverWithNoReferencePointNearby) {
  auto block = [](const Eigen::Vector3d& corner) {
    std::vector<Eigen::Vector3d> points;
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        for (int c = 0; c < 4; ++c) points.push_back(corner + 0.15 * Eigen::Vector3d(a, b, c));
      }
    }
    return points;
  };
  const std::vector<Eigen::Vector3d> car = block(Eigen::Vector3d(20, 0, 0));
  const std::vector<Eigen::Vector3d> wall = block(Eigen::Vector3d(-30, 10, 0));
  std::vector<Eigen::Vector3d> current = car;
  current.insert(current.end(), wall.begin(), wall.end());
  ReferenceSweep reference;
  reference.points = &wall;  // the car was elsewhere (out of range) in the reference sweep
  for (double half_angle_deg : {0.0, 45.0}) {
    DynamicFilterOptions options;
    options.roi_half_angle_deg = half_angle_deg;
    const DynamicFilterResult result = DetectDynamicPoints(current, {}, {reference}, options);
    for (size_t i = 0; i < current.size(); ++i) {
      EXPECT_EQ(result.dynamic[i], i < car.size() ? 1 : 0)
          << "point " << i << ", window " << half_angle_deg;
    }
    EXPECT_EQ(result.dynamic_clusters, 1);
  }
}

// The older reference is compared with its view (ReferenceSweep::check_visibility): a mover
// stands where that sweep saw through to a far wall, and is removed; a wall that a nearer
// object hid from that sweep has no neighbour either, but was never seen, and is kept. The
// hidden wall straddles the azimuth seam behind the sensor (±180°), where the range image's
// columns wrap.
TEST(DynamicFilter, OlderReferenceRemovesMoversWhereItSawThroughAndKeepsWhatItDidNotSee) {
  auto grid = [](const Eigen::Vector3d& corner, const Eigen::Vector3d& du,
                 const Eigen::Vector3d& dv, int n) {
    std::vector<Eigen::Vector3d> points;
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) points.push_back(corner + a * du + b * dv);
    }
    return points;
  };
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  // Current sweep: a car ahead-left, a wall 20 m behind (y from −0.2 to +0.25 m).
  const std::vector<Eigen::Vector3d> car = grid({15, 5, -0.5}, 0.15 * y, 0.15 * z, 8);
  const std::vector<Eigen::Vector3d> hidden = grid({-20, -0.2, -0.2}, 0.15 * y, 0.15 * z, 4);
  std::vector<Eigen::Vector3d> current = car;
  current.insert(current.end(), hidden.begin(), hidden.end());
  // Older sweep: a far wall behind the car's place, and an occluder 8 m behind the sensor.
  std::vector<Eigen::Vector3d> older = grid({32, 6, -2}, 0.12 * y - 0.04 * x, 0.12 * z, 40);
  const std::vector<Eigen::Vector3d> occluder = grid({-8, -0.6, -0.6}, 0.03 * y, 0.03 * z, 41);
  older.insert(older.end(), occluder.begin(), occluder.end());
  ReferenceSweep reference;
  reference.points = &older;
  reference.check_visibility = true;
  const DynamicFilterResult result =
      DetectDynamicPoints(current, {}, {reference}, DynamicFilterOptions());
  for (size_t i = 0; i < current.size(); ++i) {
    EXPECT_EQ(result.dynamic[i], i < car.size() ? 1 : 0) << "point " << i;
  }
  // Both lack a neighbour within τ: only the view tells them apart.
  EXPECT_EQ(result.dynamic_clusters, 1);
  // Without the visibility check the hidden wall goes too.
  reference.check_visibility = false;
  const DynamicFilterResult blind =
      DetectDynamicPoints(current, {}, {reference}, DynamicFilterOptions());
  EXPECT_EQ(blind.dynamic_clusters, 2);
  EXPECT_EQ(blind.removed_points, static_cast<int>(current.size()));
}

// A drive's LiDAR stamps are δ before the true capture times (docs/method.md §2), so a local map
// merged with the poses at the stamps puts an earlier sweep where the vehicle's motion between
// the stamps, not between the captures, says. While it accelerates or turns the two differ by
// centimetres at δ = 60 ms; RelativeLidarPoseRate places the points to first order in δ (the
// refinement does so at its start's δ). Against the simulated trajectory, with the oxts motion.
TEST(LocalMap, EarlierSweepsArePlacedAtTheTimeOffsetToFirstOrder) {
  const Simulator s(SimOptions(21, 30));
  const OxtsMotion motion(s);
  const double delta = 0.06;
  auto true_pose = [&](double t) {
    return s.trajectory().T_world_imu(t) * s.T_lidar_imu().inverse();
  };
  double worst_at_stamps = 0, worst_placed = 0;
  for (int frame : {5, 12, 19, 26}) {
    for (int back : {1, 2}) {
      const double t_current = s.LidarMidTime(frame), t_earlier = s.LidarMidTime(frame - back);
      const Rigid3d truth = true_pose(t_current).inverse() * true_pose(t_earlier);
      const Rigid3d at_stamps = RelativeLidarPose(motion, t_current - delta, t_earlier - delta);
      const Eigen::Matrix<double, 3, 4> rate =
          RelativeLidarPoseRate(motion, t_current - delta, t_earlier - delta);
      for (double range : {5.0, 15.0, 40.0}) {
        for (double azimuth_deg : {-60.0, 0.0, 60.0}) {
          for (double z : {-1.5, 0.5, 3.0}) {
            const double a = azimuth_deg * M_PI / 180.0;
            const Eigen::Vector3d p(range * std::cos(a), range * std::sin(a), z);
            const Eigen::Vector3d stamped = at_stamps * p;
            const Eigen::Vector3d placed = stamped + delta * (rate.leftCols<3>() * p + rate.col(3));
            worst_at_stamps = std::max(worst_at_stamps, (stamped - truth * p).norm());
            worst_placed = std::max(worst_placed, (placed - truth * p).norm());
          }
        }
      }
    }
  }
  std::printf("earlier sweeps' points, worst: %.1f mm at the stamps, %.1f mm placed at δ\n",
              1000 * worst_at_stamps, 1000 * worst_placed);
  EXPECT_GT(worst_at_stamps, 0.01);
  EXPECT_LT(worst_placed, 0.3 * worst_at_stamps);  // measured 205 mm and 41 mm

  // MergeEdges carries the rate into the map: ∂(T·p)/∂δ for a merged point, zero for the
  // current sweep's own.
  LidarEdges current, earlier;
  for (LidarEdges* edges : {&current, &earlier}) {
    edges->points_lidar.push_back(Eigen::Vector3d(12, -3, 0.5));
    edges->time_s.push_back(0.01);
    edges->kind.push_back(EdgeKind::kVertical);
    edges->source_index.push_back(7);
    edges->offset_rate.push_back(Eigen::Vector3d::Zero());
    edges->sweep_age.push_back(0);
    edges->fold.push_back(0);
  }
  const Rigid3d T = RelativeLidarPose(motion, 2.0, 1.8);
  Eigen::Matrix<double, 3, 4> rate = RelativeLidarPoseRate(motion, 2.0, 1.8);
  const LidarEdges map = MergeEdges(current, {{&earlier, T, rate, 2}});
  ASSERT_EQ(map.size(), 2u);
  EXPECT_EQ(map.sweep_age[0], 0);  // the current sweep's own point
  EXPECT_EQ(map.sweep_age[1], 2);
  EXPECT_EQ(map.offset_rate[0], Eigen::Vector3d::Zero());
  const Eigen::Vector3d p = earlier.points_lidar[0];
  EXPECT_LT((map.points_lidar[1] - T * p).norm(), 1e-12);
  EXPECT_LT((map.offset_rate[1] - (rate.leftCols<3>() * p + rate.col(3))).norm(), 1e-12);
  EXPECT_GT(map.offset_rate[1].norm(), 0.0);
  EXPECT_EQ(map.source_index[1], -1);
}

TEST(LocalMap, KittiMapOfThreeSweepsWithOxtsAndNdt) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  DriveMotion motion;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive, &motion));
  LidarFrameFeatures single;
  ASSERT_TRUE(LoadLidarFrameFeatures(drive, motion, 12, LidarFeatureOptions(), &single).ok());
  LidarEdges oxts_map, ndt_map;
  LocalMapStats oxts_stats, ndt_stats;
  LocalMapOptions map_options;
  ASSERT_TRUE(
      BuildLocalMap(drive, motion, 12, LidarFeatureOptions(), map_options, &oxts_map, &oxts_stats)
          .ok());
  map_options.use_ndt = true;
  ASSERT_TRUE(
      BuildLocalMap(drive, motion, 12, LidarFeatureOptions(), map_options, &ndt_map, &ndt_stats)
          .ok());
  EXPECT_EQ(oxts_stats.sweeps_used, 3);
  EXPECT_GT(oxts_map.size(), 2.5 * single.edges.size());
  ASSERT_EQ(ndt_stats.ndt_iterations.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    std::printf("NDT sweep %zu: %d iterations, %.3f m from the oxts pose\n", k,
                ndt_stats.ndt_iterations[k], ndt_stats.ndt_correction_m[k]);
    EXPECT_LT(ndt_stats.ndt_correction_m[k], 0.3);  // oxts poses are good to decimetres
  }
  // With the first sweep alone (frame 0) the map is just that sweep.
  LidarEdges first;
  map_options.use_ndt = false;
  ASSERT_TRUE(
      BuildLocalMap(drive, motion, 0, LidarFeatureOptions(), map_options, &first, &oxts_stats)
          .ok());
  EXPECT_EQ(oxts_stats.sweeps_used, 1);
}

// A local map wider than the cache's capacity: the cache grows to hold all its sweeps (it had
// freed the oldest ones while the map still pointed at them), and a backward pass keeps the
// cache bounded (it had kept every sweep).
TEST(SweepCache, HoldsAWideLocalMapAndStaysBoundedOnABackwardPass) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  DriveMotion motion;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive, &motion));
  LocalMapOptions map_options;
  map_options.sweeps = 10;
  LidarEdges narrow_map, wide_map;
  LocalMapStats narrow_stats, wide_stats;
  SweepCache narrow(drive, motion, LidarFeatureOptions(), /*capacity=*/4);
  SweepCache wide(drive, motion, LidarFeatureOptions(), /*capacity=*/16);
  ASSERT_TRUE(narrow.LocalMap(14, map_options, &narrow_map, &narrow_stats).ok());
  ASSERT_TRUE(wide.LocalMap(14, map_options, &wide_map, &wide_stats).ok());
  EXPECT_GE(narrow.capacity(), 11u);
  EXPECT_EQ(narrow_stats.sweeps_used, 10);
  EXPECT_EQ(wide_stats.sweeps_used, 10);
  ASSERT_EQ(narrow_map.size(), wide_map.size());
  ASSERT_GT(wide_map.size(), 0u);
  double worst_m = 0;
  for (size_t i = 0; i < wide_map.size(); ++i) {
    worst_m = std::max(worst_m, (narrow_map.points_lidar[i] - wide_map.points_lidar[i]).norm());
  }
  EXPECT_EQ(worst_m, 0.0);

  SweepCache backward(drive, motion, LidarFeatureOptions(), /*capacity=*/4);
  size_t most = 0;
  for (size_t frame = 20; frame-- > 0;) {
    const LidarFrameFeatures* features;
    ASSERT_TRUE(backward.Finished(frame, &features).ok());
    EXPECT_GT(features->edges.size(), 0u);
    most = std::max(most, backward.cached_sweeps());
  }
  // Finished sweeps from the one asked for to a capacity after it (capacity + 1); bases also
  // back to the long-baseline reference, 3 frames at 10 Hz (capacity + 4). Unbounded: 40.
  EXPECT_LE(most, 2 * backward.capacity() + 5);
  std::printf("backward pass over 20 sweeps: at most %zu cached (capacity %zu)\n", most,
              backward.capacity());
}

// A finished sweep takes its base's fields over instead of copying them: once finished, Base
// serves the finished entry (the same fields, bit for bit, as a fresh cache's base), the cache
// holds one entry for the sweep, and later sweeps' dynamic filters still read it.
TEST(SweepCache, AFinishedSweepIsItsOwnBase) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  DriveMotion motion;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive, &motion));
  SweepCache cache(drive, motion, LidarFeatureOptions());
  const LidarFrameFeatures *finished = nullptr, *base = nullptr;
  ASSERT_TRUE(cache.Finished(5, &finished).ok());
  const size_t cached = cache.cached_sweeps();
  ASSERT_TRUE(cache.Base(5, &base).ok());
  EXPECT_EQ(base, finished);
  EXPECT_EQ(cache.cached_sweeps(), cached);  // Base loaded nothing again
  ASSERT_GT(base->edges.size(), 0u);

  SweepCache fresh(drive, motion, LidarFeatureOptions());
  const LidarFrameFeatures* fresh_base = nullptr;
  ASSERT_TRUE(fresh.Base(5, &fresh_base).ok());
  EXPECT_TRUE(fresh_base->edges.points_lidar.empty());  // a base alone has no edges
  ASSERT_EQ(base->scan.size(), fresh_base->scan.size());
  ASSERT_GT(base->scan.size(), 0u);
  EXPECT_EQ(base->scan.points_lidar, fresh_base->scan.points_lidar);
  EXPECT_EQ(base->deskewed, fresh_base->deskewed);
  EXPECT_EQ(base->ground, fresh_base->ground);
  EXPECT_EQ(base->point_time_s, fresh_base->point_time_s);
  EXPECT_EQ(base->rings.range_m, fresh_base->rings.range_m);

  // Frame 6's filter reads frame 5 (finished) as its reference: the same result as from a cache
  // that finished nothing before.
  const LidarFrameFeatures *next = nullptr, *fresh_next = nullptr;
  ASSERT_TRUE(cache.Finished(6, &next).ok());
  SweepCache other(drive, motion, LidarFeatureOptions());
  ASSERT_TRUE(other.Finished(6, &fresh_next).ok());
  EXPECT_EQ(next->dynamic.dynamic, fresh_next->dynamic.dynamic);
  EXPECT_EQ(next->edges.points_lidar, fresh_next->edges.points_lidar);
}

// A cache that releases the capture fields of finished sweeps and holds the least capacity (the
// frame source's) gives every local map of a sequential pass bit for bit as one that keeps them,
// and its finished sweeps still hold what later sweeps read (de-skewed points, ground, edges) but
// no scan.
TEST(SweepCache, ReleasingCaptureFieldsChangesNoLocalMap) {
  STCALIB_REQUIRE_KITTI();
  Drive drive;
  DriveMotion motion;
  ASSERT_TRUE(testing::OpenKittiDrive(&drive, &motion));
  SweepCache keeping(drive, motion, LidarFeatureOptions());
  // The least capacity (the frame source's) holds a sequential pass's local maps and long-baseline
  // references: every sweep is read once.
  SweepCache releasing(drive, motion, LidarFeatureOptions(), /*capacity=*/0);
  releasing.ReleaseCaptureFieldsOnceFinished();
  const LocalMapOptions map_options;  // 3 sweeps
  for (size_t frame = 0; frame < 8; ++frame) {
    LidarEdges kept_map, released_map;
    LocalMapStats kept_stats, released_stats;
    ASSERT_TRUE(keeping.LocalMap(frame, map_options, &kept_map, &kept_stats).ok());
    ASSERT_TRUE(releasing.LocalMap(frame, map_options, &released_map, &released_stats).ok());
    ASSERT_GT(kept_map.size(), 0u) << frame;
    EXPECT_EQ(released_stats.sweeps_used, kept_stats.sweeps_used) << frame;
    EXPECT_EQ(released_map.points_lidar, kept_map.points_lidar) << frame;
    EXPECT_EQ(released_map.kind, kept_map.kind) << frame;
    EXPECT_EQ(released_map.offset_rate, kept_map.offset_rate) << frame;
    EXPECT_EQ(released_map.fold, kept_map.fold) << frame;
    EXPECT_EQ(released_map.sweep_age, kept_map.sweep_age) << frame;
  }
  EXPECT_EQ(releasing.sweeps_loaded(), 8u);
  EXPECT_LT(releasing.capacity(), keeping.capacity());
  const LidarFrameFeatures *kept = nullptr, *released = nullptr;
  ASSERT_TRUE(keeping.Finished(7, &kept).ok());
  ASSERT_TRUE(releasing.Finished(7, &released).ok());
  EXPECT_GT(kept->scan.size(), 0u);
  EXPECT_EQ(released->scan.size(), 0u);
  EXPECT_TRUE(released->point_time_s.empty());
  EXPECT_EQ(released->rings.num_rings(), -1);
  EXPECT_EQ(released->deskewed, kept->deskewed);
  EXPECT_EQ(released->ground, kept->ground);
  EXPECT_EQ(released->dynamic.dynamic, kept->dynamic.dynamic);
}

// The dynamic filter's range image bins FastAtan2's angles: within 2e-11 rad of std::atan2 over
// every octant, at the octant borders and the reduction's switch (tan π/8), and within 1e-15 rad
// with the same sign on the axes and signed zeros.
TEST(DynamicFilter, FastAtan2MatchesLibmToTenDecimals) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-60.0, 60.0);
  std::vector<std::pair<double, double>> yx;
  for (int i = 0; i < 500000; ++i) yx.emplace_back(coordinate(rng), coordinate(rng));
  for (int k = 0; k <= 4000; ++k) {
    const double t = k / 4000.0;
    for (double sy : {-1.0, 1.0}) {
      for (double sx : {-1.0, 1.0}) {
        yx.emplace_back(sy * t, sx * 1.0);
        yx.emplace_back(sy * 1.0, sx * t);
      }
    }
  }
  yx.emplace_back(0.41421356237309504880, 1.0);
  double worst = 0;
  for (const auto& [y, x] : yx)
    worst = std::max(worst, std::abs(FastAtan2(y, x) - std::atan2(y, x)));
  EXPECT_LT(worst, 2e-11);
  EXPECT_GT(worst, 0.0);  // an approximation, not libm's
  for (const auto& [y, x] : std::vector<std::pair<double, double>>{{0.0, 0.0},
                                                                   {-0.0, 0.0},
                                                                   {0.0, -0.0},
                                                                   {-0.0, -0.0},
                                                                   {0.0, -3.0},
                                                                   {-0.0, -3.0},
                                                                   {0.0, 2.0},
                                                                   {5.0, 0.0},
                                                                   {-5.0, 0.0},
                                                                   {1.0, 1.0},
                                                                   {-1.0, -1.0}}) {
    const double expected = std::atan2(y, x);
    EXPECT_NEAR(FastAtan2(y, x), expected, 1e-15) << y << ", " << x;
    EXPECT_EQ(std::signbit(FastAtan2(y, x)), std::signbit(expected)) << y << ", " << x;
  }
}

}  // namespace
}  // namespace stcalib
