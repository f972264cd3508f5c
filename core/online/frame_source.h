#pragma once

#include <memory>

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
  // Dense foliage traps the plain IDT score degrees from the truth (method.md §10): score on
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

  FrameSourceOptions() {
    image.pyramid_basins_px = {60, 30};
    // Calibration wants precision over recall from the dynamic filter: a moving point left in
    // costs little under the robust loss, but a static structure removed because its occlusion
    // boundaries moved between viewpoints takes the nearest, most informative edges with it.
    lidar.dynamic.min_flagged_fraction = 0.3;
  }
  Status Validate() const;
};

// Turns the frames of a drive into CalibrationFrames, in time order: image features, the local
// map of LiDAR edges (de-skewed, dynamic points removed), the LiDAR twist at the image time and
// the stamp gap. Sweeps are cached, so a sequential pass computes each one once.
class DriveFrameSource {
 public:
  // The motion model comes from the drive's oxts, or, without oxts/, from registering
  // consecutive sweeps (constant velocity); errors say why neither works.
  static Status Create(const Drive* drive, const FrameSourceOptions& options,
                       std::unique_ptr<DriveFrameSource>* source);
  Status Load(size_t frame, CalibrationFrame* out);
  const DriveMotion& motion() const { return motion_; }

 private:
  DriveFrameSource(const Drive* drive, const FrameSourceOptions& options)
      : drive_(drive), options_(options) {}
  const Drive* drive_;
  FrameSourceOptions options_;
  DriveMotion motion_;
  std::unique_ptr<SweepCache> cache_;
};

}  // namespace stcalib
