#include "core/features/lidar_rings.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/features/fast_atan2.h"

namespace stcalib {

namespace {

// Azimuth and range of every point.
ScanRings PolarCoordinates(const std::vector<Eigen::Vector3d>& points) {
  ScanRings rings;
  const int n = static_cast<int>(points.size());
  rings.ring.resize(n);
  rings.azimuth_rad.resize(n);
  rings.range_m.resize(n);
  for (int i = 0; i < n; ++i) {
    // FastAtan2 is within 2e-11 rad of std::atan2, far below the float the azimuth is kept in.
    rings.azimuth_rad[i] = static_cast<float>(FastAtan2(points[i].y(), points[i].x()));
    rings.range_m[i] = static_cast<float>(points[i].norm());
  }
  return rings;
}

// Given ring_begin: each point's ring, the azimuth step, the elevations and their order.
void DescribeRings(const std::vector<Eigen::Vector3d>& points, ScanRings* rings_out) {
  ScanRings& rings = *rings_out;
  std::vector<double> steps, elevation(rings.num_rings(), 0.0);
  for (int r = 0; r < rings.num_rings(); ++r) {
    double sum = 0;
    int count = 0;
    for (int i = rings.ring_begin[r]; i < rings.ring_begin[r + 1]; ++i) {
      rings.ring[i] = static_cast<uint16_t>(r);
      if (rings.range_m[i] > 0.5f) {
        sum += std::asin(std::clamp(points[i].z() / rings.range_m[i], -1.0, 1.0));
        ++count;
      }
      if (i > rings.ring_begin[r] && (i % 7) == 0) {
        const double d = WrappedAzimuthStep(rings.azimuth_rad[i - 1], rings.azimuth_rad[i]);
        if (d > 0 && d < 0.02) steps.push_back(d);
      }
    }
    elevation[r] = count > 0 ? sum / count : 0.0;
  }
  if (!steps.empty()) {
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    rings.azimuth_step_rad = steps[steps.size() / 2];
  }
  rings.ring_elevation_rad = elevation;
  rings.order_by_elevation.resize(rings.num_rings());
  std::iota(rings.order_by_elevation.begin(), rings.order_by_elevation.end(), 0);
  std::stable_sort(rings.order_by_elevation.begin(), rings.order_by_elevation.end(),
                   [&](int a, int b) { return elevation[a] > elevation[b]; });
  rings.elevation_rank.resize(rings.num_rings());
  for (int k = 0; k < rings.num_rings(); ++k) rings.elevation_rank[rings.order_by_elevation[k]] = k;
}

}  // namespace

ScanRings SplitIntoRings(const std::vector<Eigen::Vector3d>& points) {
  ScanRings rings = PolarCoordinates(points);
  const int n = static_cast<int>(points.size());
  rings.ring_begin.push_back(0);
  bool passed_back = false;  // the current laser has swept past the rear
  for (int i = 1; i < n; ++i) {
    const float a0 = rings.azimuth_rad[i - 1], a1 = rings.azimuth_rad[i];
    if (a1 < a0 - static_cast<float>(M_PI / 2)) passed_back = true;  // wrap or rear gap
    if (passed_back && a0 < 0 && a1 >= 0) {
      rings.ring_begin.push_back(i);
      passed_back = false;
    }
  }
  rings.ring_begin.push_back(n);
  if (n == 0) rings.ring_begin = {0};
  DescribeRings(points, &rings);
  return rings;
}

ScanRings RingsFromLabels(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<uint16_t>& ring_of_point) {
  CHECK_EQ(points.size(), ring_of_point.size());
  ScanRings rings = PolarCoordinates(points);
  const int n = static_cast<int>(points.size());
  rings.ring_begin.push_back(0);
  for (int i = 1; i < n; ++i) {
    if (ring_of_point[i] != ring_of_point[i - 1]) rings.ring_begin.push_back(i);
  }
  rings.ring_begin.push_back(n);
  if (n == 0) rings.ring_begin = {0};
  DescribeRings(points, &rings);
  return rings;
}

std::vector<double> PointTimesFromAzimuth(const ScanRings& rings, double sweep_duration_s) {
  std::vector<double> times(rings.azimuth_rad.size());
  for (size_t i = 0; i < times.size(); ++i) {
    times[i] = -rings.azimuth_rad[i] / (2 * M_PI) * sweep_duration_s;
  }
  return times;
}

}  // namespace stcalib
