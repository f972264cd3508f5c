#include "core/features/dynamic_filter.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <unordered_map>

#include "core/features/kdtree.h"

namespace stcalib {

Status DynamicFilterOptions::Validate() const {
  if (!(tau0_m > 0) || tau_per_range < 0 || !(max_range_m > 0) || !(cluster_tolerance_m > 0) ||
      min_flagged_points < 1 || min_flagged_fraction < 0 || min_flagged_fraction > 1 ||
      !(max_cluster_extent_m > 0) || roi_half_angle_deg < 0) {
    return Status::Error("dynamic filter: thresholds must be positive (fraction in [0, 1])");
  }
  return Status::Ok();
}

namespace {

// Range limit and, when set, the azimuth window |atan2(y, x)| ≤ half angle, tested without
// trigonometry: the angle to the x axis is ≤ half ⇔ x ≥ |(x, y)|·cos(half).
class Region {
 public:
  Region(const DynamicFilterOptions& o, double extra_m, double extra_deg)
      : max_r2_((o.max_range_m + extra_m) * (o.max_range_m + extra_m)),
        all_azimuths_(o.roi_half_angle_deg <= 0 || o.roi_half_angle_deg + extra_deg >= 180),
        cos_half_(std::cos((o.roi_half_angle_deg + extra_deg) * M_PI / 180.0)) {}
  bool Contains(const Eigen::Vector3d& p) const {
    if (p.squaredNorm() > max_r2_) return false;
    if (all_azimuths_) return true;
    if (cos_half_ >= 0) {
      return p.x() >= 0 && p.x() * p.x() >= (p.x() * p.x() + p.y() * p.y()) * cos_half_ * cos_half_;
    }
    return p.x() >= 0 || p.x() * p.x() <= (p.x() * p.x() + p.y() * p.y()) * cos_half_ * cos_half_;
  }

