#include "core/features/lidar_frame.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>

namespace stcalib {

Status LidarFeatureOptions::Validate() const {
  STCALIB_RETURN_IF_ERROR(ground.Validate());
  STCALIB_RETURN_IF_ERROR(edges.Validate());
  return dynamic.Validate();
}

LidarFrameFeatures ComputeLidarSweepBase(LidarScan scan, double stamp_s, double sweep_duration_s,
                                         const LidarPoseFunction& T_world_lidar,
                                         const LidarFeatureOptions& options) {
  LidarFrameFeatures f;
  f.scan = std::move(scan);
  f.stamp_s = stamp_s;
  // A driver's rings and capture times, when the sweep carries them, over KITTI's derivations.
  f.rings = f.scan.ring.empty() ? SplitIntoRings(f.scan.points_lidar)
                                : RingsFromLabels(f.scan.points_lidar, f.scan.ring);
  // (The driver's times move here: the scan keeps no second copy.)
  f.point_time_s = f.scan.point_time_s.empty() ? PointTimesFromAzimuth(f.rings, sweep_duration_s)
                                               : std::move(f.scan.point_time_s);
  f.deskewed = DeskewToStamp(f.scan.points_lidar, f.point_time_s, stamp_s, T_world_lidar);
  f.ground_plane = FitGroundPlane(f.deskewed, options.ground);
  f.ground = GroundMask(f.deskewed, f.ground_plane, options.ground.band_m);
  return f;
}

void FinishLidarFrameFeatures(const std::vector<ReferenceFeatures>& references,
                              const LidarFeatureOptions& options, LidarFrameFeatures* f) {
  const size_t n = f->scan.size();
  std::vector<PointUse> use(n, PointUse::kUse);
  for (size_t i = 0; i < n; ++i) {
    if (f->ground[i]) use[i] = PointUse::kGround;
  }
  f->dynamic = DynamicFilterResult();
  if (options.remove_dynamic && !references.empty()) {
    std::vector<ReferenceSweep> sweeps;
    for (const ReferenceFeatures& r : references) {
      ReferenceSweep sweep;
      sweep.points = &r.features->deskewed;
      sweep.ground = &r.features->ground;
      sweep.T_current_reference = r.T_current_reference;
      sweep.check_visibility = r.check_visibility;
      sweeps.push_back(sweep);
    }
    f->dynamic = DetectDynamicPoints(f->deskewed, f->ground, sweeps, options.dynamic);
    for (size_t i = 0; i < n; ++i) {
      if (f->dynamic.dynamic[i]) use[i] = PointUse::kDynamic;
    }
  }
  f->edges = ExtractLidarEdges(f->scan, f->rings, f->point_time_s, &use, options.edges);
  for (size_t k = 0; k < f->edges.size(); ++k) {
    // Keep the bisector placement of the edge point, moved to the stamp like its source.
    const int i = f->edges.source_index[k];
    f->edges.points_lidar[k] =
        f->deskewed[i] + (f->edges.points_lidar[k] - f->scan.points_lidar[i]);
  }
}

LidarFrameFeatures ComputeLidarFrameFeatures(LidarScan scan, double stamp_s,
                                             double sweep_duration_s,
                                             const LidarPoseFunction& T_world_lidar,
                                             const std::vector<ReferenceFeatures>& references,
                                             const LidarFeatureOptions& options) {
  LidarFrameFeatures f =
      ComputeLidarSweepBase(std::move(scan), stamp_s, sweep_duration_s, T_world_lidar, options);
  FinishLidarFrameFeatures(references, options, &f);
  return f;
}

namespace {

// Frames back to the dynamic filter's long-baseline reference sweep.
size_t LongBaselineGap(const Drive& drive, const DynamicFilterOptions& dynamic) {
  const double period =
      drive.NumFrames() > 1
          ? NsToSeconds(drive.lidar_stamps_ns.back() - drive.lidar_stamps_ns.front()) /
                (drive.NumFrames() - 1)
          : 0.1;
  return std::max<size_t>(
      1, static_cast<size_t>(std::lround(dynamic.long_baseline_s / std::max(period, 1e-3))));
}

}  // namespace

SweepCache::SweepCache(const Drive& drive, const DriveMotion& motion,
                       const LidarFeatureOptions& options, size_t capacity)
    : drive_(drive),
      motion_(motion),
      options_(options),
      sweep_s_(SweepDurationSeconds(drive)),
      long_gap_(LongBaselineGap(drive, options.dynamic)),
      // The long-baseline reference stays cached from one frame to the next.
      capacity_(std::max<size_t>({capacity, 4, long_gap_ + 2})) {}

void SweepCache::Evict(size_t newest) {
  while (base_.size() > capacity_ && base_.begin()->first + capacity_ <= newest) {
    base_.erase(base_.begin());
  }
  while (finished_.size() > capacity_ && finished_.begin()->first + capacity_ <= newest) {
    finished_.erase(finished_.begin());
  }
}

void SweepCache::EvictNewerThan(size_t last) {
  while (!base_.empty() && base_.rbegin()->first > last) base_.erase(std::prev(base_.end()));
  while (!finished_.empty() && finished_.rbegin()->first > last) {
    finished_.erase(std::prev(finished_.end()));
  }
}

Status SweepCache::Base(size_t frame, const LidarFrameFeatures** features) {
  if (auto done = finished_.find(frame); done != finished_.end()) {  // holds the base's fields
    *features = &done->second;
    return Status::Ok();
  }
  auto it = base_.find(frame);
  if (it == base_.end()) {
    STCALIB_RETURN_IF_ERROR(drive_.CheckFrame(frame));
    LidarScan scan;
    STCALIB_RETURN_IF_ERROR(drive_.LoadScan(frame, &scan));
    if (scan.size() == 0) LOG(WARNING) << drive_.ScanName(frame) << ": empty sweep";
    const double stamp = motion_.Seconds(drive_.lidar_stamps_ns[frame]);
    ++sweeps_loaded_;
    it = base_
             .emplace(frame, ComputeLidarSweepBase(std::move(scan), stamp, sweep_s_,
                                                   motion_.PoseFunction(), options_))
             .first;
    Evict(frame);
  }
  *features = &it->second;
  return Status::Ok();
}

Status SweepCache::References(size_t frame, std::vector<ReferenceFeatures>* references) {
  references->clear();
  if (!options_.remove_dynamic || frame == 0) return Status::Ok();
  const LidarFrameFeatures* current;
  STCALIB_RETURN_IF_ERROR(Base(frame, &current));
  for (size_t gap : {size_t{1}, long_gap_}) {
    if (gap > frame || (gap == long_gap_ && long_gap_ == 1 && !references->empty())) continue;
    const LidarFrameFeatures* reference;
    const Status status = Base(frame - gap, &reference);
    if (!status.ok() || !(reference->stamp_s < current->stamp_s)) {
      // A dropped, unreadable or mis-stamped earlier sweep: compare with the others only.
      LOG(WARNING) << "dynamic filter of frame " << frame << ": reference sweep " << frame - gap
                   << " left out: "
                   << (status.ok() ? "its stamp is not before this sweep's" : status.message());
      continue;
    }
    ReferenceFeatures r;
    r.features = reference;
    r.T_current_reference =
        RelativeLidarPose(motion_.PoseFunction(), current->stamp_s, reference->stamp_s);
    r.check_visibility = gap > 1;
    references->push_back(r);
  }
  return Status::Ok();
}

Status SweepCache::Finished(size_t frame, const LidarFrameFeatures** features) {
  auto it = finished_.find(frame);
  if (it == finished_.end()) {
    std::vector<ReferenceFeatures> references;
    STCALIB_RETURN_IF_ERROR(References(frame, &references));
    const LidarFrameFeatures* base;
    STCALIB_RETURN_IF_ERROR(Base(frame, &base));
    // The finished sweep takes the base's fields over (finishing only adds the dynamic marks and
    // the edges) and Base serves them from then on: the sweep (~9 MB) is not copied.
    auto node = base_.extract(frame);
    CHECK(!node.empty() && &node.mapped() == base) << "sweep " << frame << " not in the cache";
    LidarFrameFeatures f = std::move(node.mapped());
    FinishLidarFrameFeatures(references, options_, &f);
    if (release_capture_fields_) {
      f.scan = LidarScan();
      f.rings = ScanRings();
      f.point_time_s = std::vector<double>();
    }
    it = finished_.emplace(frame, std::move(f)).first;
    Evict(frame);
    // A backward pass: sweeps more than a capacity after this one are not asked for again soon.
    // (Not in Base: References holds this sweep's base while it loads one `long_gap_` back.)
    EvictNewerThan(frame + capacity_);
  }
  *features = &it->second;
  return Status::Ok();
}

Status LoadLidarFrameFeatures(const Drive& drive, const DriveMotion& motion, size_t frame,
                              const LidarFeatureOptions& options, LidarFrameFeatures* features) {
  STCALIB_RETURN_IF_ERROR(options.Validate());
  STCALIB_RETURN_IF_ERROR(drive.CheckFrame(frame));
  SweepCache cache(drive, motion, options);
  const LidarFrameFeatures* finished;
  STCALIB_RETURN_IF_ERROR(cache.Finished(frame, &finished));
  *features = *finished;
  return Status::Ok();
}

LidarEdges MergeEdges(const LidarEdges& current, const std::vector<SweepInMap>& previous) {
  LidarEdges map = current;
  for (const SweepInMap& sweep : previous) {
    CHECK_EQ(sweep.edges->offset_rate.size(), sweep.edges->size());
    LidarEdges moved = *sweep.edges;
    const Rigid3d& T = sweep.T_current_previous;
    for (size_t i = 0; i < moved.size(); ++i) {
      const Eigen::Vector3d& p = sweep.edges->points_lidar[i];
      moved.offset_rate[i] = T.linear() * moved.offset_rate[i] +
                             sweep.offset_rate.leftCols<3>() * p + sweep.offset_rate.col(3);
      moved.points_lidar[i] = T * p;
      moved.source_index[i] = -1;
      moved.sweep_age[i] = static_cast<uint8_t>(std::clamp(sweep.age, 0, 255));
    }
    map.Append(moved);
  }
  return map;
}

Status BuildLocalMap(const Drive& drive, const DriveMotion& motion, size_t frame,
                     const LidarFeatureOptions& options, const LocalMapOptions& map_options,
                     LidarEdges* map, LocalMapStats* stats) {
  STCALIB_RETURN_IF_ERROR(options.Validate());
  SweepCache cache(drive, motion, options);
  return cache.LocalMap(frame, map_options, map, stats);
}

Status SweepCache::LocalMap(size_t frame, const LocalMapOptions& map_options, LidarEdges* map,
                            LocalMapStats* stats) {
  STCALIB_RETURN_IF_ERROR(drive_.CheckFrame(frame));
  if (map_options.sweeps < 1) return Status::Error("local map: sweeps must be >= 1");
  // Every sweep of the map stays cached while the map holds pointers to them.
  capacity_ = std::max(capacity_, static_cast<size_t>(map_options.sweeps) + 1);
  *stats = LocalMapStats();
  const size_t first =
      frame + 1 >= static_cast<size_t>(map_options.sweeps) ? frame + 1 - map_options.sweeps : 0;
  const LidarFrameFeatures* current_features;
  STCALIB_RETURN_IF_ERROR(Finished(frame, &current_features));
  const LidarFrameFeatures& current = *current_features;
  std::vector<const LidarFrameFeatures*> sweeps;
  std::vector<int> ages;  // frames before `frame`
  for (size_t k = first; k < frame; ++k) {
    const LidarFrameFeatures* f;
    const Status status = Finished(k, &f);
    if (!status.ok() || !(f->stamp_s < current.stamp_s)) {
      // A dropped, unreadable or mis-stamped earlier sweep: the map is built without it.
      LOG(WARNING) << "local map of frame " << frame << ": sweep " << k << " left out: "
                   << (status.ok() ? "its stamp is not before this sweep's" : status.message());
      continue;
    }
    sweeps.push_back(f);
    ages.push_back(static_cast<int>(frame - k));
  }
  sweeps.push_back(current_features);
  std::vector<SweepInMap> previous;
  for (size_t k = 0; k + 1 < sweeps.size(); ++k) {
    Rigid3d T = RelativeLidarPose(motion_.PoseFunction(), current.stamp_s, sweeps[k]->stamp_s);
    if (map_options.use_ndt) {
      std::vector<Eigen::Vector3d> source, target;
      for (size_t i = 0; i < sweeps[k]->deskewed.size(); ++i) {
        if (!sweeps[k]->ground[i]) source.push_back(sweeps[k]->deskewed[i]);
      }
      for (size_t i = 0; i < current.deskewed.size(); ++i) {
        if (!current.ground[i]) target.push_back(current.deskewed[i]);
      }
      RegistrationResult result;
      STCALIB_RETURN_IF_ERROR(RegisterNdt(source, target, T, map_options.ndt, &result));
      stats->ndt_iterations.push_back(result.iterations);
      stats->ndt_correction_m.push_back(
          (result.T_target_source.translation() - T.translation()).norm());
      T = result.T_target_source;
    }
    // Poses from the oxts (or odometry), looked up at the LiDAR stamps, are off with δ; NDT and a
    // motion from scan registration relate the sweeps themselves, so their relative pose holds at
    // any δ.
    SweepInMap sweep{&sweeps[k]->edges, T};
    sweep.age = ages[k];
    if (!map_options.use_ndt && motion_.measured()) {
      sweep.offset_rate =
          RelativeLidarPoseRate(motion_.PoseFunction(), current.stamp_s, sweeps[k]->stamp_s);
    }
    previous.push_back(sweep);
  }
  *map = MergeEdges(current.edges, previous);
  stats->sweeps_used = static_cast<int>(sweeps.size());
  return Status::Ok();
}

}  // namespace stcalib
