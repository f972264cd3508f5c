#pragma once

#include <ceres/cubic_interpolation.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

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
//   p_m      = Tv(e) · p,       Tv(e) = Exp(e · ξ_L)           (ξ_L = (ω, v): LiDAR body twist, §3)
//   p_c      = R · p_m + t,     R = R(q / |q|)
//   h        = P · R_rect · p_c + p4,   (u, v) = (h_x / h_z, h_y / h_z)
//   r        = √w · D(v, u)
//
// with D the smoothed distance map read by a bicubic interpolator, P | p4 = P_rect_02 and w the
// point's weight (horizontal and vertical edges weighted w and 1 − w). The residual is in pixels.
//
// Jacobians (analytic: with autodiff through the motion model's sines and the quaternion, a
// 12-frame KITTI refinement took 188 ms instead of 41-46 ms, BM_Refine/12). With
// g = √w · [∂D/∂u, ∂D/∂v] and A = ∂(u, v)/∂h · P · R_rect, ∂(u, v)/∂h = [1/h_z, 0, −h_x/h_z²;
// 0, 1/h_z, −h_y/h_z²], the row J = g · A = ∂r/∂p_c, and
//   ∂r/∂t = J;
//   ∂r/∂δ = J · R · (ω × p_m + v)      (d/de Exp(eξ)·p = ξ^ · Exp(eξ)·p: a constant twist
//                                        commutes with its own exponential);
//   ∂r/∂θ = −2 · J · [R·p_m]×          (tangent θ of EigenQuaternionManifold: q ⊕ θ =
//                                        [cos|θ|, sin|θ|·θ/|θ|] ⊗ q rotates by 2θ on the camera
//                                        side, so p_c moves by 2θ × R·p_m);
//   ∂r/∂q = ∂r/∂θ · Mᵀ / |q|           (ambient, with M = ∂(q ⊕ θ)/∂θ at θ = 0 for the unit q̂:
//                                        Mᵀ = [q̂_w·I + [q̂_v]× | −q̂_v]; M has orthonormal columns
//                                        orthogonal to q̂, so this is the exact gradient of the
//                                        normalised function and Ceres' M·(·) gives ∂r/∂θ back).
//
// Parameters: the extrinsic T_camera_lidar as one block [qx, qy, qz, qw, tx, ty, tz] (Eigen
// quaternion order, on ProductManifold<EigenQuaternionManifold, EuclideanManifold<3>>) and the
// time offset δ [s] as its own block. A point that falls behind the camera or outside the image
// costs the constant `outside_px` (the map's cap) with zero derivative: it is dropped for that
// evaluation rather than clamped to the border, and leaving the image is never a way to lower
// the cost.
class EdgeAlignmentCost : public ceres::SizedCostFunction<1, 7, 1> {
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

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* pose = parameters[0];
    const Eigen::Map<const Eigen::Vector4d> q_coeffs(pose);
    const double q_norm = q_coeffs.norm();
    const Eigen::Quaterniond q(q_coeffs / q_norm);  // unit: the residual ignores |q|
    const Eigen::Map<const Eigen::Vector3d> t(pose + 4);
    const double e = e0_s_ + parameters[1][0];
    const Eigen::Vector3d p_moved = ApplyLidarMotion<double>(twist_, e, point_lidar_);
    const Eigen::Vector3d p_rotated = q * p_moved;
    Eigen::Vector2d pixel;
    Eigen::Matrix<double, 2, 3> d_pixel_d_point;
    if (!camera_->ProjectWithJacobian(p_rotated + t, &pixel, &d_pixel_d_point) || !Inside(pixel)) {
      residuals[0] = sqrt_weight_ * outside_px_;
      if (jacobians != nullptr) {
        if (jacobians[0] != nullptr) std::fill(jacobians[0], jacobians[0] + 7, 0.0);
        if (jacobians[1] != nullptr) jacobians[1][0] = 0.0;
      }
      return true;
    }
    double value, d_dv, d_du;
    map_->Evaluate(pixel.y(), pixel.x(), &value, &d_dv, &d_du);
    residuals[0] = sqrt_weight_ * value;
    if (jacobians == nullptr) return true;
    const Eigen::RowVector3d d_point =
        sqrt_weight_ * Eigen::RowVector2d(d_du, d_dv) * d_pixel_d_point;
    if (jacobians[0] != nullptr) {
      const Eigen::RowVector3d d_theta = 2.0 * p_rotated.cross(d_point.transpose()).transpose();
      Eigen::Matrix<double, 3, 4> m_transpose;
      m_transpose.leftCols<3>() << q.w(), -q.z(), q.y(),  //
          q.z(), q.w(), -q.x(),                           //
          -q.y(), q.x(), q.w();
      m_transpose.col(3) = -q.vec();
      Eigen::Map<Eigen::Matrix<double, 1, 7>> j_pose(jacobians[0]);
      j_pose.head<4>() = d_theta * m_transpose / q_norm;
      j_pose.tail<3>() = d_point;
    }
    if (jacobians[1] != nullptr) {
      jacobians[1][0] = d_point.dot(q * (twist_.angular_rad_s.cross(p_moved) + twist_.linear_m_s));
    }
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& point_lidar, double weight,
                                     const LidarTwist& twist, double e0_s,
                                     const CameraModel* camera, const DistanceInterpolator* map,
                                     double outside_px) {
    return new EdgeAlignmentCost(point_lidar, weight, twist, e0_s, camera, map, outside_px);
  }

 private:
  bool Inside(const Eigen::Vector2d& pixel) const {
    // One pixel of margin keeps the bicubic stencil on real data.
    return pixel.x() >= 1 && pixel.y() >= 1 && pixel.x() <= camera_->width - 2 &&
           pixel.y() <= camera_->height - 2;
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
