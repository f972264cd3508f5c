#include "core/features/dynamic_filter.h"

#include <cmath>
#include <numeric>
#include <unordered_map>

#include <glog/logging.h>

#include "core/features/kdtree.h"

namespace stcalib {
namespace {

bool InRegion(const Eigen::Vector3d& p, const DynamicFilterOptions& o, double extra_m) {
  const double r2 = p.squaredNorm();
  const double max_r = o.max_range_m + extra_m;
  if (r2 > max_r * max_r) return false;
  if (o.roi_half_angle_deg <= 0) return true;
  const double margin = extra_m > 0 ? 10.0 : 0.0;
  return std::abs(std::atan2(p.y(), p.x())) * 180.0 / M_PI <= o.roi_half_angle_deg + margin;
}

int Find(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

Status DynamicFilterOptions::Validate() const {
  if (!(tau0_m > 0) || tau_per_range < 0 || !(max_range_m > 0) || !(cluster_tolerance_m > 0) ||
      min_flagged_points < 1 || min_flagged_fraction < 0 || min_flagged_fraction > 1 ||
      !(max_cluster_extent_m > 0) || roi_half_angle_deg < 0) {
    return Status::Error("dynamic filter: thresholds must be positive (fraction in [0, 1])");
  }
  return Status::Ok();
}

DynamicFilterResult DetectDynamicPoints(const std::vector<Eigen::Vector3d>& current,
                                        const std::vector<uint8_t>& current_ground,
                                        const std::vector<Eigen::Vector3d>& previous,
                                        const std::vector<uint8_t>& previous_ground,
                                        const DynamicFilterOptions& options) {
  CHECK(options.Validate().ok()) << options.Validate().message();
  CHECK(current_ground.empty() || current_ground.size() == current.size());
  CHECK(previous_ground.empty() || previous_ground.size() == previous.size());
  DynamicFilterResult result;
  result.dynamic.assign(current.size(), 0);
  if (current.empty() || previous.empty()) {
    LOG(WARNING) << "dynamic filter: empty sweep, nothing removed";
    return result;
  }
  std::vector<Eigen::Vector3d> reference;
  reference.reserve(previous.size());
  for (size_t i = 0; i < previous.size(); ++i) {
    if ((previous_ground.empty() || !previous_ground[i]) && InRegion(previous[i], options, 5.0)) {
      reference.push_back(previous[i]);
    }
  }
  std::vector<int> selected;
  for (size_t i = 0; i < current.size(); ++i) {
    if ((current_ground.empty() || !current_ground[i]) && InRegion(current[i], options, 0.0)) {
      selected.push_back(static_cast<int>(i));
    }
  }
  if (selected.empty() || reference.empty()) return result;

  // Flag points without a close previous neighbour (Eq. τ(r) = τ0 + k·r).
  const PointKdTree tree(reference);
  std::vector<uint8_t> flagged(selected.size(), 0);
  for (size_t k = 0; k < selected.size(); ++k) {
    const Eigen::Vector3d& p = current[selected[k]];
    int nearest;
    double distance;
    tree.Nearest(p, &nearest, &distance);
    if (distance > options.tau0_m + options.tau_per_range * p.norm()) {
      flagged[k] = 1;
      ++result.flagged_points;
    }
  }

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
    auto [it, inserted] = voxel_id.emplace(key(v.x(), v.y(), v.z()), static_cast<int>(voxels.size()));
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
