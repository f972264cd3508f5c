#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/io/kitti_calib.h"
#include "core/types/camera_model.h"
#include "core/types/transform.h"

namespace stcalib {

// CameraModel from calib_cam_to_cam.txt with the image size read from the image.
CameraModel MakeCameraModel(const CameraCalibration& calibration, int width, int height);

struct ProjectedPoint {
  Eigen::Vector2d pixel;  ///< [px]
  double depth_m = 0.0;   ///< rectified z [m]
  int index = 0;          ///< index of the source point
};

// Projects LiDAR points through T_camera_lidar; keeps those in front of the camera and inside
// the image.
std::vector<ProjectedPoint> ProjectPoints(const CameraModel& camera, const Rigid3d& T_camera_lidar,
                                          const std::vector<Eigen::Vector3d>& points_lidar);

}  // namespace stcalib
