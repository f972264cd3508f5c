#include "core/features/dynamic_filter.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <utility>
#include <vector>

#include "core/features/fast_atan2.h"
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

// The azimuth window |azimuth − centre| ≤ half angle, tested without trigonometry: in a frame
// whose x axis points at the centre, the angle to x is ≤ half ⇔ x ≥ |(x, y)|·cos(half).
class AzimuthWindow {
 public:
  AzimuthWindow(double center_deg, double half_deg)
      : all_(half_deg <= 0 || half_deg >= 180),
        cos_center_(std::cos(center_deg * M_PI / 180.0)),
        sin_center_(std::sin(center_deg * M_PI / 180.0)),
        cos_half_(std::cos(half_deg * M_PI / 180.0)) {}
  bool all() const { return all_; }
  bool Contains(const Eigen::Vector3d& p) const {
    if (all_) return true;
    const double x = cos_center_ * p.x() + sin_center_ * p.y();
    const double y = -sin_center_ * p.x() + cos_center_ * p.y();
    if (cos_half_ >= 0) return x >= 0 && x * x >= (x * x + y * y) * cos_half_ * cos_half_;
    return x >= 0 || x * x <= (x * x + y * y) * cos_half_ * cos_half_;
  }

 private:
  bool all_;
  double cos_center_, sin_center_, cos_half_;
};

// A horizontal grid around the sensor whose cells are at least τ_max wide: after Dilate(), the
// marked cells hold every place within τ_max (in x and y) of a marked point, so a reference point
// outside them cannot be any marked query's neighbour within τ.
class ReachGrid {
 public:
  ReachGrid(double half_extent_m, double cell_m)
      : cell_m_(cell_m),
        half_(static_cast<int>(std::ceil(half_extent_m / cell_m))),
        side_(2 * half_ + 1),
        marked_(static_cast<size_t>(side_) * side_, 0) {}
  // `p` must lie within the half extent (queried points are within max_range_m).
  void Mark(const Eigen::Vector3d& p) {
    const int i = Index(p);
    CHECK_GE(i, 0) << "reach grid: a queried point off the grid";
    marked_[i] = 1;
  }
  // Marks the 8 neighbours of every marked cell.
  void Dilate() {
    std::vector<uint8_t> grown = marked_;
    for (int y = 0; y < side_; ++y) {
      for (int x = 0; x < side_; ++x) {
        if (!marked_[y * side_ + x]) continue;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx >= 0 && xx < side_ && yy >= 0 && yy < side_) grown[yy * side_ + xx] = 1;
          }
        }
      }
    }
    marked_.swap(grown);
  }
  bool Reaches(const Eigen::Vector3d& p) const {
    const int i = Index(p);
    return i >= 0 && marked_[i] != 0;
  }

 private:
  int Index(const Eigen::Vector3d& p) const {
    const int x = static_cast<int>(std::floor(p.x() / cell_m_)) + half_;
    const int y = static_cast<int>(std::floor(p.y() / cell_m_)) + half_;
    if (x < 0 || x >= side_ || y < 0 || y >= side_) return -1;
    return y * side_ + x;
  }
  double cell_m_;
  int half_, side_;
  std::vector<uint8_t> marked_;
};

