#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace stcalib {

// Weak prior tying the refinement to a reference calibration (the search result, or the mount
// drawing), docs/method.md §6:
//
//   Δq = q0⁻¹ ⊗ q               rotation from the reference, on the LiDAR side
//   r_rot   = 2·sign(Δq_w)·Δq_xyz / σ_rot     (≈ the rotation vector of R0ᵀ·R for small angles)
//   r_trans = L · (t − t0),  L = √(information) (3×3; L = I/σ_trans for an isotropic prior)
//   r_time  = (δ − δ0) / σ_time
//
// Seven residuals, dimensionless. Blocks as in EdgeAlignmentCost: [qx, qy, qz, qw, tx, ty, tz]
// and δ. Holding translation with σ_trans keeps δ and the forward translation, which are nearly
// inseparable on a straight road (docs/method.md §10), from drifting along their ridge together.
class CalibrationPriorCost {
 public:
  CalibrationPriorCost(const Eigen::Quaterniond& q0, const Eigen::Vector3d& t0, double delta0_s,
                       double sigma_rotation_rad,
                       const Eigen::Matrix3d& sqrt_information_translation, double sigma_time_s)
      : q0_inverse_(q0.conjugate().normalized()),
        t0_(t0),
        delta0_s_(delta0_s),
        inv_sigma_rotation_(1.0 / sigma_rotation_rad),
        sqrt_information_translation_(sqrt_information_translation),
        inv_sigma_time_(1.0 / sigma_time_s) {}

  template <typename T>
  bool operator()(const T* const pose, const T* const time_offset, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(pose);
    const Eigen::Quaternion<T> dq = q0_inverse_.cast<T>() * q;
    const T sign = dq.w() < T(0) ? T(-1) : T(1);
    const Eigen::Matrix<T, 3, 1> dt(pose[4] - T(t0_[0]), pose[5] - T(t0_[1]), pose[6] - T(t0_[2]));
    const Eigen::Matrix<T, 3, 1> r_t = sqrt_information_translation_.cast<T>() * dt;
    for (int k = 0; k < 3; ++k) {
      residual[k] = T(2 * inv_sigma_rotation_) * sign * dq.vec()[k];
      residual[3 + k] = r_t[k];
    }
    residual[6] = (time_offset[0] - T(delta0_s_)) * T(inv_sigma_time_);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Quaterniond& q0, const Eigen::Vector3d& t0,
                                     double delta0_s, double sigma_rotation_rad,
                                     double sigma_translation_m, double sigma_time_s) {
    return Create(q0, t0, delta0_s, sigma_rotation_rad,
                  Eigen::Matrix3d::Identity() / sigma_translation_m, sigma_time_s);
  }
  static ceres::CostFunction* Create(const Eigen::Quaterniond& q0, const Eigen::Vector3d& t0,
                                     double delta0_s, double sigma_rotation_rad,
                                     const Eigen::Matrix3d& sqrt_information_translation,
                                     double sigma_time_s) {
    return new ceres::AutoDiffCostFunction<CalibrationPriorCost, 7, 7, 1>(new CalibrationPriorCost(
        q0, t0, delta0_s, sigma_rotation_rad, sqrt_information_translation, sigma_time_s));
  }

 private:
  const Eigen::Quaterniond q0_inverse_;
  const Eigen::Vector3d t0_;
  const double delta0_s_;
  const double inv_sigma_rotation_;
  const Eigen::Matrix3d sqrt_information_translation_;
  const double inv_sigma_time_;
};

}  // namespace stcalib
