#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

namespace stcalib {

// Nearest-neighbour queries over a fixed set of 3-D points (nanoflann KD-tree, single precision).
class PointKdTree {
 public:
  explicit PointKdTree(const std::vector<Eigen::Vector3d>& points);
  ~PointKdTree();
  PointKdTree(const PointKdTree&) = delete;
  PointKdTree& operator=(const PointKdTree&) = delete;

  // False when the tree is empty.
  bool Nearest(const Eigen::Vector3d& query, int* index, double* distance_m) const;
  size_t size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stcalib
