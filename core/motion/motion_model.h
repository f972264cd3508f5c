#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "core/motion/deskew.h"
#include "core/types/transform.h"

namespace stcalib {

// The LiDAR's velocity in its own frame (a body twist): p_L(t) = Tv · p_L(t + e) with
// Tv = T_L(t)←L(t+e) = Exp(e · ξ), ξ = (ω, v) (docs/method.md §3).
struct LidarTwist {
  Eigen::Vector3d angular_rad_s = Eigen::Vector3d::Zero();  ///< ω [rad/s]
  Eigen::Vector3d linear_m_s = Eigen::Vector3d::Zero();     ///< v [m/s]
};

// Tv(e) · p, the exact SE(3) exponential of e·ξ applied to p. Templated on the scalar so that a
// Ceres Jet in e (through the time offset δ) differentiates through it:
//   φ = e·ω, θ = |φ|, R = exp([φ]×),
//   V = I + (1 − cos θ)/θ² [φ]× + (θ − sin θ)/θ³ [φ]×²,  Tv·p = R·p + V·(e·v).
// Near θ = 0 the coefficients use their Taylor series (θ < 1e-4: errors below 1e-13).
template <typename T>
Eigen::Matrix<T, 3, 1> ApplyLidarMotion(const LidarTwist& twist, const T& e_s,
                                        const Eigen::Matrix<T, 3, 1>& p) {
  const Eigen::Matrix<T, 3, 1> phi = twist.angular_rad_s.cast<T>() * e_s;
  const Eigen::Matrix<T, 3, 1> u = twist.linear_m_s.cast<T>() * e_s;
  const T theta2 = phi.squaredNorm();
  T a, b, c;  // sin θ/θ, (1 − cos θ)/θ², (θ − sin θ)/θ³
  if (theta2 < T(1e-8)) {
    a = T(1) - theta2 / T(6);
    b = T(0.5) - theta2 / T(24);
    c = T(1.0 / 6.0) - theta2 / T(120);
  } else {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const T theta = sqrt(theta2);
    a = sin(theta) / theta;
    b = (T(1) - cos(theta)) / theta2;
    c = (theta - sin(theta)) / (theta2 * theta);
  }
  // Rodrigues: R·p = p + a·φ×p + b·φ×(φ×p); V·u = u + b·φ×u + c·φ×(φ×u).
  const Eigen::Matrix<T, 3, 1> phi_p = phi.cross(p);
  const Eigen::Matrix<T, 3, 1> phi_u = phi.cross(u);
  return p + a * phi_p + b * phi.cross(phi_p) + u + b * phi_u + c * phi.cross(phi_u);
}

// Tv(e) as a transform (double).
Rigid3d LidarMotion(const LidarTwist& twist, double e_s);

// Body twist of the LiDAR at time t from a pose function (central difference over ±h).
LidarTwist TwistFromPoses(const LidarPoseFunction& T_world_lidar, double t_s, double h_s = 0.005);

// Constant-velocity fallback: the twist that carries the previous sweep's pose to the current
// one over dt (from GPS positions or scan registration), T_previous_current = Exp(dt · ξ).
LidarTwist ConstantVelocityTwist(const Rigid3d& T_previous_current, double dt_s);

}  // namespace stcalib
