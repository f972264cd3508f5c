#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/types/status.h"
#include "core/types/transform.h"

namespace stcalib {

// Dynamic points (docs/method.md §5): with the previous sweep motion-compensated into the current
// one, a static point finds a close neighbour in it and a moving one does not. Points farther than
// τ(r) = τ0 + k·r from their nearest previous neighbour (KD-tree) are flagged — but only where the
// previous sweep saw through that place (its range in that direction, seen from its own viewpoint,
// is longer): structure that was merely hidden before (disocclusion) is not moving. The current
// non-ground points are clustered (Euclidean, on a voxel grid) and whole clusters with enough
// flagged points are removed.
struct DynamicFilterOptions {
  double tau0_m = 0.15;          ///< τ0 [m]
  double tau_per_range = 0.008;  ///< k [m/m]: beam spacing grows with range
  double max_range_m = 80.0;     ///< points beyond are left alone [m]
  // The camera's view, as an azimuth window |azimuth − centre| ≤ half angle: only clusters that
  // reach into it are judged, each exactly as without the window (all its points, against the
  // whole reference); clusters wholly outside it are left unjudged (kept). 0 = judge all [deg].
  double roi_half_angle_deg = 0.0;
  double roi_center_azimuth_deg = 0.0;  ///< LiDAR azimuth of the window's centre [deg]
  double cluster_tolerance_m = 0.45;    ///< voxel size of the clustering [m]
  int min_flagged_points = 6;           ///< a dynamic cluster has at least this many flagged
  double min_flagged_fraction = 0.12;   ///< ... and at least this share of its points flagged
  double max_cluster_extent_m = 14.0;   ///< larger clusters are structure, never removed [m]
  double visibility_margin_m = 0.3;     ///< previous range must exceed ours by this (+2 %) [m]
  // Slow movers (pedestrians) shift less than τ between adjacent sweeps; a second, older
  // reference sweep this far back, compared with the visibility check, catches them [s].
  double long_baseline_s = 0.3;
  // Speed: reference sweeps keep one point per voxel of this size, and current points sharing a
  // voxel share one nearest-neighbour query [m].
  double reference_voxel_m = 0.0;
  double query_voxel_m = 0.0;

  Status Validate() const;
};

struct DynamicFilterResult {
  std::vector<uint8_t> dynamic;  ///< one per current point: 1 = removed as dynamic
  // Points beyond τ(r), among the clusters judged: in the view, no wider than
  // max_cluster_extent_m and with at least min_flagged_points points (no other can be removed,
  // so no other is queried).
  int flagged_points = 0;
  int clusters = 0;  ///< clusters found
  int dynamic_clusters = 0;
  int removed_points = 0;
};

// An earlier sweep to compare with: de-skewed points in its own frame, its ground mask (may be
// empty) and its pose in the current sweep's frame. The adjacent sweep is compared without the
// visibility check (fast movers), older ones with it.
struct ReferenceSweep {
  const std::vector<Eigen::Vector3d>* points = nullptr;
  const std::vector<uint8_t>* ground = nullptr;
  Rigid3d T_current_reference = Rigid3d::Identity();
  bool check_visibility = false;
};

// `current` is de-skewed; a point is flagged when any reference flags it.
DynamicFilterResult DetectDynamicPoints(const std::vector<Eigen::Vector3d>& current,
                                        const std::vector<uint8_t>& current_ground,
                                        const std::vector<ReferenceSweep>& references,
                                        const DynamicFilterOptions& options);

}  // namespace stcalib
