#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/types/status.h"

namespace stcalib {

// Dynamic points (method.md §5): with the previous sweep motion-compensated into the current one,
// a static point finds a close neighbour in it and a moving one does not. Points farther than
// τ(r) = τ0 + k·r from their nearest previous neighbour are flagged; the current non-ground
// points are clustered (Euclidean, on a voxel grid) and whole clusters with enough flagged points
// are removed.
struct DynamicFilterOptions {
  double tau0_m = 0.15;                 ///< τ0 [m]
  double tau_per_range = 0.008;         ///< k [m/m]: beam spacing grows with range
  double max_range_m = 80.0;            ///< points beyond are left alone [m]
  double roi_half_angle_deg = 0.0;      ///< only |azimuth| ≤ this (camera view); 0 = all
  double cluster_tolerance_m = 0.45;    ///< voxel size of the clustering [m]
  int min_flagged_points = 6;           ///< a dynamic cluster has at least this many flagged
  double min_flagged_fraction = 0.12;   ///< ... and at least this share of its points flagged
  double max_cluster_extent_m = 14.0;   ///< larger clusters are structure, never removed [m]

  Status Validate() const;
};

struct DynamicFilterResult {
  std::vector<uint8_t> dynamic;  ///< one per current point: 1 = removed as dynamic
  int flagged_points = 0;        ///< points beyond τ(r)
  int clusters = 0;              ///< clusters examined
  int dynamic_clusters = 0;
  int removed_points = 0;
};

// `current` and `previous_in_current` are de-skewed; the previous sweep is expressed in the
// current sweep's frame. Ground masks (1 = ground) exclude ground from both; either may be empty.
DynamicFilterResult DetectDynamicPoints(const std::vector<Eigen::Vector3d>& current,
                                        const std::vector<uint8_t>& current_ground,
                                        const std::vector<Eigen::Vector3d>& previous_in_current,
                                        const std::vector<uint8_t>& previous_ground,
                                        const DynamicFilterOptions& options);

}  // namespace stcalib
