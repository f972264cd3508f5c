#include "core/features/lidar_frame.h"

#include <glog/logging.h>

namespace stcalib {

Status LidarFeatureOptions::Validate() const {
  STCALIB_RETURN_IF_ERROR(ground.Validate());
  STCALIB_RETURN_IF_ERROR(edges.Validate());
  return dynamic.Validate();
}

LidarFrameFeatures ComputeLidarFrameFeatures(const LidarScan& scan, double stamp_s,
                                             double sweep_duration_s,
                                             const LidarPoseFunction& T_world_lidar,
                                             const LidarFrameFeatures* previous,
                                             const Rigid3d& T_current_previous,
                                             const LidarFeatureOptions& options) {
  LidarFrameFeatures f;
  f.stamp_s = stamp_s;
  f.rings = SplitIntoRings(scan.points_lidar);
  f.point_time_s = PointTimesFromAzimuth(f.rings, sweep_duration_s);
  f.deskewed = DeskewToStamp(scan.points_lidar, f.point_time_s, stamp_s, T_world_lidar);
  f.ground_plane = FitGroundPlane(f.deskewed, options.ground);
  f.ground = GroundMask(f.deskewed, f.ground_plane, options.ground.band_m);

  std::vector<PointUse> use(scan.size(), PointUse::kUse);
  for (size_t i = 0; i < scan.size(); ++i) {
    if (f.ground[i]) use[i] = PointUse::kGround;
  }
  if (previous != nullptr && options.remove_dynamic) {
    std::vector<Eigen::Vector3d> previous_in_current(previous->deskewed.size());
    for (size_t i = 0; i < previous_in_current.size(); ++i) {
      previous_in_current[i] = T_current_previous * previous->deskewed[i];
    }
    f.dynamic = DetectDynamicPoints(f.deskewed, f.ground, previous_in_current, previous->ground,
                                    options.dynamic);
    for (size_t i = 0; i < scan.size(); ++i) {
      if (f.dynamic.dynamic[i]) use[i] = PointUse::kDynamic;
    }
  }
  f.edges = ExtractLidarEdges(scan, f.rings, f.point_time_s, &use, options.edges);
  for (size_t k = 0; k < f.edges.size(); ++k) {
    f.edges.points_lidar[k] = f.deskewed[f.edges.source_index[k]];
  }
  return f;
}

namespace {

Status LoadBase(const Drive& drive, const DriveMotion& motion, size_t frame, double sweep_s,
                const LidarFeatureOptions& options, const LidarFrameFeatures* previous,
                LidarFrameFeatures* out) {
  LidarScan scan;
  STCALIB_RETURN_IF_ERROR(drive.LoadScan(frame, &scan));
  if (scan.size() == 0) LOG(WARNING) << drive.VelodynePath(frame) << ": empty sweep";
  const double stamp = motion.Seconds(drive.lidar_stamps_ns[frame]);
  const Rigid3d T_current_previous =
      previous == nullptr ? Rigid3d::Identity()
                          : RelativeLidarPose(motion.PoseFunction(), stamp, previous->stamp_s);
  *out = ComputeLidarFrameFeatures(scan, stamp, sweep_s, motion.PoseFunction(), previous,
                                   T_current_previous, options);
  return Status::Ok();
}

}  // namespace

Status LoadLidarFrameFeatures(const Drive& drive, const DriveMotion& motion, size_t frame,
                              const LidarFeatureOptions& options, LidarFrameFeatures* features) {
  STCALIB_RETURN_IF_ERROR(options.Validate());
  STCALIB_RETURN_IF_ERROR(drive.CheckFrame(frame));
  const double sweep_s = SweepDurationSeconds(drive);
  if (frame == 0 || !options.remove_dynamic) {
    return LoadBase(drive, motion, frame, sweep_s, options, nullptr, features);
  }
  LidarFeatureOptions base = options;
  base.remove_dynamic = false;
  LidarFrameFeatures previous;
  STCALIB_RETURN_IF_ERROR(LoadBase(drive, motion, frame - 1, sweep_s, base, nullptr, &previous));
  return LoadBase(drive, motion, frame, sweep_s, options, &previous, features);
}

LidarEdges MergeEdges(const LidarEdges& current,
                      const std::vector<std::pair<const LidarEdges*, Rigid3d>>& previous) {
  LidarEdges map = current;
  for (const auto& [edges, T_current_previous] : previous) {
    LidarEdges moved = *edges;
    for (size_t i = 0; i < moved.size(); ++i) {
      moved.points_lidar[i] = T_current_previous * moved.points_lidar[i];
      moved.source_index[i] = -1;
    }
    map.Append(moved);
  }
  return map;
}

Status BuildLocalMap(const Drive& drive, const DriveMotion& motion, size_t frame,
                     const LidarFeatureOptions& options, const LocalMapOptions& map_options,
                     LidarEdges* map, LocalMapStats* stats) {
  STCALIB_RETURN_IF_ERROR(options.Validate());
  STCALIB_RETURN_IF_ERROR(drive.CheckFrame(frame));
  if (map_options.sweeps < 1) return Status::Error("local map: sweeps must be >= 1");
  *stats = LocalMapStats();
  const double sweep_s = SweepDurationSeconds(drive);
  const size_t first = frame + 1 >= static_cast<size_t>(map_options.sweeps)
                           ? frame + 1 - map_options.sweeps
                           : 0;
  // Sweeps first-1 .. frame; each sweep's dynamic filter uses the one before it.
  LidarFeatureOptions base = options;
  base.remove_dynamic = false;
  std::vector<LidarFrameFeatures> sweeps;
  LidarFrameFeatures before;
  const bool have_before = first > 0 && options.remove_dynamic;
  if (have_before) {
    STCALIB_RETURN_IF_ERROR(LoadBase(drive, motion, first - 1, sweep_s, base, nullptr, &before));
  }
  for (size_t k = first; k <= frame; ++k) {
    const LidarFrameFeatures* previous =
        k == first ? (have_before ? &before : nullptr) : &sweeps.back();
    LidarFrameFeatures f;
    STCALIB_RETURN_IF_ERROR(LoadBase(drive, motion, k, sweep_s,
                                     previous != nullptr ? options : base, previous, &f));
    sweeps.push_back(std::move(f));
  }
  const LidarFrameFeatures& current = sweeps.back();
  std::vector<std::pair<const LidarEdges*, Rigid3d>> previous;
  for (size_t k = 0; k + 1 < sweeps.size(); ++k) {
    Rigid3d T = RelativeLidarPose(motion.PoseFunction(), current.stamp_s, sweeps[k].stamp_s);
    if (map_options.use_ndt) {
      std::vector<Eigen::Vector3d> source, target;
      for (size_t i = 0; i < sweeps[k].deskewed.size(); ++i) {
        if (!sweeps[k].ground[i]) source.push_back(sweeps[k].deskewed[i]);
      }
      for (size_t i = 0; i < current.deskewed.size(); ++i) {
        if (!current.ground[i]) target.push_back(current.deskewed[i]);
      }
      RegistrationResult result;
      STCALIB_RETURN_IF_ERROR(RegisterNdt(source, target, T, map_options.ndt, &result));
      stats->ndt_iterations.push_back(result.iterations);
      stats->ndt_correction_m.push_back((result.T_target_source.translation() - T.translation()).norm());
      T = result.T_target_source;
    }
    previous.emplace_back(&sweeps[k].edges, T);
  }
  *map = MergeEdges(current.edges, previous);
  stats->sweeps_used = static_cast<int>(sweeps.size());
  return Status::Ok();
}

}  // namespace stcalib
