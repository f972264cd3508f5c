#include "core/features/lidar_edges.h"

#include <cmath>

#include <glog/logging.h>

namespace stcalib {
namespace {

constexpr float kNoReturn = std::numeric_limits<float>::infinity();

}  // namespace

Status LidarEdgeOptions::Validate() const {
  if (!(min_range_m >= 0 && max_range_m > min_range_m)) {
    return Status::Error("lidar edges: need 0 <= min_range_m < max_range_m");
  }
  if (!(jump_min_m > 0) || jump_per_range < 0 || !(smooth_tolerance_m > 0) ||
      smooth_per_range < 0 || smooth_neighbours < 0 || !(max_gap_steps >= 1)) {
    return Status::Error("lidar edges: thresholds must be positive");
  }
  return Status::Ok();
}

void LidarEdges::Append(const LidarEdges& other) {
  points_lidar.insert(points_lidar.end(), other.points_lidar.begin(), other.points_lidar.end());
  time_s.insert(time_s.end(), other.time_s.begin(), other.time_s.end());
  kind.insert(kind.end(), other.kind.begin(), other.kind.end());
  source_index.insert(source_index.end(), other.source_index.begin(), other.source_index.end());
}

LidarEdges ExtractLidarEdges(const LidarScan& scan, const ScanRings& rings,
                             const std::vector<double>& point_time_s,
                             const std::vector<PointUse>* use, const LidarEdgeOptions& options) {
  CHECK(options.Validate().ok()) << options.Validate().message();
  CHECK_EQ(rings.ring.size(), scan.size());
  CHECK_EQ(point_time_s.size(), scan.size());
  CHECK(use == nullptr || use->size() == scan.size());
  LidarEdges edges;
  if (scan.size() == 0 || rings.num_rings() == 0) {
    LOG(WARNING) << "lidar edges: empty scan, no edges";
    return edges;
  }
  const double step = rings.azimuth_step_rad > 0 ? rings.azimuth_step_rad : 0.0016;
  auto usage = [&](int i) { return use == nullptr ? PointUse::kUse : (*use)[i]; };
  auto jump = [&](double near) { return options.jump_min_m + options.jump_per_range * near; };
  auto smooth = [&](double r) { return options.smooth_tolerance_m + options.smooth_per_range * r; };
  auto in_range = [&](double r) { return r >= options.min_range_m && r <= options.max_range_m; };
  std::vector<uint8_t> is_edge(scan.size(), 0);
  auto add = [&](int i, EdgeKind kind) {
    if (is_edge[i]) return;
    is_edge[i] = 1;
    edges.points_lidar.push_back(scan.points_lidar[i]);
    edges.time_s.push_back(point_time_s[i]);
    edges.kind.push_back(kind);
    edges.source_index.push_back(i);
  };

  // Vertical edges: along each ring, returns in azimuth order.
  for (int r = 0; r < rings.num_rings(); ++r) {
    const int begin = rings.ring_begin[r], end = rings.ring_begin[r + 1];
    const int count = end - begin;
    if (count < 2 * options.smooth_neighbours + 2) continue;
    // Range of the neighbour `k` steps from i in direction dir, or +inf when there is none
    // within the gap limit (no return); dynamic neighbours are reported as NaN.
    auto neighbour = [&](int i, int dir, int k, int* index) -> float {
      int j = i;
      for (int s = 0; s < k; ++s) {
        const int next = j + dir;
        if (next < begin || next >= end) return kNoReturn;
        const double gap = std::abs(
            std::remainder(rings.azimuth_rad[next] - rings.azimuth_rad[j], 2 * M_PI));
        if (gap > options.max_gap_steps * step) return kNoReturn;
        j = next;
      }
      *index = j;
      if (usage(j) == PointUse::kDynamic) return std::numeric_limits<float>::quiet_NaN();
      if (usage(j) == PointUse::kGround) return kNoReturn;
      return rings.range_m[j];
    };
    for (int i = begin; i < end; ++i) {
      if (usage(i) != PointUse::kUse) continue;
      const float r = rings.range_m[i];
      if (!in_range(r)) continue;
      for (int dir : {-1, 1}) {
        int j = -1;
        const float other = neighbour(i, dir, 1, &j);
        if (std::isnan(other) || other - r < jump(r)) continue;  // i must be the near side
        // The near side continues smoothly away from the jump.
        bool smooth_side = true;
        float previous = r;
        for (int k = 1; k <= options.smooth_neighbours && smooth_side; ++k) {
          int n = -1;
          const float rn = neighbour(i, -dir, k, &n);
          smooth_side = std::isfinite(rn) && std::abs(rn - previous) < smooth(r);
          previous = rn;
        }
        if (smooth_side) {
          add(i, EdgeKind::kVertical);
          break;
        }
      }
    }
  }

  if (!options.horizontal_edges || rings.num_rings() < 3) return edges;
  // Horizontal edges: compare each return with the returns at the same azimuth in the rings
  // above and below (elevation order).
  const int bins = static_cast<int>(std::ceil(2 * M_PI / step));
  auto bin_of = [&](float azimuth) {
    int b = static_cast<int>((azimuth + M_PI) / step);
    return std::min(std::max(b, 0), bins - 1);
  };
  std::vector<std::vector<int>> table(rings.num_rings(), std::vector<int>(bins, -1));
  for (int r = 0; r < rings.num_rings(); ++r) {
    for (int i = rings.ring_begin[r]; i < rings.ring_begin[r + 1]; ++i) {
      table[r][bin_of(rings.azimuth_rad[i])] = i;
    }
  }
  // Return at the same azimuth `k` rings away in elevation order: +inf for no return (sky),
  // NaN when undecidable (ground, dynamic, ring missing).
  auto vertical_neighbour = [&](int i, int k) -> float {
    const int rank = rings.elevation_rank[rings.ring[i]] + k;
    if (rank < 0 || rank >= rings.num_rings()) return std::numeric_limits<float>::quiet_NaN();
    const int b = bin_of(rings.azimuth_rad[i]);
    const std::vector<int>& row = table[rings.order_by_elevation[rank]];
    int j = row[b];
    if (j < 0 && b > 0) j = row[b - 1];
    if (j < 0 && b + 1 < bins) j = row[b + 1];
    if (j < 0) return kNoReturn;
    if (usage(j) != PointUse::kUse) return std::numeric_limits<float>::quiet_NaN();
    return rings.range_m[j];
  };
  for (size_t i = 0; i < scan.size(); ++i) {
    if (is_edge[i] || usage(i) != PointUse::kUse) continue;
    const float r = rings.range_m[i];
    if (!in_range(r)) continue;
    for (int dir : {-1, 1}) {
      const float other = vertical_neighbour(static_cast<int>(i), dir);
      if (std::isnan(other) || other - r < jump(r)) continue;
      const float next = vertical_neighbour(static_cast<int>(i), -dir);
      if (std::isfinite(next) && std::abs(next - r) < smooth(r)) {
        add(static_cast<int>(i), EdgeKind::kHorizontal);
        break;
      }
    }
  }
  return edges;
}

}  // namespace stcalib
