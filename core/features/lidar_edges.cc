#include "core/features/lidar_edges.h"

#include <glog/logging.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace stcalib {
namespace {

constexpr float kNoReturn = std::numeric_limits<float>::infinity();

// Calls f(to.field, from.field) for every per-point field of LidarEdges: the one list of them.
template <typename To, typename F>
void ForEachPointField(To &to, const LidarEdges &from, F f) {
  f(to.points_lidar, from.points_lidar);
  f(to.time_s, from.time_s);
  f(to.kind, from.kind);
  f(to.source_index, from.source_index);
  f(to.offset_rate, from.offset_rate);
  f(to.fold, from.fold);
  f(to.sweep_age, from.sweep_age);
}

void CheckPointFields(const LidarEdges &edges) {
  ForEachPointField(edges, edges, [&](const auto &, const auto &field) {
    CHECK_EQ(field.size(), edges.size()) << "LidarEdges: one entry per point in every field";
  });
}

// Keeps edge points supported by neighbours of the same run (see
// LidarEdgeOptions::run_support).
LidarEdges KeepRuns(const LidarEdges &edges, const ScanRings &rings,
                    const LidarEdgeOptions &options) {
  // Edge points by ring, sorted by azimuth.
  std::vector<std::vector<int>> by_ring(rings.num_rings());
  for (size_t k = 0; k < edges.size(); ++k) by_ring[rings.ring[edges.source_index[k]]].push_back(k);
  auto azimuth = [&](int k) { return rings.azimuth_rad[edges.source_index[k]]; };
  auto range = [&](int k) { return rings.range_m[edges.source_index[k]]; };
  for (auto &list : by_ring) {
    std::sort(list.begin(), list.end(), [&](int a, int b) { return azimuth(a) < azimuth(b); });
  }
  const double window = options.run_azimuth_deg * M_PI / 180.0;
  const double along_window = 3.5 * std::max(rings.azimuth_step_rad, 1e-4);
  auto supporters = [&](int k, int ring, EdgeKind kind, double half_width) {
    if (ring < 0 || ring >= rings.num_rings()) return 0;
    const std::vector<int> &list = by_ring[ring];
    const float a = azimuth(k);
    auto it = std::lower_bound(list.begin(), list.end(), a - half_width,
                               [&](int j, double value) { return azimuth(j) < value; });
    int count = 0;
    for (; it != list.end() && azimuth(*it) <= a + half_width; ++it) {
      if (*it == k || edges.kind[*it] != kind) continue;
      if (std::abs(range(*it) - range(k)) <= options.run_range_tolerance * range(k) + 0.1) ++count;
    }
    return count;
  };
  std::vector<int> kept;
  for (size_t k = 0; k < edges.size(); ++k) {
    const int ring = rings.ring[edges.source_index[k]];
    int support = 0;
    if (edges.kind[k] == EdgeKind::kVertical) {
      const int rank = rings.elevation_rank[ring];
      for (int d : {-1, 1}) {
        const int r = rank + d;
        if (r >= 0 && r < rings.num_rings()) {
          support += supporters(k, rings.order_by_elevation[r], EdgeKind::kVertical, window);
        }
      }
    } else {
      support = supporters(k, ring, EdgeKind::kHorizontal, along_window);
    }
    if (support >= options.run_support) kept.push_back(static_cast<int>(k));
  }
  return edges.Select(kept);
}

}  // namespace

Status LidarEdgeOptions::Validate() const {
  if (!(min_range_m >= 0 && max_range_m > min_range_m)) {
    return Status::Error("lidar edges: need 0 <= min_range_m < max_range_m");
  }
  if (!(fold_height_tolerance_m >= 0) || !(fold_max_depth_m >= 0) || !(fold_top_depth_m >= 0)) {
    return Status::Error(
        "lidar edges: fold_height_tolerance_m, fold_max_depth_m and fold_top_depth_m must be >= 0");
  }
  if (!(jump_min_m > 0) || jump_per_range < 0 || !(smooth_tolerance_m > 0) ||
      smooth_per_range < 0 || smooth_neighbours < 0 || !(max_gap_steps >= 1)) {
    return Status::Error("lidar edges: thresholds must be positive");
  }
  return Status::Ok();
}

