#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace stcalib {

// Rigid transforms are named T_<to>_<from>: T_camera_lidar maps a point expressed in the LiDAR
// frame to the camera frame, p_camera = T_camera_lidar * p_lidar.
using Rigid3d = Eigen::Isometry3d;

inline Rigid3d MakeRigid(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation) {
  Rigid3d T = Rigid3d::Identity();
  T.linear() = rotation;
  T.translation() = translation;
  return T;
}

// Rotation by the axis-angle vector `rotation_vector_rad` (exponential map of SO(3)).
inline Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& rotation_vector_rad) {
  const double angle = rotation_vector_rad.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, rotation_vector_rad / angle).toRotationMatrix();
}

// The rotation nearest to `m` in the Frobenius norm (U·Vᵀ of its SVD, with the sign that keeps
// det = +1). Calibration files print rotations to a few digits, so they are not exactly
// orthonormal.
inline Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

// Axis-angle vector of a rotation matrix (logarithm map of SO(3)), angle in [0, pi].
inline Eigen::Vector3d LogSO3(const Eigen::Matrix3d& rotation) {
  const Eigen::AngleAxisd aa(rotation);
  return aa.angle() * aa.axis();
}

}  // namespace stcalib
