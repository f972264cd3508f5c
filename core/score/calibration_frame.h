#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "core/features/image_features.h"
#include "core/features/lidar_edges.h"
#include "core/motion/motion_model.h"
#include "core/types/calibration.h"
#include "core/types/camera_model.h"

namespace stcalib {

// Everything of a frame but its LiDAR edge points: the image, its maps, the stamps and the motion.
struct FrameImageAndMotion {
  int index = 0;             ///< frame of the drive
  double e0_s = 0;           ///< LiDAR stamp − camera stamp [s]; the gap is e = e0 + δ
  double camera_time_s = 0;  ///< image stamp on the drive's clock [s] (frames must advance)
  LidarTwist twist;          ///< LiDAR body twist at the image time (motion model,
                             ///< docs/method.md §3)
  CameraModel camera;        ///< size read from the image
  ImageFeatures image;       ///< distance_raw_px for overlays
  // Maps per edge kind, indexed by EdgeKind (0 vertical, 1 horizontal): with oriented maps a
  // vertical LiDAR edge reads the map of near-vertical image edges only; otherwise both entries
  // share the same map.
  // Score maps, coarsest first, finest last (IDTs of growing sharpness).
  std::array<std::vector<cv::Mat>, 2> score_maps;
  // Plain (not suppressed) IDT: its mean at the projected points is the gray rate that picks
  // the search's step sizes (docs/method.md §6).
  std::array<cv::Mat, 2> gray_map;
  // Smoothed, capped distance maps for the refinement's bicubic residuals [px].
  std::array<cv::Mat, 2> distance_px;
  // The largest value of the two distance maps: the residual of a point outside the image [px];
  // 0 = not yet known (the refinement then finds it).
  double distance_cap_px = 0;
  // The finest score maps are the band-pass IDTs, whose positive parts are the texture-suppressed
  // IDTs (ImageFeatures::idt_suppressed, which the frame then need not keep: TextureSuppressedMap).
  bool score_maps_bandpass = false;
  // The acquisition's coarse maps per edge kind (CoarseScoreMap): CV_32F at 1/coarse_map_scale
  // of the image size, one zero cell of padding on each side; empty: the frame has none.
  std::array<cv::Mat, 2> coarse_map;
  int coarse_map_scale = 0;
  // > 0: the frame keeps no gray_map; its plain IDT is 255·(1 − distance_px/gray_basin_px), as
  // the image features make it from the same distance map (PlainIdt) [px].
  double gray_basin_px = 0;
};

// The plain IDT of edge kind `kind` (the gray rate's map): gray_map, or, when the frame keeps
// none (gray_basin_px > 0), made from its distance map exactly as the image features make it.
// Empty when the frame has neither.
cv::Mat PlainIdt(const FrameImageAndMotion& frame, int kind);

// The texture-suppressed IDT of edge kind `kind`: the image features' own, or, when the frame
// scores on the band-pass IDT, its positive part (the same values: ExtractImageFeatures makes the
// one from the other). Empty when the frame has neither.
cv::Mat TextureSuppressedMap(const FrameImageAndMotion& frame, int kind);

// One image with its LiDAR edge points: everything the score, the search and the refinement read.
// The per-point fields are the ones below; ClearPoints, TakePoints and WithPoints are the only
// code that lists them, so a new one is added there and nowhere else.
struct CalibrationFrame : FrameImageAndMotion {
  std::vector<Eigen::Vector3d> points_lidar;  ///< edge points (local map), at the LiDAR stamp
  std::vector<EdgeKind> kinds;
  // ∂p/∂δ [m/s] (LidarEdges::offset_rate), read by the refinement; empty: all zero.
  std::vector<Eigen::Vector3d> offset_rates;
  // 1: the point is a fold (LidarEdges::fold); empty: none is.
  std::vector<uint8_t> folds;
  // Frames between the sweep of each point and this frame's own (LidarEdges::sweep_age); empty:
  // all from its own.
  std::vector<uint8_t> sweep_ages;

  size_t size() const { return points_lidar.size(); }
  // Whether every optional per-point field is empty or has an entry per point.
  bool PointFieldsConsistent() const;
  void ClearPoints();
  // The points of a local map, moved out of `edges` (its capture times and scan indices are not
  // kept).
  void TakePoints(LidarEdges&& edges);
  // The same image and maps with the points at `indices` only (in that order), each with its
  // per-point entries; the points are copied, nothing else is (the maps share their data).
  CalibrationFrame WithPoints(const std::vector<size_t>& indices) const;
};

inline cv::Mat TextureSuppressedMap(const FrameImageAndMotion& frame, int kind) {
  const cv::Mat& oriented = frame.image.oriented[kind].idt_suppressed;
  const cv::Mat& own = oriented.empty() ? frame.image.idt_suppressed : oriented;
  if (!own.empty() || !frame.score_maps_bandpass || frame.score_maps[kind].empty()) return own;
  cv::Mat positive;
  cv::max(frame.score_maps[kind].back(), 0.0, positive);
  return positive;
}

inline cv::Mat PlainIdt(const FrameImageAndMotion& frame, int kind) {
  if (!frame.gray_map[kind].empty() || !(frame.gray_basin_px > 0)) return frame.gray_map[kind];
  cv::Mat idt;
  frame.distance_px[kind].convertTo(idt, CV_32F, -255.0 / frame.gray_basin_px, 255.0);
  return idt;
}

// Frames that share sweeps through their local maps: 1 + the oldest sweep any point of `frames`
// comes from (CalibrationFrame::sweep_ages; 1 without ages). The jackknife leaves out blocks of
// this many frames, so that a block's sweeps are not all still in the frames it keeps; the
// acquisition's dominance counts them once.
inline int SharedSweepFrames(const std::vector<const CalibrationFrame*>& frames) {
  int oldest = 0;
  for (const CalibrationFrame* frame : frames) {
    for (uint8_t age : frame->sweep_ages) oldest = std::max<int>(oldest, age);
  }
  return oldest + 1;
}

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

inline bool CalibrationFrame::PointFieldsConsistent() const {
  const size_t n = size();
  return kinds.size() == n && (offset_rates.empty() || offset_rates.size() == n) &&
         (folds.empty() || folds.size() == n) && (sweep_ages.empty() || sweep_ages.size() == n);
}

inline void CalibrationFrame::ClearPoints() {
  points_lidar.clear();
  kinds.clear();
  offset_rates.clear();
  folds.clear();
  sweep_ages.clear();
}

inline void CalibrationFrame::TakePoints(LidarEdges&& edges) {
  points_lidar = std::move(edges.points_lidar);
  kinds = std::move(edges.kind);
  offset_rates = std::move(edges.offset_rate);
  folds = std::move(edges.fold);
  sweep_ages = std::move(edges.sweep_age);
}

inline CalibrationFrame CalibrationFrame::WithPoints(const std::vector<size_t>& indices) const {
  CalibrationFrame out;
  static_cast<FrameImageAndMotion&>(out) = *this;
  auto pick = [&](const auto& from, auto* to) {
    if (from.empty()) return;
    to->reserve(indices.size());
    for (size_t i : indices) to->push_back(from[i]);
  };
  pick(points_lidar, &out.points_lidar);
  pick(kinds, &out.kinds);
  pick(offset_rates, &out.offset_rates);
  pick(folds, &out.folds);
  pick(sweep_ages, &out.sweep_ages);
  return out;
}

}  // namespace stcalib
