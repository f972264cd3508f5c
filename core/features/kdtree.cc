#include "core/features/kdtree.h"

#include <cmath>
#include <nanoflann.hpp>

namespace stcalib {

struct PointKdTree::Impl {
  // nanoflann dataset adaptor over a packed float array.
  struct Dataset {
    std::vector<float> xyz;
    size_t kdtree_get_point_count() const { return xyz.size() / 3; }
    float kdtree_get_pt(size_t i, size_t dim) const { return xyz[3 * i + dim]; }
    template <class BBox>
    bool kdtree_get_bbox(BBox&) const {
      return false;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Dataset>,
                                                   Dataset, 3, uint32_t>;
  Dataset data;
  std::unique_ptr<Tree> tree;
};

PointKdTree::PointKdTree(const std::vector<Eigen::Vector3d>& points) : impl_(new Impl) {
  impl_->data.xyz.reserve(points.size() * 3);
  for (const auto& p : points) {
    impl_->data.xyz.push_back(static_cast<float>(p.x()));
    impl_->data.xyz.push_back(static_cast<float>(p.y()));
    impl_->data.xyz.push_back(static_cast<float>(p.z()));
  }
  impl_->tree =
      std::make_unique<Impl::Tree>(3, impl_->data, nanoflann::KDTreeSingleIndexAdaptorParams(32));
  if (!points.empty()) impl_->tree->buildIndex();
}

PointKdTree::~PointKdTree() = default;

size_t PointKdTree::size() const { return impl_->data.kdtree_get_point_count(); }

bool PointKdTree::Nearest(const Eigen::Vector3d& query, int* index, double* distance_m) const {
  if (size() == 0) return false;
  const float q[3] = {static_cast<float>(query.x()), static_cast<float>(query.y()),
                      static_cast<float>(query.z())};
  uint32_t i = 0;
  float d2 = 0;
  impl_->tree->knnSearch(q, 1, &i, &d2);
  *index = static_cast<int>(i);
  *distance_m = std::sqrt(static_cast<double>(d2));
  return true;
}

}  // namespace stcalib
