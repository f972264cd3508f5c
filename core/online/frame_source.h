#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "core/features/image_features.h"
#include "core/features/lidar_frame.h"
#include "core/io/drive.h"
#include "core/motion/drive_motion.h"
#include "core/score/calibration_frame.h"
#include "core/types/status.h"

namespace stcalib {

struct FrameSourceOptions {
  ImageFeatureOptions image;
  LidarFeatureOptions lidar;
  LocalMapOptions local_map;
  // Dense foliage traps the plain IDT score degrees from the truth (docs/method.md §10): score on
  // texture-suppressed maps.
  bool suppress_texture = true;  ///< score maps are the texture-suppressed IDTs
  // With suppress_texture: the finest score map is the band-pass IDT (not clipped at zero, see
  // BandPass: foliage averages to zero instead of pulling points into it) rather than the clipped
  // one. The health check keeps the clipped maps its thresholds were measured on.
  bool bandpass_score = true;
  bool oriented_maps = true;  ///< vertical/horizontal LiDAR edges read their own maps
  // A frame whose image time lies in a longer gap between oxts packets (or further from the
  // nearest one) is refused: its motion model would be a guess [s].
  double max_oxts_gap_s = 0.25;
  // The dynamic filter judges only the clusters that reach the camera's horizontal field of
  // view, widened by this on each side, as `view_T_camera_lidar` (unset: the drive's
  // calibration) places it; the points the calibration uses are judged exactly as without the
  // window. It must cover how far the estimate may move from that calibration. Negative: judge
  // the whole sweep [deg].
  double view_margin_deg = 20.0;
  std::optional<Rigid3d> view_T_camera_lidar;

  FrameSourceOptions() {
    // Calibration wants precision over recall from the dynamic filter: a moving point left in
    // costs little under the robust loss, but a static structure removed because its occlusion
    // boundaries moved between viewpoints takes the nearest, most informative edges with it.
    lidar.dynamic.min_flagged_fraction = 0.3;
  }
  Status Validate() const;
  // The image options every frame is extracted with: `image` plus the map choices above.
  ImageFeatureOptions ImageOptions() const;
};

// Turns the frames of a drive into CalibrationFrames, in time order: image features, the local
// map of LiDAR edges (de-skewed, dynamic points removed), the LiDAR twist at the image time and
// the stamp gap. Sweeps are cached, so a sequential pass computes each one once.
// The LiDAR azimuth window [centre, half angle] in degrees that holds the camera's horizontal
// field of view (the rays through the rectified image's corners and edge midpoints) widened by
// `margin_deg`; a half angle of 0 (the whole sweep) when the camera looks nearly straight up or
// down, where an azimuth window cannot hold its view.
Eigen::Vector2d CameraAzimuthWindowDeg(const CameraCalibration& camera, int image_width,
                                       int image_height, const Rigid3d& T_camera_lidar,
                                       double margin_deg);

// The smallest azimuth window [centre, half angle] in degrees that holds every window of
// `windows` (CameraAzimuthWindowDeg's), to 0.5°; a half angle of 0 (the whole sweep) when one of
// them is the whole sweep or together they leave no gap.
Eigen::Vector2d AzimuthWindowUnionDeg(const std::vector<Eigen::Vector2d>& windows);

// One camera's frame, as DriveFrameSource::LoadCameras returns it.
struct CameraFrameLoad {
  Status status = Status::Ok();  ///< a failed frame comes with its error
  std::shared_ptr<CalibrationFrame> frame;
};

class DriveFrameSource {
 public:
  // The motion model comes from the drive's oxts, or, without oxts/ or without
  // calib_imu_to_velo.txt, from registering consecutive sweeps (constant velocity); errors say
  // why neither works.
  static Status Create(const Drive* drive, const FrameSourceOptions& options,
                       std::unique_ptr<DriveFrameSource>* source) {
    return Create(std::vector<const Drive*>{drive}, options, source);
  }
  // Several cameras of one drive (one Drive each, the same LiDAR and frames; the first's LiDAR
  // and motion are read): each frame's sweeps, LiDAR features, local map and dynamic filter are
  // computed once and shared by every camera. The dynamic filter judges the union of the
  // cameras' views. Errors name a camera whose frames or LiDAR stamps differ from the first's.
  static Status Create(const std::vector<const Drive*>& cameras, const FrameSourceOptions& options,
                       std::unique_ptr<DriveFrameSource>* source);
  // Frame `frame` of a single-camera source (LoadCameras's one entry).
  Status Load(size_t frame, CalibrationFrame* out);
  // Frame `frame` of every camera, in Create's order. A failed image fails its camera's entry
  // only; a failed sweep or motion fails every entry.
  void LoadCameras(size_t frame, std::vector<CameraFrameLoad>* out);
  size_t cameras() const { return drives_.size(); }
  const DriveMotion& motion() const { return motion_; }
  // The azimuth window the dynamic filter judges (roi_center_azimuth_deg, roi_half_angle_deg).
  const DynamicFilterOptions& dynamic_options() const { return options_.lidar.dynamic; }

 private:
  DriveFrameSource(std::vector<const Drive*> drives, const FrameSourceOptions& options)
      : drives_(std::move(drives)), drive_(drives_.front()), options_(options) {}
  // The camera's image, maps, stamps and motion (no points); `camera` indexes drives_.
  Status LoadImageAndMotion(size_t camera, size_t frame, CalibrationFrame* out) const;
  std::vector<const Drive*> drives_;
  const Drive* drive_;  // the first camera's, whose LiDAR and motion every camera shares
  FrameSourceOptions options_;
  DriveMotion motion_;
  std::unique_ptr<SweepCache> cache_;
};

}  // namespace stcalib