int Find(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Spherical range image of a sweep: the nearest return per (azimuth, elevation) cell. Only the
// azimuth columns marked in `columns` are filled (RangeAround reads a query's column and the two
// beside it, see MarkAround): a reference point's elevation is computed only when its column is
// wanted, and the cells read hold what a full image would.
class RangeImage {
 public:
  class Columns {
   public:
    Columns() : wanted_(kAz, 0) {}
    // Wants the columns RangeAround(p) reads.
    void MarkAround(const Eigen::Vector3d& p) {
      const int a = Column(p);
      for (int da = -1; da <= 1; ++da) wanted_[(a + da + kAz) % kAz] = 1;
    }
    bool Wanted(int column) const { return wanted_[column] != 0; }

   private:
    std::vector<uint8_t> wanted_;
  };

  RangeImage(const std::vector<Eigen::Vector3d>& points, double max_range_m, const Columns& columns)
      : range_(kAz * kEl, kEmpty) {
    const double max_r2 = max_range_m * max_range_m;
    for (const auto& p : points) {
      const double r2 = p.squaredNorm();
      if (r2 > max_r2) continue;
      const int a = Column(p);
      if (!columns.Wanted(a)) continue;
      const int e = Row(p);
      if (e < 0) continue;
      float& cell = range_[e * kAz + a];
      cell = std::min(cell, static_cast<float>(std::sqrt(r2)));
    }
  }
  // Nearest previous range in the 3×3 cells around the direction of p; +inf when nothing.
  float RangeAround(const Eigen::Vector3d& p) const {
    const int e = Row(p);
    if (e < 0) return kEmpty;
    const int a = Column(p);
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
  static int Column(const Eigen::Vector3d& p) {
    const double az = FastAtan2(p.y(), p.x());
    return std::min(static_cast<int>((az + M_PI) / (2 * M_PI) * kAz), kAz - 1);
  }
  // Elevation row, or −1 outside −30°..+10°.
  static int Row(const Eigen::Vector3d& p) {
    const double el = FastAtan2(p.z(), p.head<2>().norm());
    const int e = static_cast<int>((el * 180 / M_PI + 30.0) / 0.25);
    return e >= 0 && e < kEl ? e : -1;
  }
  std::vector<float> range_;
};

// Voxel key → index, open addressing with linear probing: one flat array instead of a node per
// key (std::unordered_map's allocations were most of the filter's own time). Keys are
// non-negative (PackVoxel).
class VoxelIndex {
 public:
  explicit VoxelIndex(size_t expected) { Rehash(std::max<size_t>(64, 2 * expected)); }
  // The value stored for `key`, inserting `value` when absent; `inserted` says which.
  int Emplace(int64_t key, int value, bool* inserted = nullptr) {
    if (2 * (size_ + 1) > keys_.size()) Rehash(2 * keys_.size());
    size_t slot = Slot(key);
    while (keys_[slot] != kEmpty && keys_[slot] != key) slot = (slot + 1) & mask_;
    const bool added = keys_[slot] == kEmpty;
    if (added) {
      keys_[slot] = key;
      values_[slot] = value;
      ++size_;
    }
    if (inserted != nullptr) *inserted = added;
    return values_[slot];
  }
  // The value stored for `key`, or −1.
  int Find(int64_t key) const {
    for (size_t slot = Slot(key); keys_[slot] != kEmpty; slot = (slot + 1) & mask_) {
      if (keys_[slot] == key) return values_[slot];
    }
    return -1;
  }

 private:
  static constexpr int64_t kEmpty = -1;
  size_t Slot(int64_t key) const {
    return static_cast<size_t>((static_cast<uint64_t>(key) * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  void Rehash(size_t capacity) {
    size_t pow2 = 64;
    int bits = 6;
    while (pow2 < capacity) {
      pow2 *= 2;
      ++bits;
    }
    std::vector<int64_t> keys = std::move(keys_);
    std::vector<int> values = std::move(values_);
    keys_.assign(pow2, kEmpty);
    values_.assign(pow2, 0);
    mask_ = pow2 - 1;
    shift_ = 64 - bits;
    size_ = 0;
    for (size_t i = 0; i < keys.size(); ++i) {
      if (keys[i] != kEmpty) Emplace(keys[i], values[i]);
    }
  }
  std::vector<int64_t> keys_;
  std::vector<int> values_;
  size_t mask_ = 0, size_ = 0;
  int shift_ = 58;
};

// Integer voxel coordinates packed into one non-negative key, 21 bits each.
int64_t PackVoxel(int64_t x, int64_t y, int64_t z) {
  return (x & 0x1FFFFF) | ((y & 0x1FFFFF) << 21) | ((z & 0x1FFFFF) << 42);
}

int64_t VoxelKey(const Eigen::Vector3d& p, double cell) {
  return PackVoxel(static_cast<int64_t>(std::floor(p.x() / cell)),
                   static_cast<int64_t>(std::floor(p.y() / cell)),
                   static_cast<int64_t>(std::floor(p.z() / cell)));
}

// τ(r), widened by the reference voxel's half diagonal [m].
double Tau(const DynamicFilterOptions& options, double range_m) {
  return options.tau0_m + options.tau_per_range * range_m + 0.87 * options.reference_voxel_m;
}

// Flags the selected current points with `queried` set that `reference` cannot explain.
// `representative[k]` is the selected point whose query stands for point k (same query voxel).
// `reach` holds every place within τ of a queried point: reference points outside it are left
// out of the tree, which cannot change a verdict (a neighbour within τ lies inside it; without
// one the nearest is beyond τ either way).
void FlagAgainst(const std::vector<Eigen::Vector3d>& current, const std::vector<int>& selected,
                 const std::vector<int>& representative, const std::vector<uint8_t>& queried,
                 const ReferenceSweep& reference, const ReachGrid& reach,
                 const DynamicFilterOptions& options, std::vector<uint8_t>* flagged) {
  const std::vector<Eigen::Vector3d>& own = *reference.points;
  std::vector<Eigen::Vector3d> moved;
  moved.reserve(own.size() / 2);
  VoxelIndex occupied(options.reference_voxel_m > 0 ? own.size() / 2 : 0);
  const double max_r2 = (options.max_range_m + 5.0) * (options.max_range_m + 5.0);
  bool any_in_range = false;  // a reference to compare with at all
  for (size_t i = 0; i < own.size(); ++i) {
    if (reference.ground != nullptr && !reference.ground->empty() && (*reference.ground)[i])
      continue;
    const Eigen::Vector3d p = reference.T_current_reference * own[i];
    if (p.squaredNorm() > max_r2) continue;
    any_in_range = true;
    if (options.reference_voxel_m > 0) {
      bool inserted = false;
      occupied.Emplace(VoxelKey(p, options.reference_voxel_m), 1, &inserted);
      if (!inserted) continue;
    }
    if (!reach.Reaches(p)) continue;
    moved.push_back(p);
  }
  if (!any_in_range) return;
  // No reference point within reach: every query's nearest neighbour is beyond τ.
  std::unique_ptr<PointKdTree> tree;
  if (!moved.empty()) tree = std::make_unique<PointKdTree>(moved);
  const Rigid3d T_reference_current = reference.T_current_reference.inverse();
  std::vector<int8_t> verdict(selected.size(), -1);  // per representative: 0 static, 1 flagged
  // Points beyond τ, in the reference's frame when their place must be seen to have been free.
  std::vector<int> beyond;
  std::vector<Eigen::Vector3d> beyond_in_reference;
  RangeImage::Columns columns;
  for (size_t k = 0; k < selected.size(); ++k) {
    if ((*flagged)[k] || !queried[k]) continue;
    const int rep = representative[k];
    if (verdict[rep] < 0) {
      verdict[rep] = 0;
      const Eigen::Vector3d& p = current[selected[rep]];
      int nearest;
      double distance = std::numeric_limits<double>::infinity();
      if (tree != nullptr) tree->Nearest(p, &nearest, &distance);
      if (distance > Tau(options, p.norm())) verdict[rep] = 1;
    }
    if (verdict[rep] == 0) continue;
    if (!reference.check_visibility) {
      (*flagged)[k] = 1;
      continue;
    }
    beyond.push_back(static_cast<int>(k));
    beyond_in_reference.push_back(T_reference_current * current[selected[k]]);
    columns.MarkAround(beyond_in_reference.back());
  }
  if (beyond.empty()) return;
  // Seen from the reference viewpoint, was this place free space (a longer return)?
  const RangeImage view(own, options.max_range_m + 5.0, columns);
  for (size_t b = 0; b < beyond.size(); ++b) {
    const Eigen::Vector3d& q = beyond_in_reference[b];
    const double r = q.norm();
    if (view.RangeAround(q) < r + options.visibility_margin_m + 0.02 * r) continue;
    (*flagged)[beyond[b]] = 1;
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
  const double max_r2 = options.max_range_m * options.max_range_m;
  for (size_t i = 0; i < current.size(); ++i) {
    if ((current_ground.empty() || !current_ground[i]) && current[i].squaredNorm() <= max_r2) {
      selected.push_back(static_cast<int>(i));
    }
  }
  if (selected.empty()) return result;

  // Euclidean clustering on a voxel grid: occupied voxels touching (26-neighbourhood) join.
  const double cell = options.cluster_tolerance_m;
  VoxelIndex voxel_id(selected.size() / 2);
  std::vector<Eigen::Vector3i> voxels;
  std::vector<int> point_voxel(selected.size());
  for (size_t k = 0; k < selected.size(); ++k) {
    const Eigen::Vector3d& p = current[selected[k]];
    const Eigen::Vector3i v(static_cast<int>(std::floor(p.x() / cell)),
                            static_cast<int>(std::floor(p.y() / cell)),
                            static_cast<int>(std::floor(p.z() / cell)));
    bool inserted = false;
    point_voxel[k] = voxel_id.Emplace(PackVoxel(v.x(), v.y(), v.z()),
                                      static_cast<int>(voxels.size()), &inserted);
    if (inserted) voxels.push_back(v);
  }
  std::vector<int> parent(voxels.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (size_t a = 0; a < voxels.size(); ++a) {
    const Eigen::Vector3i& v = voxels[a];
    // Half the neighbourhood (the 13 offsets after (0, 0, 0) in lexicographic order): the
    // other half joins the same pairs from the other voxel.
    for (int dx = 0; dx <= 1; ++dx) {
      for (int dy = dx == 0 ? 0 : -1; dy <= 1; ++dy) {
        for (int dz = dx == 0 && dy == 0 ? 1 : -1; dz <= 1; ++dz) {
          const int b = voxel_id.Find(PackVoxel(v.x() + dx, v.y() + dy, v.z() + dz));
          if (b < 0) continue;
          const int ra = Find(parent, static_cast<int>(a)), rb = Find(parent, b);
          if (ra != rb) parent[ra] = rb;
        }
      }
    }
  }
  // Per cluster (indexed by its root voxel): size, extent and whether it reaches the view.
  struct ClusterStats {
    int points = 0, flagged = 0;
    bool in_view = false;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e18), hi = Eigen::Vector3d::Constant(-1e18);
  };
  std::vector<ClusterStats> clusters(voxels.size());
  std::vector<int> point_cluster(selected.size());
  const AzimuthWindow view(options.roi_center_azimuth_deg, options.roi_half_angle_deg);
  for (size_t k = 0; k < selected.size(); ++k) {
    const int c = Find(parent, point_voxel[k]);
    point_cluster[k] = c;
    ClusterStats& s = clusters[c];
    const Eigen::Vector3d& p = current[selected[k]];
    if (s.points++ == 0) ++result.clusters;
    s.lo = s.lo.cwiseMin(p);
    s.hi = s.hi.cwiseMax(p);
    s.in_view = s.in_view || view.Contains(p);
  }
  // Only a cluster that could be removed is worth its queries: in the view, small enough to
  // move, with enough points to reach min_flagged_points.
  auto judged = [&](const ClusterStats& s) {
    return s.in_view && s.points >= options.min_flagged_points &&
           (s.hi - s.lo).head<2>().maxCoeff() <= options.max_cluster_extent_m;
  };
  std::vector<uint8_t> queried(selected.size(), 0);
  for (size_t k = 0; k < selected.size(); ++k) queried[k] = judged(clusters[point_cluster[k]]);

  // Points sharing a query voxel share one nearest-neighbour query.
  std::vector<int> representative(selected.size());
  if (!(options.query_voxel_m > 0)) {
    std::iota(representative.begin(), representative.end(), 0);  // every point its own query
  } else {
    VoxelIndex first(selected.size());
    for (size_t k = 0; k < selected.size(); ++k) {
      representative[k] =
          first.Emplace(VoxelKey(current[selected[k]], options.query_voxel_m), static_cast<int>(k));
    }
  }
  // Where the queries can find a neighbour within τ: cells at least τ_max wide, dilated by one.
  const double tau_max = Tau(options, options.max_range_m);
  // (Padded against the KD-tree's single-precision distances.)
  ReachGrid reach(options.max_range_m + 2 * tau_max, std::max(tau_max, 0.5) + 0.01);
  bool any_queried = false;
  for (size_t k = 0; k < selected.size(); ++k) {
    if (!queried[k]) continue;
    reach.Mark(current[selected[representative[k]]]);
    any_queried = true;
  }
  reach.Dilate();

  std::vector<uint8_t> flagged(selected.size(), 0);
  for (const ReferenceSweep& reference : references) {
    CHECK(reference.points != nullptr);
    if (any_queried) {
      FlagAgainst(current, selected, representative, queried, reference, reach, options, &flagged);
    }
  }
  for (size_t k = 0; k < selected.size(); ++k) {
    result.flagged_points += flagged[k];
    clusters[point_cluster[k]].flagged += flagged[k];
  }
  auto removed = [&](const ClusterStats& s) {
    return judged(s) && s.flagged >= options.min_flagged_points &&
           s.flagged >= options.min_flagged_fraction * s.points;
  };
  for (const ClusterStats& s : clusters) result.dynamic_clusters += s.points > 0 && removed(s);
  for (size_t k = 0; k < selected.size(); ++k) {
    if (removed(clusters[point_cluster[k]])) {
      result.dynamic[selected[k]] = 1;
      ++result.removed_points;
    }
  }
  return result;
}

}  // namespace stcalib
