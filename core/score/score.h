#pragma once

#include <array>
#include <memory>
#include <vector>

#include "core/score/calibration_frame.h"
#include "core/score/frame_score_cache.h"
#include "core/types/calibration.h"

namespace stcalib {

// Score of a calibration (docs/method.md §6): over projected LiDAR edge points, the score map at
// the projected pixel (bilinear), horizontal points weighted w and vertical ones 1 − w. The gray
// rate is score / 255 / (weighted number of points): the mean map value, 0..1.
struct ScoreOptions {
  double horizontal_weight = 0.5;  ///< w of docs/method.md §6
  int max_points_per_frame = 600;  ///< evenly thinned for speed; 0 = all
};

struct ScoreValue {
  double score = 0;       ///< weighted sum of map values
  double gray_rate = 0;   ///< score / 255 / weight sum
  int projected = 0;      ///< points that landed in the image
  double weight_sum = 0;  ///< sum of the point weights (score = 255·gray_rate·weight_sum)
};

// Evaluates many candidate calibrations on a window of frames fast: the motion model's Tv(e0 + δ)
// is one rigid transform per frame, folded with the candidate's extrinsic and the camera into one
// 3×4 projection, so each candidate (any δ) costs one 3×3 product per point.
class WindowScorer {
 public:
  WindowScorer(std::vector<const CalibrationFrame*> frames, const ScoreOptions& options);

  // `level` indexes CalibrationFrame::score_maps (negative counts from the finest: −1).
  ScoreValue Evaluate(const CalibrationState& state, int level);
  // Gray rate on the frames' plain IDT (CalibrationFrame::gray_map; the finest score map when
  // absent).
  double GrayRate(const CalibrationState& state);
  int num_levels() const;
  size_t num_frames() const { return frames_.size(); }
  const CalibrationFrame& frame(size_t f) const { return *frames_[f]; }
  const ScoreOptions& options() const { return options_; }
  // Evaluate() of each of `states` (all at one δ), bit for bit: states with the same rotation
  // share its projection products, so a 728-neighbourhood (27 rotations) costs about half of 728
  // Evaluate() calls.
  std::vector<ScoreValue> EvaluateStates(const std::vector<CalibrationState>& states, int level);
  // EvaluateStates() on frame `f` alone.
  std::vector<ScoreValue> EvaluateStatesOnFrame(size_t f,
                                                const std::vector<CalibrationState>& states,
                                                int level);
  // Evaluate() on frame `f` alone. The window's score is the sum of these in frame order up to
  // rounding (Evaluate() accumulates point by point across frames).
  ScoreValue EvaluateFrame(size_t f, const CalibrationState& state, int level);

 private:
  // Evaluates frames [begin, end) on the map `map_of(frame, kind)`.
  template <typename MapOf>
  ScoreValue EvaluateOn(const CalibrationState& state, const MapOf& map_of, size_t begin,
                        size_t end);
  // Evaluate() over frames [begin, end).
  ScoreValue EvaluateLevel(const CalibrationState& state, int level, size_t begin, size_t end);
  // EvaluateStates() over frames [begin, end).
  std::vector<ScoreValue> EvaluateStatesOn(const std::vector<CalibrationState>& states, int level,
                                           size_t begin, size_t end);

  std::vector<const CalibrationFrame*> frames_;
  ScoreOptions options_;
  std::vector<std::vector<float>> weights_;
  std::vector<std::vector<uint8_t>> kinds_;
  std::vector<std::vector<Eigen::Vector3d>> points_;  // the thinned points per frame
  // Plain IDTs made by GrayRate for frames that keep none (PlainIdt), when they are kept.
  std::vector<std::array<cv::Mat, 2>> plain_idt_;
};

// The 728 neighbour directions of the 6-DoF grid (docs/method.md §6), each component in {−1, 0, 1}
// (rotation first, then translation), in a fixed order; with `translation` false the 26 that
// move the rotation only.
const std::vector<Eigen::Matrix<double, 6, 1>>& NeighbourDirections(bool translation);

// Applies a step to a calibration: rotation as roll/pitch/yaw about the LiDAR axes [rad]
// (R·Exp(Δ)), translation in the camera frame [m], time offset [s].
CalibrationState Step(const CalibrationState& state, const Eigen::Vector3d& rotation_rad,
                      const Eigen::Vector3d& translation_m, double time_offset_s);

// The frame with only the edge points that project inside the image shrunk by `margin` (a share
// of its size on each side) at `state`. Scores compare calibrations on the same points: a score
// over all points would reward calibrations that pull outside points into the image.
std::shared_ptr<const CalibrationFrame> PruneToImage(const CalibrationFrame& frame,
                                                     const CalibrationState& state, double margin);
// The frame without its folds (CalibrationFrame::folds): the same frame when it has none.
std::shared_ptr<const CalibrationFrame> WithoutFolds(std::shared_ptr<const CalibrationFrame> frame);
// The frame with the points of its local map's latest `sweeps` sweeps only
// (CalibrationFrame::sweep_ages): the same frame when it has no older one or `sweeps` <= 0.
std::shared_ptr<const CalibrationFrame> LatestSweepsOnly(
    std::shared_ptr<const CalibrationFrame> frame, int sweeps);

// What the health score's per-frame scores depend on besides the frame. With a
// HealthScoreCache, an online calibrator whose estimate did not move since the last frame scores
// only the newest frame of its sliding window.
struct HealthSetting {
  Eigen::Matrix4d T_camera_lidar;
  double time_offset_s, rotation_deg, translation_m, horizontal_weight;
  int max_points_per_frame;
  bool operator==(const HealthSetting& o) const;
};
using HealthScoreCache = FrameScoreCache<HealthSetting>;  // per frame: centre, 728 neighbours

// Health score (docs/method.md §7): the share of the 728 grid neighbours at ±`rotation_deg` /
// ±`translation_m` that score worse than `state` on the finest map. Window scores are the sums
// of the frames' scores in frame order, so a result from `cache` (optional) is identical to one
// without it.
// `best_gain` (optional) receives the largest relative score gain of a neighbour over `state`
// (score(neighbour) / score(state) − 1; ≤ 0 when `state` beats all of them).
constexpr double kHealthRotationDeg = 1.0;
constexpr double kHealthTranslationM = 0.05;
double HealthScore(WindowScorer* scorer, const CalibrationState& state,
                   double rotation_deg = kHealthRotationDeg,
                   double translation_m = kHealthTranslationM, double* best_gain = nullptr,
                   HealthScoreCache* cache = nullptr);

}  // namespace stcalib
