#pragma once

#include <ceres/manifold.h>
#include <glog/logging.h>

#include <Eigen/Core>

namespace stcalib {

// A point of R³ that may move only along one fixed unit direction d: tangent size 1,
//   x ⊞ s = x + s·d,   y ⊟ x = dᵀ(y − x),
// so ∂(x ⊞ s)/∂s = d and ∂(y ⊟ x)/∂y = dᵀ. Minus is the exact inverse of Plus for y on the line
// x + R·d (the only points Plus reaches) and the least-squares one elsewhere. The refinement
// uses it for a translation that moves only along the direction of travel.
class AlongDirectionManifold final : public ceres::Manifold {
 public:
  explicit AlongDirectionManifold(const Eigen::Vector3d& direction) : d_(direction.normalized()) {
    CHECK(direction.allFinite() && direction.norm() > 0) << "direction must be non-zero";
  }

  int AmbientSize() const override { return 3; }
  int TangentSize() const override { return 1; }

  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    for (int k = 0; k < 3; ++k) x_plus_delta[k] = x[k] + delta[0] * d_[k];
    return true;
  }
  bool PlusJacobian(const double* /*x*/, double* jacobian) const override {
    for (int k = 0; k < 3; ++k) jacobian[k] = d_[k];  // 3×1
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    y_minus_x[0] = d_[0] * (y[0] - x[0]) + d_[1] * (y[1] - x[1]) + d_[2] * (y[2] - x[2]);
    return true;
  }
  bool MinusJacobian(const double* /*x*/, double* jacobian) const override {
    for (int k = 0; k < 3; ++k) jacobian[k] = d_[k];  // 1×3
    return true;
  }

  const Eigen::Vector3d& direction() const { return d_; }

 private:
  Eigen::Vector3d d_;
};

}  // namespace stcalib
