#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/features/lidar_rings.h"
#include "core/io/velodyne.h"
#include "core/types/status.h"

namespace stcalib {

// Per-point role for edge extraction.
enum class PointUse : uint8_t {
  kUse = 0,      ///< ordinary return
  kGround = 1,   ///< ground: never an edge; counts as far background along a ring
  kDynamic = 2,  ///< moving object: never an edge, and no edge is declared against it
};

// Depth-discontinuity edges (docs/method.md §4). Along a ring a jump in range marks a vertical edge
// (an object's left/right silhouette); between vertically adjacent rings at the same azimuth it
// marks a horizontal one (tops and overhangs). The nearer side is kept, and only where it is
// smooth: its next points away from the jump continue the surface. Foliage, whose returns
// scatter in depth, fails that test (docs/method.md §10).
struct LidarEdgeOptions {
  double min_range_m = 2.0;          ///< nearer edge points are dropped [m]
  double max_range_m = 70.0;         ///< farther edge points are dropped [m]
  double jump_min_m = 0.3;           ///< range jump that makes an edge, at 0 m [m]
  double jump_per_range = 0.02;      ///< added per metre of the near range [m/m]
  double smooth_tolerance_m = 0.15;  ///< near-side continuity between neighbours, at 0 m [m]
  double smooth_per_range = 0.005;   ///< added per metre of range [m/m]
  int smooth_neighbours = 2;         ///< near-side neighbours that must continue the surface
  double max_gap_steps = 4;          ///< a larger azimuth gap between returns is "no return"
  bool horizontal_edges = true;      ///< also detect cross-ring (horizontal) edges
  // Edge runs: a real vertical edge continues in the rings above or below (an edge point at
  // nearly the same azimuth and range), a horizontal one along its ring. Points without
  // `run_support` such neighbours are dropped: scattered foliage edges do not line up.
  int run_support = 1;
  double run_azimuth_deg = 0.6;       ///< azimuth window for a vertical-edge neighbour [deg]
  double run_range_tolerance = 0.05;  ///< relative range difference allowed within a run
  // Folds (LidarEdges::fold): horizontal edges below the sensor whose beam above returns within
  // fold_height_tolerance_m of their height (0 = mark none), at most fold_max_depth_m farther:
  // near, corners of tops seen from above (the image outline is the top's far side); unbounded by
  // default, also tops against a background at their height [m]. docs/tuning.md#fold-max-depth
  double fold_height_tolerance_m = 0.08;
  double fold_max_depth_m = std::numeric_limits<double>::infinity();
  // A fold is moved up the beams that land on its top at its height (each at most this much
  // farther than the last) to the top's far side, where the image outline is; 0 = none. 1.5 m is
  // about a car's bonnet or roof [m]. Measured: docs/tuning.md#fold-top-depth
  double fold_top_depth_m = 1.5;

  Status Validate() const;
};

enum class EdgeKind : uint8_t { kVertical = 0, kHorizontal = 1 };

struct LidarEdges {
  std::vector<Eigen::Vector3d> points_lidar;
  std::vector<double> time_s;  ///< capture time relative to the sweep stamp [s]
  std::vector<EdgeKind> kind;
  std::vector<int> source_index;  ///< index in the scan (−1 after merging into a local map)
  // ∂p/∂δ [m/s]: how the point moves with the time offset δ beyond the motion model's Tv (a
  // local map's earlier sweeps, RelativeLidarPoseRate); zero in a sweep's own edges.
  std::vector<Eigen::Vector3d> offset_rate;
  std::vector<uint8_t> fold;  ///< 1: a fold (LidarEdgeOptions::fold_height_tolerance_m)
  // Sweeps between the point's and the local map's own (MergeEdges); 0 in a sweep's own edges.
  std::vector<uint8_t> sweep_age;

  size_t size() const { return points_lidar.size(); }
  bool empty() const { return points_lidar.empty(); }
  void Append(const LidarEdges& other);
  // The points at `indices` (in that order), every per-point field with them.
  LidarEdges Select(const std::vector<int>& indices) const;
};

// `use` (optional, one entry per point) marks ground and dynamic points; `point_time_s` gives
// every point's capture time. An empty scan gives empty edges and a warning.
LidarEdges ExtractLidarEdges(const LidarScan& scan, const ScanRings& rings,
                             const std::vector<double>& point_time_s,
                             const std::vector<PointUse>* use, const LidarEdgeOptions& options);

}  // namespace stcalib
