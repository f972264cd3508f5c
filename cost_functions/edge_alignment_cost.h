#pragma once

#include <ceres/cost_function.h>
#include <ceres/cubic_interpolation.h>
#include <ceres/loss_function.h>
#include <glog/logging.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/motion/motion_model.h"
#include "core/types/camera_model.h"

namespace stcalib {

// The smoothed distance map of an image (distance to the nearest image edge, capped at the
// basin, in pixels), row-major float, sampled bicubically.
using DistanceGrid = ceres::Grid2D<float, 1>;
using DistanceInterpolator = ceres::BiCubicInterpolator<DistanceGrid>;

// Edge-alignment residuals of one frame's LiDAR edge points (docs/method.md §6), one residual per
// point, all in one residual block.
//
// A LiDAR edge point p, de-skewed to its sweep stamp t_l, is carried to the image time t_c by the
// LiDAR's own motion and then into the camera:
//
//   e        = (t_l + δ) − t_c = e0 + δ                       (docs/method.md §2; one e per frame)
//   p_m      = Tv(e) · p,       Tv(e) = Exp(e · ξ_L)           (ξ_L = (ω, v): LiDAR body twist, §3)
//   p_c      = R · p_m + t,     R = R(q / |q|)
//   h        = P · R_rect · p_c + p4,   (u, v) = (h_x / h_z, h_y / h_z)
//   r        = √w · D(v, u)
//
// with D the smoothed distance map of the point's edge kind read by a bicubic interpolator,
// P | p4 = P_rect_02 and w the point's weight (horizontal and vertical edges weighted w and
// 1 − w). r is in pixels.
//
// Jacobians (analytic). With g = √w · [∂D/∂u, ∂D/∂v], K = P · R_rect and
// ∂(u, v)/∂h = [1/h_z, 0, −u/h_z; 0, 1/h_z, −v/h_z], the row J = g · ∂(u, v)/∂h · K = ∂r/∂p_c,
// i.e. J = (g_u · (K₀ − u·K₂) + g_v · (K₁ − v·K₂)) / h_z with K_i the rows of K, and
//   ∂r/∂t = J;
//   ∂r/∂δ = J · R · (ω × p_m + v)      (d/de Exp(eξ)·p = ξ^ · Exp(eξ)·p: a constant twist
//                                        commutes with its own exponential);
//   ∂r/∂θ = 2 · (R·p_m) × J            (tangent θ of EigenQuaternionManifold: q ⊕ θ =
//                                        [cos|θ|, sin|θ|·θ/|θ|] ⊗ q rotates by 2θ on the camera
//                                        side, so p_c moves by 2θ × R·p_m, and
//                                        J·(2θ × a) = θ · 2(a × Jᵀ));
//   ∂r/∂q = ∂r/∂θ · Mᵀ / |q|           (ambient, with M = ∂(q ⊕ θ)/∂θ at θ = 0 for the unit q̂:
//                                        Mᵀ = [q̂_w·I + [q̂_v]× | −q̂_v]; M has orthonormal columns
//                                        orthogonal to q̂, so this is the exact gradient of the
//                                        normalised function and Ceres' M·(·) gives ∂r/∂θ back).
//
// The robust loss ρ is applied per point here, not by Ceres (Ceres would apply it to the whole
// block's squared norm), in the form Ceres itself uses for a one-residual block under a loss with
// ρ'' ≤ 0 (Cauchy, Huber: its Corrector with α = 0). With s = r²:
//   r̃_i = √ρ'(s_i) · r_i,   ∂r̃_i = √ρ'(s_i) · ∂r_i        (one per point)
//   r̃_n = √(Σ_i ρ(s_i) − ρ'(s_i)·s_i),   ∂r̃_n = 0        (one more residual)
// so that ½Σr̃² = ½Σρ(s_i), the cost; J̃ᵀr̃ = Σρ'·r·∂r, its exact gradient; and J̃ᵀJ̃ = Σρ'·∂rᵀ∂r,
// Ceres' Gauss-Newton model and the matrix ceres::Covariance reads. ∂r̃_i is therefore not the
// derivative of r̃_i (a loss-weighted residual, as in iteratively reweighted least squares);
// the last residual is ≥ 0 because ρ(s) ≥ ρ'(s)·s for a concave ρ with ρ(0) = 0.
// Without a loss the block has the n plain residuals only.
//
// Why one block per frame (not one per point): Tv(e), R and K·R are computed once per frame and
// Ceres' per-block bookkeeping is paid 20 times, not 6000 (BM_Refine/12: see benchmarks).
//
// Parameters: the extrinsic T_camera_lidar as one block [qx, qy, qz, qw, tx, ty, tz] (Eigen
// quaternion order, on a ProductManifold of EigenQuaternionManifold and a translation manifold:
// free, along the direction of travel, or held; see RefineOptions) and the time offset δ [s] as
// its own block. A point that falls behind the camera or outside the image
// costs the constant `outside_px` (the map's cap) with zero derivative: it is dropped for that
// evaluation rather than clamped to the border, and leaving the image is never a way to lower
// the cost.
class EdgeAlignmentCost : public ceres::CostFunction {
 public:
  struct Point {
    Eigen::Vector3d p_lidar;  ///< de-skewed to the sweep stamp (local map: placed at δ) [m]
    double weight = 1;        ///< w > 0
    int kind = 0;             ///< index into the maps (EdgeKind)
  };

