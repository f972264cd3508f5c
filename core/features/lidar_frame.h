#pragma once

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
  bool remove_dynamic = true;  ///< run the dynamic filter against the previous sweep

  Status Validate() const;
};

// Everything the calibrator needs from one sweep, in the LiDAR frame at the sweep stamp.
struct LidarFrameFeatures {
  double stamp_s = 0;                      ///< LiDAR stamp, DriveMotion seconds
  ScanRings rings;
  std::vector<double> point_time_s;        ///< capture time of each point relative to the stamp
  std::vector<Eigen::Vector3d> deskewed;   ///< every point moved to the stamp
  GroundPlane ground_plane;
  std::vector<uint8_t> ground;             ///< 1 = ground
  DynamicFilterResult dynamic;             ///< empty `dynamic` when not run
  LidarEdges edges;  ///< de-skewed to the stamp; time_s keeps each point's capture offset
};

// One sweep: rings, per-point times, de-skew, ground, dynamic filter (when `previous` is given:
// the previous sweep's features and its pose in this sweep's frame), edges.
LidarFrameFeatures ComputeLidarFrameFeatures(const LidarScan& scan, double stamp_s,
                                             double sweep_duration_s,
                                             const LidarPoseFunction& T_world_lidar,
                                             const LidarFrameFeatures* previous,
                                             const Rigid3d& T_current_previous,
                                             const LidarFeatureOptions& options);

// Loads frame `frame` of a drive (and frame − 1 for the dynamic filter) and computes its features.
Status LoadLidarFrameFeatures(const Drive& drive, const DriveMotion& motion, size_t frame,
                              const LidarFeatureOptions& options, LidarFrameFeatures* features);

// Local map (method.md §4): the edges of `sweeps` consecutive sweeps ending at `frame`, merged
// into the frame of the last one, with oxts poses or, when `ndt` is set, poses refined by NDT.
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
Status BuildLocalMap(const Drive& drive, const DriveMotion& motion, size_t frame,
                     const LidarFeatureOptions& options, const LocalMapOptions& map_options,
                     LidarEdges* map, LocalMapStats* stats);

// Merges `previous` (each with its pose in the current frame) into `current`.
LidarEdges MergeEdges(const LidarEdges& current,
                      const std::vector<std::pair<const LidarEdges*, Rigid3d>>& previous);

}  // namespace stcalib
