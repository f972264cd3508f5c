#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/score/calibration_frame.h"
#include "core/score/score.h"
#include "core/types/calibration.h"
#include "core/types/status.h"

namespace stcalib {

// Does a stored calibration still hold (docs/method.md §7)? Frames are taken in windows; each
// window gets the health score at the calibration (share of the 728 neighbours at ±1° / ±5 cm that
// score worse) and the best neighbour's score gain. A calibrated pair has health near 1 and no
// neighbour much better; a pair 1° off has a clearly better neighbour.
struct HealthCheckOptions {
  int window_frames = 3;
  double rotation_step_deg = 1.0;    ///< neighbour offset on roll, pitch, yaw [deg]
  double translation_step_m = 0.05;  ///< neighbour offset on x, y, z [m]
  // The calibration holds when the mean health over the windows is at least this (between a
  // calibrated pair's and one 1° off). Measured: docs/tuning.md#min-health
  double min_health = 0.85;
  // Health is a share and saturates along directions the scene barely constrains; the best
  // neighbour's score gain does not: the calibration is off when, on average over the windows,
  // some neighbour scores more than this share better. Measured: docs/tuning.md#max-neighbour-gain
  double max_neighbour_gain = 0.09;
  double point_margin = 0.02;      ///< points kept inside the image shrunk by this share
  int min_points_per_window = 60;  ///< fewer LiDAR edge points in the image: window skipped
  int min_windows = 2;             ///< fewer usable windows: no verdict
  ScoreOptions score;

  Status Validate() const;
};

struct WindowHealth {
  int first_frame = 0, last_frame = 0;  ///< frame indices of the drive
  int points = 0;                       ///< LiDAR edge points in the image
  double health = 0;                    ///< share of neighbours scoring worse, 0..1
  double gray_rate = 0;                 ///< mean score-map value at the points, 0..1
  double best_neighbour_gain = 0;       ///< the best neighbour's relative score gain
  bool used = false;
  std::string note;  ///< why a window was skipped
};

struct HealthCheckResult {
  bool decided = false;  ///< enough evidence for a verdict
  bool holds = false;    ///< the calibration still holds (only when decided)
  double mean_health = 0;
  double min_window_health = 0;
  double mean_neighbour_gain = 0;
  std::vector<WindowHealth> windows;
  std::string reason;  ///< the verdict or why there is none, in words
};

// `frames` in time order (consecutive windows of window_frames are scored). Whatever score maps
// the frames carry, each is scored on its clipped texture-suppressed IDT (the maps the
// thresholds above were measured on).
HealthCheckResult CheckCalibrationHealth(
    const std::vector<std::shared_ptr<const CalibrationFrame>>& frames,
    const CalibrationState& calibration, const HealthCheckOptions& options);

// A view of `frame` whose only score map per edge kind is its clipped texture-suppressed IDT.
std::shared_ptr<const CalibrationFrame> WithSuppressedScoreMaps(const CalibrationFrame& frame);

}  // namespace stcalib
