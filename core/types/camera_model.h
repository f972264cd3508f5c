#pragma once

#include <Eigen/Core>

namespace stcalib {

// A rectified camera (docs/method.md §1): a point p_camera of the camera's frame (KITTI: the
// unrectified camera 0, which every KITTI camera projects from) projects as
// u ~ P_rect · [R_rect_00 · p_camera; 1], P_rect the camera's own (KITTI: P_rect_02 of image_02).
struct CameraModel {
  Eigen::Matrix3d R_rect_00 = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 3, 4> P_rect = Eigen::Matrix<double, 3, 4>::Zero();
  int width = 0;             ///< [px], read from the image or S_rect_02, never assumed
  int height = 0;            ///< [px]
  double min_depth_m = 0.5;  ///< points nearer than this (rectified z) are not projected [m]

  // Projects a point of the unrectified camera-0 frame. Returns false when the point is not in
  // front of the camera (rectified z < min_depth_m).
  bool Project(const Eigen::Vector3d& p_camera, Eigen::Vector2d* pixel, double* depth_m) const {
    return Project(p_camera, pixel, depth_m, nullptr);
  }

  // Project() with the Jacobian of the pixel with respect to p_camera:
  //   h = P·R_rect·p + p4, (u, v) = (h_x/h_z, h_y/h_z),
  //   ∂(u, v)/∂p = [1/h_z, 0, −h_x/h_z²; 0, 1/h_z, −h_y/h_z²] · P · R_rect.
  bool ProjectWithJacobian(const Eigen::Vector3d& p_camera, Eigen::Vector2d* pixel,
                           Eigen::Matrix<double, 2, 3>* d_pixel_d_point) const {
    double depth_m;
    return Project(p_camera, pixel, &depth_m, d_pixel_d_point);
  }

  bool InImage(const Eigen::Vector2d& pixel) const {
    return pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() <= width - 1.0 &&
           pixel.y() <= height - 1.0;
  }

 private:
  // Both of the above: the Jacobian only when `d_pixel_d_point` is given.
  bool Project(const Eigen::Vector3d& p_camera, Eigen::Vector2d* pixel, double* depth_m,
               Eigen::Matrix<double, 2, 3>* d_pixel_d_point) const {
    const Eigen::Vector3d p_rect = R_rect_00 * p_camera;
    if (p_rect.z() < min_depth_m) return false;
    const Eigen::Vector3d h = P_rect.leftCols<3>() * p_rect + P_rect.col(3);
    if (h.z() <= 0) return false;
    const double inv_z = 1.0 / h.z();
    (*pixel) << h.x() * inv_z, h.y() * inv_z;
    *depth_m = p_rect.z();
    if (d_pixel_d_point != nullptr) {
      Eigen::Matrix<double, 2, 3> d_pixel_d_h;
      d_pixel_d_h << inv_z, 0, -(*pixel)(0) * inv_z, 0, inv_z, -(*pixel)(1) * inv_z;
      *d_pixel_d_point = d_pixel_d_h * P_rect.leftCols<3>() * R_rect_00;
    }
    return true;
  }
};

}  // namespace stcalib