 private:
  double max_r2_;
  bool all_azimuths_;
  double cos_half_;
};

int Find(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Spherical range image of a sweep: the nearest return per (azimuth, elevation) cell.
class RangeImage {
 public:
  RangeImage(const std::vector<Eigen::Vector3d>& points, const Region& region)
      : range_(kAz * kEl, kEmpty) {
    for (const auto& p : points) {
      if (!region.Contains(p)) continue;
      const int c = Cell(p);
      if (c >= 0) range_[c] = std::min(range_[c], static_cast<float>(p.norm()));
    }
  }
  // Nearest previous range in the 3×3 cells around the direction of p; +inf when nothing.
  float RangeAround(const Eigen::Vector3d& p) const {
    const int c = Cell(p);
    if (c < 0) return kEmpty;
    const int a = c % kAz, e = c / kAz;
    float best = kEmpty;
    for (int de = -1; de <= 1; ++de) {
      if (e + de < 0 || e + de >= kEl) continue;
      for (int da = -1; da <= 1; ++da) {
        best = std::min(best, range_[(e + de) * kAz + (a + da + kAz) % kAz]);
      }
    }
    return best;
  }

 private:
  static constexpr int kAz = 1440, kEl = 160;  // 0.25° cells, elevation −30°..+10°
  static constexpr float kEmpty = std::numeric_limits<float>::infinity();
  static int Cell(const Eigen::Vector3d& p) {
    const double az = std::atan2(p.y(), p.x());
    const double el = std::atan2(p.z(), p.head<2>().norm());
    const int a = static_cast<int>((az + M_PI) / (2 * M_PI) * kAz);
    const int e = static_cast<int>((el * 180 / M_PI + 30.0) / 0.25);
    if (e < 0 || e >= kEl) return -1;
    return e * kAz + std::min(a, kAz - 1);
  }
  std::vector<float> range_;
};

int64_t VoxelKey(const Eigen::Vector3d& p, double cell) {
  const int64_t x = static_cast<int64_t>(std::floor(p.x() / cell));
  const int64_t y = static_cast<int64_t>(std::floor(p.y() / cell));
  const int64_t z = static_cast<int64_t>(std::floor(p.z() / cell));
  return (x & 0x1FFFFF) | ((y & 0x1FFFFF) << 21) | ((z & 0x1FFFFF) << 42);
}

// Flags the selected current points that `reference` cannot explain. `representative[k]` is the
// selected point whose query stands for point k (same query voxel).
void FlagAgainst(const std::vector<Eigen::Vector3d>& current, const std::vector<int>& selected,
                 const std::vector<int>& representative, const ReferenceSweep& reference,
                 const DynamicFilterOptions& options, std::vector<uint8_t>* flagged) {
  const std::vector<Eigen::Vector3d>& own = *reference.points;
  std::vector<Eigen::Vector3d> moved;
  moved.reserve(own.size() / 2);
  std::unordered_map<int64_t, char> occupied;
  const Region region(options, 5.0, 10.0);
  for (size_t i = 0; i < own.size(); ++i) {
    if (reference.ground != nullptr && !reference.ground->empty() && (*reference.ground)[i])
      continue;
    const Eigen::Vector3d p = reference.T_current_reference * own[i];
    if (!region.Contains(p)) continue;
    if (options.reference_voxel_m > 0 &&
        !occupied.emplace(VoxelKey(p, options.reference_voxel_m), 1).second) {
      continue;
    }
    moved.push_back(p);
  }
  if (moved.empty()) return;
  const PointKdTree tree(moved);
  std::unique_ptr<RangeImage> view;
  if (reference.check_visibility) view = std::make_unique<RangeImage>(own, region);
  const Rigid3d T_reference_current = reference.T_current_reference.inverse();
  std::vector<int8_t> verdict(selected.size(), -1);  // per representative: 0 static, 1 flagged
  for (size_t k = 0; k < selected.size(); ++k) {
    if ((*flagged)[k]) continue;
    const int rep = representative[k];
    if (verdict[rep] < 0) {
      verdict[rep] = 0;
      const Eigen::Vector3d& p = current[selected[rep]];
      int nearest;
      double distance;
      tree.Nearest(p, &nearest, &distance);
      // τ(r), widened by the reference voxel's half diagonal.
      if (distance >
          options.tau0_m + options.tau_per_range * p.norm() + 0.87 * options.reference_voxel_m) {
        verdict[rep] = 1;
      }
    }
    if (verdict[rep] == 0) continue;
    const Eigen::Vector3d& p = current[selected[k]];
    if (view != nullptr) {
      // Seen from the reference viewpoint, was this place free space (a longer return)?
      const Eigen::Vector3d q = T_reference_current * p;
      const double r = q.norm();
      if (view->RangeAround(q) < r + options.visibility_margin_m + 0.02 * r) continue;
    }
    (*flagged)[k] = 1;
  }
}

}  // namespace

DynamicFilterResult DetectDynamicPoints(const std::vector<Eigen::Vector3d>& current,
                                        const std::vector<uint8_t>& current_ground,
                                        const std::vector<ReferenceSweep>& references,
                                        const DynamicFilterOptions& options) {
  CHECK(options.Validate().ok()) << options.Validate().message();
  CHECK(current_ground.empty() || current_ground.size() == current.size());
  DynamicFilterResult result;
  result.dynamic.assign(current.size(), 0);
  if (current.empty() || references.empty()) {
    LOG_IF(WARNING, current.empty()) << "dynamic filter: empty sweep, nothing removed";
    return result;
  }
  std::vector<int> selected;
  const Region region(options, 0.0, 0.0);
  for (size_t i = 0; i < current.size(); ++i) {
    if ((current_ground.empty() || !current_ground[i]) && region.Contains(current[i])) {
      selected.push_back(static_cast<int>(i));
    }
  }
  if (selected.empty()) return result;
  // Points sharing a query voxel share one nearest-neighbour query.
  std::vector<int> representative(selected.size());
  {
    std::unordered_map<int64_t, int> first;
    first.reserve(selected.size());
    for (size_t k = 0; k < selected.size(); ++k) {
      const double cell = options.query_voxel_m > 0 ? options.query_voxel_m : 1e-6;
      representative[k] =
          first.emplace(VoxelKey(current[selected[k]], cell), static_cast<int>(k)).first->second;
    }
  }
  std::vector<uint8_t> flagged(selected.size(), 0);
  for (const ReferenceSweep& reference : references) {
    CHECK(reference.points != nullptr);
    FlagAgainst(current, selected, representative, reference, options, &flagged);
  }
  for (uint8_t f : flagged) result.flagged_points += f;

  // Euclidean clustering on a voxel grid: occupied voxels touching (26-neighbourhood) join.
  const double cell = options.cluster_tolerance_m;
  auto key = [](int64_t x, int64_t y, int64_t z) {
    return (x & 0x1FFFFF) | ((y & 0x1FFFFF) << 21) | ((z & 0x1FFFFF) << 42);
  };
  std::unordered_map<int64_t, int> voxel_id;
  voxel_id.reserve(selected.size() / 2);
  std::vector<Eigen::Vector3i> voxels;
  std::vector<int> point_voxel(selected.size());
  for (size_t k = 0; k < selected.size(); ++k) {
    const Eigen::Vector3d& p = current[selected[k]];
    const Eigen::Vector3i v(static_cast<int>(std::floor(p.x() / cell)),
                            static_cast<int>(std::floor(p.y() / cell)),
                            static_cast<int>(std::floor(p.z() / cell)));
    auto [it, inserted] =
        voxel_id.emplace(key(v.x(), v.y(), v.z()), static_cast<int>(voxels.size()));
    if (inserted) voxels.push_back(v);
    point_voxel[k] = it->second;
  }
  std::vector<int> parent(voxels.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (size_t a = 0; a < voxels.size(); ++a) {
    const Eigen::Vector3i& v = voxels[a];
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = voxel_id.find(key(v.x() + dx, v.y() + dy, v.z() + dz));
          if (it == voxel_id.end()) continue;
          const int ra = Find(parent, static_cast<int>(a)), rb = Find(parent, it->second);
          if (ra != rb) parent[ra] = rb;
        }
      }
    }
  }
  struct ClusterStats {
    int points = 0, flagged = 0;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e18), hi = Eigen::Vector3d::Constant(-1e18);
  };
  std::unordered_map<int, ClusterStats> clusters;
  std::vector<int> point_cluster(selected.size());
  for (size_t k = 0; k < selected.size(); ++k) {
    const int c = Find(parent, point_voxel[k]);
    point_cluster[k] = c;
    ClusterStats& s = clusters[c];
    ++s.points;
    s.flagged += flagged[k];
    s.lo = s.lo.cwiseMin(current[selected[k]]);
    s.hi = s.hi.cwiseMax(current[selected[k]]);
  }
  result.clusters = static_cast<int>(clusters.size());
  std::unordered_map<int, bool> is_dynamic;
  for (const auto& [id, s] : clusters) {
    const bool dynamic = s.flagged >= options.min_flagged_points &&
                         s.flagged >= options.min_flagged_fraction * s.points &&
                         (s.hi - s.lo).head<2>().maxCoeff() <= options.max_cluster_extent_m;
    is_dynamic[id] = dynamic;
    result.dynamic_clusters += dynamic;
  }
  for (size_t k = 0; k < selected.size(); ++k) {
    if (is_dynamic[point_cluster[k]]) {
      result.dynamic[selected[k]] = 1;
      ++result.removed_points;
    }
  }
  return result;
}

}  // namespace stcalib
