#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "core/features/image_features.h"
#include "core/features/lidar_edges.h"
#include "core/motion/motion_model.h"
#include "core/types/calibration.h"
#include "core/types/camera_model.h"

namespace stcalib {

// One image with its LiDAR edge points: everything the score, the search and the refinement read.
struct CalibrationFrame {
  int index = 0;             ///< frame of the drive
  double e0_s = 0;           ///< LiDAR stamp − camera stamp [s]; the gap is e = e0 + δ
  double camera_time_s = 0;  ///< image stamp on the drive's clock [s] (frames must advance)
  LidarTwist twist;          ///< LiDAR body twist at the image time (motion model, method.md §3)
  CameraModel camera;        ///< size read from the image
  std::vector<Eigen::Vector3d> points_lidar;  ///< edge points (local map), at the LiDAR stamp
  std::vector<EdgeKind> kinds;
  // ∂p/∂δ [m/s] (LidarEdges::offset_rate), read by the refinement; empty: all zero.
  std::vector<Eigen::Vector3d> offset_rates;
  // 1: the point is a fold (LidarEdges::fold); empty: none is.
  std::vector<uint8_t> folds;
  // Frames between the sweep of each point and this frame's own (LidarEdges::sweep_age); empty:
  // all from its own.
  std::vector<uint8_t> sweep_ages;
  ImageFeatures image;  ///< distance_raw_px for overlays
  // Maps per edge kind, indexed by EdgeKind (0 vertical, 1 horizontal): with oriented maps a
  // vertical LiDAR edge reads the map of near-vertical image edges only; otherwise both entries
  // share the same map.
  // Score maps, coarsest first, finest last (IDTs of growing sharpness).
  std::array<std::vector<cv::Mat>, 2> score_maps;
  // Plain (not suppressed) IDT: its mean at the projected points is the gray rate that picks
  // the search's step sizes (method.md §6).
  std::array<cv::Mat, 2> gray_map;
  // Smoothed, capped distance maps for the refinement's bicubic residuals [px].
  std::array<cv::Mat, 2> distance_px;
  // The largest value of the two distance maps: the residual of a point outside the image [px];
  // 0 = not yet known (the refinement then finds it).
  double distance_cap_px = 0;

  size_t size() const { return points_lidar.size(); }
};

// Pixel of edge point i of `frame` at `state` (carried by the motion model over e0 + δ, then
// through T_camera_lidar and the camera); false when it falls behind the camera.
inline bool ProjectFramePoint(const CalibrationFrame& frame, const CalibrationState& state,
                              size_t i, Eigen::Vector2d* pixel) {
  const Eigen::Vector3d p =
      state.T_camera_lidar * ApplyLidarMotion<double>(frame.twist, frame.e0_s + state.time_offset_s,
                                                      frame.points_lidar[i]);
  double depth;
  return frame.camera.Project(p, pixel, &depth);
}

}  // namespace stcalib
