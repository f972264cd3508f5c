#pragma once

#include <map>
#include <vector>

#include "core/features/dynamic_filter.h"
#include "core/features/ground.h"
#include "core/features/lidar_edges.h"
#include "core/features/lidar_rings.h"
#include "core/io/drive.h"
#include "core/motion/drive_motion.h"
#include "core/pcl/registration.h"

namespace stcalib {

struct LidarFeatureOptions {
  GroundOptions ground;
  LidarEdgeOptions edges;
  DynamicFilterOptions dynamic;
  bool remove_dynamic = true;  ///< run the dynamic filter against earlier sweeps

  Status Validate() const;
};

// Everything the calibrator needs from one sweep, in the LiDAR frame at the sweep stamp.
struct LidarFrameFeatures {
  LidarScan scan;      ///< as read (scan order, capture-time geometry)
  double stamp_s = 0;  ///< LiDAR stamp, DriveMotion seconds
  ScanRings rings;
  std::vector<double> point_time_s;       ///< capture time of each point relative to the stamp
  std::vector<Eigen::Vector3d> deskewed;  ///< every point moved to the stamp
  GroundPlane ground_plane;
  std::vector<uint8_t> ground;  ///< 1 = ground
  DynamicFilterResult dynamic;  ///< empty `dynamic` when not run
  LidarEdges edges;  ///< de-skewed to the stamp; time_s keeps each point's capture offset
};

// The first stage of a sweep: rings, per-point times, de-skew and ground. No edges yet.
LidarFrameFeatures ComputeLidarSweepBase(LidarScan scan, double stamp_s, double sweep_duration_s,
                                         const LidarPoseFunction& T_world_lidar,
                                         const LidarFeatureOptions& options);

// An earlier sweep for the dynamic filter, with its pose in the current sweep's frame.
struct ReferenceFeatures {
  const LidarFrameFeatures* features = nullptr;
  Rigid3d T_current_reference = Rigid3d::Identity();
  bool check_visibility = false;
};

// The second stage: the dynamic filter against `references` (when enabled and not empty), then
// the edges, which skip ground and dynamic points.
void FinishLidarFrameFeatures(const std::vector<ReferenceFeatures>& references,
                              const LidarFeatureOptions& options, LidarFrameFeatures* features);

// Both stages in one call.
LidarFrameFeatures ComputeLidarFrameFeatures(LidarScan scan, double stamp_s,
                                             double sweep_duration_s,
                                             const LidarPoseFunction& T_world_lidar,
                                             const std::vector<ReferenceFeatures>& references,
                                             const LidarFeatureOptions& options);

// Local map (docs/method.md §4): the edges of `sweeps` consecutive sweeps ending at `frame`, merged
// into the frame of the last one, with oxts poses or, when `use_ndt` is set, refined by NDT.
struct LocalMapOptions {
  int sweeps = 3;
  bool use_ndt = false;
  NdtOptions ndt;
};
struct LocalMapStats {
  int sweeps_used = 0;
  std::vector<int> ndt_iterations;
  std::vector<double> ndt_correction_m;  ///< |t| of NDT's change to the oxts pose [m]
};
// Loads frame `frame` of a drive and computes its features; the dynamic filter compares with
// the previous sweep and with the sweep DynamicFilterOptions::long_baseline_s earlier.
Status LoadLidarFrameFeatures(const Drive& drive, const DriveMotion& motion, size_t frame,
                              const LidarFeatureOptions& options, LidarFrameFeatures* features);

// Sweeps of a drive computed once each and kept while they are among the last `capacity`
// frames asked for: a sequential pass computes every sweep's base and finished features once.
// The capacity grows to hold the dynamic filter's long-baseline reference and every sweep of a
// local map; a backward pass keeps at most a capacity of sweeps after the one asked for.
// Pointers handed out stay valid until the next call.
class SweepCache {
 public:
  SweepCache(const Drive& drive, const DriveMotion& motion, const LidarFeatureOptions& options,
             size_t capacity = 8);
  // The sweep's base fields (scan to ground); the dynamic marks and edges are set only when the
  // sweep is already finished, whose entry then serves them (one copy of each sweep).
  Status Base(size_t frame, const LidarFrameFeatures** features);
  Status Finished(size_t frame, const LidarFrameFeatures** features);  ///< with it, and edges
  // The previous sweep and the one DynamicFilterOptions::long_baseline_s back.
  Status References(size_t frame, std::vector<ReferenceFeatures>* references);
  Status LocalMap(size_t frame, const LocalMapOptions& map_options, LidarEdges* map,
                  LocalMapStats* stats);
  size_t capacity() const { return capacity_; }
  // From now on a sweep, once finished, gives up what only finishing reads: the scan as read, its
  // rings and per-point capture times (about 5.5 MB of a 64-beam sweep's 9 MB). Later readers of
  // a finished entry (the dynamic filter's references, the local map, NDT) read its de-skewed
  // points, ground mask and edges, which it keeps. For a caller that reads no other field.
  void ReleaseCaptureFieldsOnceFinished() { release_capture_fields_ = true; }
  size_t cached_sweeps() const { return base_.size() + finished_.size(); }  ///< base + finished
  size_t sweeps_loaded() const { return sweeps_loaded_; }  ///< sweeps read and based so far

 private:
  void Evict(size_t newest);
  void EvictNewerThan(size_t last);
  const Drive& drive_;
  const DriveMotion& motion_;
  const LidarFeatureOptions options_;
  double sweep_s_;
  size_t long_gap_;  ///< frames back to the long-baseline reference sweep
  size_t capacity_;
  bool release_capture_fields_ = false;
  size_t sweeps_loaded_ = 0;
  std::map<size_t, LidarFrameFeatures> base_, finished_;
};

Status BuildLocalMap(const Drive& drive, const DriveMotion& motion, size_t frame,
                     const LidarFeatureOptions& options, const LocalMapOptions& map_options,
                     LidarEdges* map, LocalMapStats* stats);

// An earlier sweep's edges and their pose in the current sweep's frame, with the pose's rate
// under a common shift of both stamps (RelativeLidarPoseRate; zero: none).
struct SweepInMap {
  const LidarEdges* edges = nullptr;
  Rigid3d T_current_previous = Rigid3d::Identity();
  Eigen::Matrix<double, 3, 4> offset_rate = Eigen::Matrix<double, 3, 4>::Zero();
  int age = 1;  ///< frames before the current sweep (LidarEdges::sweep_age, at most 255)
};

// Merges `previous` into `current`; a merged point's offset_rate is ∂(T·p)/∂δ.
LidarEdges MergeEdges(const LidarEdges& current, const std::vector<SweepInMap>& previous);

}  // namespace stcalib
