#include "core/online/health_check.h"

#include <glog/logging.h>

#include <algorithm>
#include <cstdio>

namespace stcalib {

std::shared_ptr<const CalibrationFrame> WithSuppressedScoreMaps(const CalibrationFrame& frame) {
  auto view = std::make_shared<CalibrationFrame>(frame);
  for (int kind = 0; kind < 2; ++kind) {
    const cv::Mat map = TextureSuppressedMap(frame, kind);
    view->score_maps[kind].clear();
    if (!map.empty()) view->score_maps[kind].push_back(map);
  }
  view->score_maps_bandpass = false;
  return view;
}

Status HealthCheckOptions::Validate() const {
  if (window_frames < 1 || min_windows < 1 || min_points_per_window < 1) {
    return Status::Error("health check: window_frames, min_windows and min points must be >= 1");
  }
  if (!(rotation_step_deg > 0) || !(translation_step_m > 0)) {
    return Status::Error("health check: neighbour steps must be positive");
  }
  if (!(max_neighbour_gain >= 0)) {
    return Status::Error("health check: max_neighbour_gain must be >= 0");
  }
  if (!(min_health >= 0 && min_health <= 1)) {
    return Status::Error("health check: min_health must be in [0, 1]");
  }
  if (!(point_margin >= 0 && point_margin < 0.5)) {
    return Status::Error("health check: point_margin must be in [0, 0.5)");
  }
  return Status::Ok();
}

HealthCheckResult CheckCalibrationHealth(
    const std::vector<std::shared_ptr<const CalibrationFrame>>& frames,
    const CalibrationState& calibration, const HealthCheckOptions& options) {
  CHECK(options.Validate().ok()) << options.Validate().message();
  HealthCheckResult result;
  double sum = 0, gain_sum = 0;
  int used = 0;
  result.min_window_health = 1.0;
  for (size_t begin = 0; begin < frames.size(); begin += options.window_frames) {
    const size_t end = std::min(frames.size(), begin + options.window_frames);
    WindowHealth window;
    window.first_frame = frames[begin]->index;
    window.last_frame = frames[end - 1]->index;
    std::vector<std::shared_ptr<const CalibrationFrame>> pruned;
    std::vector<const CalibrationFrame*> view;
    for (size_t k = begin; k < end; ++k) {
      pruned.push_back(
          WithSuppressedScoreMaps(*PruneToImage(*frames[k], calibration, options.point_margin)));
      view.push_back(pruned.back().get());
      window.points += static_cast<int>(pruned.back()->size());
    }
    if (window.points < options.min_points_per_window) {
      window.note = "too few LiDAR edge points in the image (" + std::to_string(window.points) +
                    " < " + std::to_string(options.min_points_per_window) + ")";
      result.windows.push_back(window);
      continue;
    }
    WindowScorer scorer(view, options.score);
    window.gray_rate = scorer.GrayRate(calibration);
    window.health = HealthScore(&scorer, calibration, options.rotation_step_deg,
                                options.translation_step_m, &window.best_neighbour_gain);
    gain_sum += window.best_neighbour_gain;
    window.used = true;
    sum += window.health;
    ++used;
    result.min_window_health = std::min(result.min_window_health, window.health);
    result.windows.push_back(window);
  }
  char text[256];
  if (used < options.min_windows) {
    std::snprintf(text, sizeof(text),
                  "no verdict: %d usable window(s) of %d frames, %d needed (too few LiDAR edges "
                  "in the image)",
                  used, options.window_frames, options.min_windows);
    result.reason = text;
    result.min_window_health = 0;
    return result;
  }
  result.decided = true;
  result.mean_health = sum / used;
  result.mean_neighbour_gain = gain_sum / used;
  const bool healthy = result.mean_health >= options.min_health;
  const bool no_better = result.mean_neighbour_gain <= options.max_neighbour_gain;
  result.holds = healthy && no_better;
  std::snprintf(text, sizeof(text),
                "mean health %.3f (threshold %.2f), best neighbour %+.1f%% (limit %+.1f%%) over %d "
                "windows: %s",
                result.mean_health, options.min_health, 100 * result.mean_neighbour_gain,
                100 * options.max_neighbour_gain, used,
                result.holds ? "the calibration holds"
                : !healthy   ? "the calibration is off (low health)"
                             : "the calibration is off (a neighbour scores clearly better)");
  result.reason = text;
  return result;
}

}  // namespace stcalib