void LidarEdges::Append(const LidarEdges &other) {
  CheckPointFields(*this);
  CheckPointFields(other);
  ForEachPointField(*this, other, [](auto &to, const auto &from) {
    to.insert(to.end(), from.begin(), from.end());
  });
}

LidarEdges LidarEdges::Select(const std::vector<int> &indices) const {
  CheckPointFields(*this);
  for (int i : indices) {
    CHECK(i >= 0 && static_cast<size_t>(i) < size()) << "LidarEdges::Select: index " << i;
  }
  LidarEdges out;
  ForEachPointField(out, *this, [&](auto &to, const auto &from) {
    to.reserve(indices.size());
    for (int i : indices) to.push_back(from[i]);
  });
  return out;
}

LidarEdges ExtractLidarEdges(const LidarScan &scan, const ScanRings &rings,
                             const std::vector<double> &point_time_s,
                             const std::vector<PointUse> *use, const LidarEdgeOptions &options) {
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
  // The silhouette lies between the near return and the direction of its far
  // neighbour: the edge point is put at the near range on the bisecting direction
  // (half a beam or azimuth step towards the far side), which removes the
  // half-step bias of taking the near return itself. `far_direction` is the far
  // neighbour's direction, or the direction of the missing return (sky) it would
  // have had; zero when unknown.
  auto add = [&](int i, EdgeKind kind, const Eigen::Vector3d &far_direction, bool fold) {
    if (is_edge[i]) return;
    is_edge[i] = 1;
    Eigen::Vector3d p = scan.points_lidar[i];
    if (!far_direction.isZero()) {
      const Eigen::Vector3d bisector = p.normalized() + far_direction.normalized();
      if (bisector.norm() > 1e-6) p = bisector.normalized() * rings.range_m[i];
    }
    edges.points_lidar.push_back(p);
    edges.time_s.push_back(point_time_s[i]);
    edges.kind.push_back(kind);
    edges.source_index.push_back(i);
    edges.offset_rate.push_back(Eigen::Vector3d::Zero());
    edges.fold.push_back(fold ? 1 : 0);
    edges.sweep_age.push_back(0);
  };

  // Vertical edges: along each ring, returns in azimuth order.
  for (int r = 0; r < rings.num_rings(); ++r) {
    const int begin = rings.ring_begin[r], end = rings.ring_begin[r + 1];
    const int count = end - begin;
    if (count < 2 * options.smooth_neighbours + 2) continue;
    // Range of the neighbour `k` steps from i in direction dir, or +inf when
    // there is none within the gap limit (no return); dynamic neighbours are
    // reported as NaN.
    auto neighbour = [&](int i, int dir, int k, int *index) -> float {
      int j = i;
      for (int s = 0; s < k; ++s) {
        const int next = j + dir;
        if (next < begin || next >= end) return kNoReturn;
        const double gap =
            std::abs(WrappedAzimuthStep(rings.azimuth_rad[j], rings.azimuth_rad[next]));
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
          Eigen::Vector3d far_direction = Eigen::Vector3d::Zero();
          if (j >= 0) {
            far_direction = scan.points_lidar[j];
          } else {  // no return: one azimuth step further round, same elevation
            far_direction =
                Eigen::AngleAxisd(dir * step, Eigen::Vector3d::UnitZ()) * scan.points_lidar[i];
          }
          add(i, EdgeKind::kVertical, far_direction, false);
          break;
        }
      }
    }
  }

  auto AddHorizontal = [&]() {
    // Horizontal edges: compare each return with the returns at the same
    // azimuth in the rings above and below (elevation order).
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
    // Return at the same azimuth `k` rings away in elevation order: +inf for no
    // return (sky), NaN when undecidable (ground, dynamic, ring missing).
    auto vertical_neighbour = [&](int i, int k, int *index) -> float {
      const int rank = rings.elevation_rank[rings.ring[i]] + k;
      if (rank < 0 || rank >= rings.num_rings()) return std::numeric_limits<float>::quiet_NaN();
      const int b = bin_of(rings.azimuth_rad[i]);
      const std::vector<int> &row = table[rings.order_by_elevation[rank]];
      int j = row[b];
      if (j < 0 && b > 0) j = row[b - 1];
      if (j < 0 && b + 1 < bins) j = row[b + 1];
      if (j < 0) return kNoReturn;
      *index = j;
      if (usage(j) != PointUse::kUse) return std::numeric_limits<float>::quiet_NaN();
      return rings.range_m[j];
    };
    // Direction of the ring `dir` steps from i's in elevation order, at i's azimuth (where a
    // missing return would have been); zero when there is no such ring.
    auto ring_direction = [&](int i, int dir) -> Eigen::Vector3d {
      const int rank = rings.elevation_rank[rings.ring[i]] + dir;
      if (rank < 0 || rank >= rings.num_rings()) return Eigen::Vector3d::Zero();
      const double elevation = rings.ring_elevation_rad[rings.order_by_elevation[rank]];
      const double azimuth = rings.azimuth_rad[i];
      return Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                             std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    };
    // A fold's top (LidarEdgeOptions::fold_top_depth_m): from `top`, the return of the beam
    // above the corner, up the beams that land on it at its height. Returns the last of them
    // and, in `beyond`, the direction of the beam above it (its return, or where it would be);
    // −1 when the walk meets an edge point: the top's far side is one already.
    auto far_side_of_top = [&](int top, Eigen::Vector3d *beyond) {
      for (;;) {
        if (is_edge[top]) return -1;
        int above = -1;
        const float range = vertical_neighbour(top, -1, &above);
        if (above >= 0 && std::isfinite(range) &&
            range - rings.range_m[top] < options.fold_top_depth_m &&
            std::abs(scan.points_lidar[above].z() - scan.points_lidar[top].z()) <
                options.fold_height_tolerance_m) {
          top = above;
          continue;
        }
        *beyond =
            above >= 0 && !std::isnan(range) ? scan.points_lidar[above] : ring_direction(top, -1);
        return top;
      }
    };
    std::vector<int> tops;  // the tops' first returns of the folds to move, after the edges
    for (size_t i = 0; i < scan.size(); ++i) {
      if (is_edge[i] || usage(i) != PointUse::kUse) continue;
      const float r = rings.range_m[i];
      if (!in_range(r)) continue;
      for (int dir : {-1, 1}) {
        int far = -1, unused = -1;
        const float other = vertical_neighbour(static_cast<int>(i), dir, &far);
        if (std::isnan(other) || other - r < jump(r)) continue;
        const float next = vertical_neighbour(static_cast<int>(i), -dir, &unused);
        if (std::isfinite(next) && std::abs(next - r) < smooth(r)) {
          // No return (sky): the adjacent ring's elevation, same azimuth.
          Eigen::Vector3d far_direction =
              far >= 0 ? scan.points_lidar[far] : ring_direction(static_cast<int>(i), dir);
          // The beam above (dir −1 in elevation order) on the same height, below the sensor.
          const double z = scan.points_lidar[i].z();
          const bool fold =
              dir < 0 && far >= 0 && z < 0 && other - r < options.fold_max_depth_m &&
              std::abs(scan.points_lidar[far].z() - z) < options.fold_height_tolerance_m;
          if (fold && other - r < options.fold_top_depth_m) {
            is_edge[i] = 1;  // the corner is not the outline: the top's far side is
            tops.push_back(far);
            break;
          }
          add(static_cast<int>(i), EdgeKind::kHorizontal, far_direction, fold);
          break;
        }
      }
    }
    // Moved once every other edge is known, so that the result does not depend on scan order.
    for (int first : tops) {
      Eigen::Vector3d beyond;
      const int top = far_side_of_top(first, &beyond);
      if (top >= 0) add(top, EdgeKind::kHorizontal, beyond, true);
    }
  };
  if (options.horizontal_edges && rings.num_rings() >= 3) AddHorizontal();
  return options.run_support > 0 ? KeepRuns(edges, rings, options) : edges;
}

}  // namespace stcalib
