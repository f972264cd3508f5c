#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

namespace stcalib {

// Beams (rings) of a spinning-LiDAR sweep stored in KITTI order, which has no ring field
// (docs/method.md §10): each laser's points run counter-clockwise from just left of straight ahead
// all the way round to just right of it, and lasers follow each other. A laser ends where the
// azimuth, having passed the ±180° wrap, crosses from negative to positive.
struct ScanRings {
  std::vector<uint16_t> ring;              ///< ring of every point, in file order
  std::vector<float> azimuth_rad;          ///< atan2(y, x) of every point, (−π, π]
  std::vector<float> range_m;              ///< |p| of every point
  std::vector<int> ring_begin;             ///< first point of each ring; back() = number of points
  std::vector<int> order_by_elevation;     ///< rings sorted from the top beam to the bottom one
  std::vector<int> elevation_rank;         ///< inverse of order_by_elevation
  double azimuth_step_rad = 0;             ///< median spacing of consecutive returns in a ring
  std::vector<double> ring_elevation_rad;  ///< mean elevation of each ring's returns [rad]

  int num_rings() const { return static_cast<int>(ring_begin.size()) - 1; }
};

ScanRings SplitIntoRings(const std::vector<Eigen::Vector3d>& points_lidar);
// The same for a sweep whose driver gave each point its ring: `ring_of_point` (one per point,
// grouped: non-decreasing) starts a new ring wherever it changes; the rings are numbered in that
// order from 0.
ScanRings RingsFromLabels(const std::vector<Eigen::Vector3d>& points_lidar,
                          const std::vector<uint16_t>& ring_of_point);

// Capture time of every point relative to the sweep stamp, which KITTI puts mid-sweep when the
// head faces forward; the head spins clockwise, so t = −azimuth / 2π · sweep_duration [s].
std::vector<double> PointTimesFromAzimuth(const ScanRings& rings, double sweep_duration_s);

// The azimuth step from `from` to `to` (float atan2 values, within a float ulp of (−π, π] as
// ScanRings stores them) wrapped into [−π, π] [rad]: std::remainder(to − from, 2π) bit for bit
// (the difference lies within about ±2π, and subtracting 2π from a value in (π, 2π + ulp] is exact
// by Sterbenz's lemma), without its cost (measured: docs/tuning.md#wrapped-azimuth-step).
inline double WrappedAzimuthStep(float from, float to) {
  const double d = to - from;  // the float difference, as before
  if (d > M_PI) return d - 2 * M_PI;
  if (d < -M_PI) return d + 2 * M_PI;
  return d;
}

}  // namespace stcalib