  // `maps` indexed by Point::kind; `camera`, the maps and `loss` (nullptr = none) must outlive
  // the cost.
  EdgeAlignmentCost(std::vector<Point> points, const LidarTwist& twist, double e0_s,
                    const CameraModel* camera, std::array<const DistanceInterpolator*, 2> maps,
                    double outside_px, const ceres::LossFunction* loss)
      : points_(std::move(points)),
        twist_(twist),
        e0_s_(e0_s),
        camera_(camera),
        maps_(maps),
        outside_px_(outside_px),
        loss_(loss),
        K_(camera->P_rect.leftCols<3>() * camera->R_rect_00),
        depth_row_(camera->R_rect_00.row(2)) {
    CHECK(!points_.empty());
    for (Point& point : points_) {
      CHECK(point.kind >= 0 && point.kind < 2 && maps_[point.kind] != nullptr);
      CHECK_GT(point.weight, 0);
      point.weight = std::sqrt(point.weight);  // kept as √w
    }
    set_num_residuals(static_cast<int>(points_.size()) + (loss_ != nullptr ? 1 : 0));
    mutable_parameter_block_sizes()->push_back(7);
    mutable_parameter_block_sizes()->push_back(1);
  }

  size_t num_points() const { return points_.size(); }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* pose = parameters[0];
    const Eigen::Map<const Eigen::Vector4d> q_coeffs(pose);
    const double q_norm = q_coeffs.norm();
    const Eigen::Quaterniond q(q_coeffs / q_norm);  // unit: the residual ignores |q|
    const Eigen::Matrix3d R = q.toRotationMatrix();
    const Eigen::Map<const Eigen::Vector3d> t(pose + 4);
    const Rigid3d Tv = LidarMotion(twist_, e0_s_ + parameters[1][0]);
    // p_c = R·(R_v·p + t_v) + t = A·p + b; h = K·p_c + p4.
    const Eigen::Matrix3d A = R * Tv.linear();
    const Eigen::Vector3d b = R * Tv.translation() + t;
    const Eigen::Vector3d p4 = camera_->P_rect.col(3);
    double* j_pose = jacobians != nullptr ? jacobians[0] : nullptr;
    double* j_delta = jacobians != nullptr ? jacobians[1] : nullptr;
    Eigen::Matrix<double, 3, 4> m_transpose;            // ∂θ → ∂q (see the header)
    m_transpose.leftCols<3>() << q.w(), -q.z(), q.y(),  //
        q.z(), q.w(), -q.x(),                           //
        -q.y(), q.x(), q.w();
    m_transpose.col(3) = -q.vec();
    m_transpose /= q_norm;
    const double width_limit = camera_->width - 2, height_limit = camera_->height - 2;
    double loss_rest = 0;  // Σ ρ(s) − ρ'(s)·s
    for (size_t i = 0; i < points_.size(); ++i) {
      const Point& point = points_[i];
      const Eigen::Vector3d p_c = A * point.p_lidar + b;
      double r = point.weight * outside_px_;
      Eigen::RowVector3d d_point = Eigen::RowVector3d::Zero();
      bool inside = depth_row_.dot(p_c) >= camera_->min_depth_m;
      Eigen::Vector3d h;
      if (inside) {
        h = K_ * p_c + p4;
        inside = h.z() > 0;
      }
      double u = 0, v = 0;
      if (inside) {
        u = h.x() / h.z();
        v = h.y() / h.z();
        // One pixel of margin keeps the bicubic stencil on real data.
        inside = u >= 1 && v >= 1 && u <= width_limit && v <= height_limit;
      }
      if (inside) {
        double value, d_dv, d_du;
        maps_[point.kind]->Evaluate(v, u, &value, &d_dv, &d_du);
        r = point.weight * value;
        if (jacobians != nullptr) {
          d_point = (point.weight / h.z()) *
                    (d_du * (K_.row(0) - u * K_.row(2)) + d_dv * (K_.row(1) - v * K_.row(2)));
        }
      }
      double scale = 1;  // √ρ'(s)
      if (loss_ != nullptr) {
        double rho[3];
        loss_->Evaluate(r * r, rho);
        scale = std::sqrt(std::max(rho[1], 0.0));
        loss_rest += std::max(rho[0] - rho[1] * r * r, 0.0);
      }
      residuals[i] = scale * r;
      if (jacobians == nullptr) continue;
      d_point *= scale;
      if (j_pose != nullptr) {
        Eigen::Map<Eigen::Matrix<double, 1, 7>> row(j_pose + 7 * i);
        if (inside) {
          const Eigen::Vector3d p_rotated = p_c - t;  // R·p_m
          const Eigen::RowVector3d d_theta = 2.0 * p_rotated.cross(d_point.transpose()).transpose();
          row.head<4>() = d_theta * m_transpose;
          row.tail<3>() = d_point;
        } else {
          row.setZero();
        }
      }
      if (j_delta != nullptr) {
        if (inside) {
          const Eigen::Vector3d p_m = Tv * point.p_lidar;
          j_delta[i] = d_point.dot(R * (twist_.angular_rad_s.cross(p_m) + twist_.linear_m_s));
        } else {
          j_delta[i] = 0;
        }
      }
    }
    if (loss_ != nullptr) {
      const size_t n = points_.size();
      residuals[n] = std::sqrt(loss_rest);
      if (j_pose != nullptr) std::fill(j_pose + 7 * n, j_pose + 7 * (n + 1), 0.0);
      if (j_delta != nullptr) j_delta[n] = 0;
    }
    return true;
  }

 private:
  std::vector<Point> points_;
  const LidarTwist twist_;
  const double e0_s_;
  const CameraModel* camera_;
  const std::array<const DistanceInterpolator*, 2> maps_;
  const double outside_px_;
  const ceres::LossFunction* loss_;
  const Eigen::Matrix3d K_;             // P · R_rect
  const Eigen::RowVector3d depth_row_;  // rectified depth of p_c
};

}  // namespace stcalib
