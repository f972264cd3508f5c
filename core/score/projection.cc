#include "core/score/projection.h"

namespace stcalib {

CameraModel MakeCameraModel(const CameraCalibration& calibration, int width, int height) {
  CameraModel camera;
  camera.R_rect_00 = calibration.R_rect_00;
  camera.P_rect = calibration.P_rect;
  camera.width = width;
  camera.height = height;
  return camera;
}

std::vector<ProjectedPoint> ProjectPoints(const CameraModel& camera, const Rigid3d& T_camera_lidar,
                                          const std::vector<Eigen::Vector3d>& points_lidar) {
  std::vector<ProjectedPoint> projected;
  projected.reserve(points_lidar.size() / 4);
  for (size_t i = 0; i < points_lidar.size(); ++i) {
    ProjectedPoint p;
    if (!camera.Project(T_camera_lidar * points_lidar[i], &p.pixel, &p.depth_m)) continue;
    if (!camera.InImage(p.pixel)) continue;
    p.index = static_cast<int>(i);
    projected.push_back(p);
  }
  return projected;
}

}  // namespace stcalib
