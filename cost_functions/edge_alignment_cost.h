#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/cubic_interpolation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/motion/motion_model.h"
#include "core/types/camera_model.h"

namespace stcalib {

// The smoothed distance map of an image (distance to the nearest image edge, capped at the
// basin, in pixels), row-major float, sampled bicubically.
using DistanceGrid = ceres::Grid2D<float, 1>;
using DistanceInterpolator = ceres::BiCubicInterpolator<DistanceGrid>;

// Edge-alignment residual (method.md §6).
//
// A LiDAR edge point p, de-skewed to its sweep stamp t_l, is carried to the image time t_c by the
// LiDAR's own motion and then into the camera:
//
//   e        = (t_l + δ) − t_c = e0 + δ                       (method.md §2)
//   p_c      = R · Tv(e) · p + t,   Tv(e) = Exp(e · ξ_L)       (ξ_L: LiDAR body twist, §3)
//   (u, v)   = π(P_rect_02 · [R_rect_00 · p_c; 1])
//   r        = √w · D(v, u)
//
// with D the smoothed distance map read by a bicubic interpolator and w the point's weight
// (horizontal and vertical edges weighted w and 1 − w). The residual is in pixels.
//
// Parameters: the extrinsic T_camera_lidar as one block [qx, qy, qz, qw, tx, ty, tz] (Eigen
// quaternion order, on ProductManifold<EigenQuaternionManifold, EuclideanManifold<3>>) and the
// time offset δ [s] as its own block. A point that falls behind the camera or outside the image
// costs the constant `outside_px` (the map's cap) with zero derivative: it is dropped for that
// evaluation rather than clamped to the border, and leaving the image is never a way to lower
// the cost.
class EdgeAlignmentCost {
 public:
  EdgeAlignmentCost(const Eigen::Vector3d& point_lidar, double weight, const LidarTwist& twist,
                    double e0_s, const CameraModel* camera, const DistanceInterpolator* map,
                    double outside_px)
      : point_lidar_(point_lidar),
        sqrt_weight_(std::sqrt(weight)),
        twist_(twist),
        e0_s_(e0_s),
        camera_(camera),
        map_(map),
        outside_px_(outside_px) {}

  template <typename T>
  bool operator()(const T* const pose, const T* const time_offset, T* residual) const {
    // Normalised so that the residual depends on the rotation only, not on |q|.
    const Eigen::Quaternion<T> q = Eigen::Map<const Eigen::Quaternion<T>>(pose).normalized();
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(pose + 4);
    const T e = T(e0_s_) + time_offset[0];
    const Eigen::Matrix<T, 3, 1> p_moved = ApplyLidarMotion<T>(twist_, e, point_lidar_.cast<T>());
    const Eigen::Matrix<T, 3, 1> p_camera = q * p_moved + t;
    Eigen::Matrix<T, 2, 1> pixel;
    T depth;
    if (!camera_->Project<T>(p_camera, &pixel, &depth) || !Inside(pixel)) {
      residual[0] = T(sqrt_weight_ * outside_px_);
      return true;
    }
    T value;
    map_->Evaluate(pixel.y(), pixel.x(), &value);
    residual[0] = T(sqrt_weight_) * value;
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& point_lidar, double weight,
                                     const LidarTwist& twist, double e0_s,
                                     const CameraModel* camera, const DistanceInterpolator* map,
                                     double outside_px) {
    return new ceres::AutoDiffCostFunction<EdgeAlignmentCost, 1, 7, 1>(
        new EdgeAlignmentCost(point_lidar, weight, twist, e0_s, camera, map, outside_px));
  }

 private:
  template <typename T>
  bool Inside(const Eigen::Matrix<T, 2, 1>& pixel) const {
    // One pixel of margin keeps the bicubic stencil on real data.
    return pixel.x() >= T(1) && pixel.y() >= T(1) && pixel.x() <= T(camera_->width - 2) &&
           pixel.y() <= T(camera_->height - 2);
  }

  const Eigen::Vector3d point_lidar_;
  const double sqrt_weight_;
  const LidarTwist twist_;
  const double e0_s_;
  const CameraModel* camera_;
  const DistanceInterpolator* map_;
  const double outside_px_;
};

}  // namespace stcalib
