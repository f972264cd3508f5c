#include "core/motion/motion_model.h"

#include <glog/logging.h>

namespace stcalib {
namespace {

// Logarithm of SE(3): the twist ξ with Exp(ξ) = T.
void LogSE3(const Rigid3d& T, Eigen::Vector3d* phi, Eigen::Vector3d* u) {
  *phi = LogSO3(T.linear());
  const double theta = phi->norm();
  Eigen::Matrix3d V = Eigen::Matrix3d::Identity();
  if (theta > 1e-9) {
    Eigen::Matrix3d K;
    K << 0, -phi->z(), phi->y(), phi->z(), 0, -phi->x(), -phi->y(), phi->x(), 0;
    V += (1 - std::cos(theta)) / (theta * theta) * K +
         (theta - std::sin(theta)) / (theta * theta * theta) * K * K;
  }
  *u = V.inverse() * T.translation();
}

}  // namespace

Rigid3d LidarMotion(const LidarTwist& twist, double e_s) {
  Rigid3d T = Rigid3d::Identity();
  T.translation() = ApplyLidarMotion<double>(twist, e_s, Eigen::Vector3d::Zero());
  for (int k = 0; k < 3; ++k) {
    T.linear().col(k) =
        ApplyLidarMotion<double>(twist, e_s, Eigen::Vector3d::Unit(k)) - T.translation();
  }
  return T;
}

LidarTwist TwistFromPoses(const LidarPoseFunction& T_world_lidar, double t_s, double h_s) {
  CHECK_GT(h_s, 0);
  const Rigid3d T = T_world_lidar(t_s - h_s).inverse() * T_world_lidar(t_s + h_s);
  LidarTwist twist;
  LogSE3(T, &twist.angular_rad_s, &twist.linear_m_s);
  twist.angular_rad_s /= 2 * h_s;
  twist.linear_m_s /= 2 * h_s;
  return twist;
}

LidarTwist ConstantVelocityTwist(const Rigid3d& T_previous_current, double dt_s) {
  CHECK_GT(dt_s, 0);
  LidarTwist twist;
  LogSE3(T_previous_current, &twist.angular_rad_s, &twist.linear_m_s);
  twist.angular_rad_s /= dt_s;
  twist.linear_m_s /= dt_s;
  return twist;
}

}  // namespace stcalib
