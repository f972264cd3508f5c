#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/score/score.h"
#include "core/types/calibration.h"
#include "core/types/status.h"

namespace stcalib {

// Adaptive step-size grid search (docs/method.md §6). From the current estimate all 3⁶ − 1 = 728
// neighbours (±step on each of roll, pitch, yaw, x, y, z) are scored; the step pair is the large
// one (α1 rotation, α2 translation) while the gray rate is below γ and the small one (α3, α4)
// above it. When a neighbour is better the search keeps moving in that direction while the score
// improves (steepest-direction following), then looks around again; a 1-D search over the time
// offset is interleaved. It searches the frames' finest score map (their last): the hypothesis
// lattice, not the search, covers a start several degrees off (docs/method.md §6).
struct AdaptiveGridSearchOptions {
  double alpha1_rotation_deg = 1.0;    ///< large step pair: rotation [deg]
  double alpha2_translation_m = 0.04;  ///< large step pair: translation [m]
  double alpha3_rotation_deg = 0.2;    ///< small step pair: rotation [deg]
  double alpha4_translation_m = 0.01;  ///< small step pair: translation [m]
  double gamma = 0.45;                 ///< gray-rate threshold between the pairs (finest map)
  int max_iterations = 25;             ///< neighbourhood evaluations per level
  int max_follow_steps = 12;           ///< moves along one improving direction
  bool search_translation = true;
  bool search_time_offset = true;
  double time_offset_step_s = 0.004;  ///< δ line-search step [s]
  double time_offset_bound_s = 0.15;  ///< |δ| never exceeds this [s]
  // Bounds around `anchor` (the mount / initial calibration): the search never leaves them.
  double max_rotation_offset_deg = 6.0;
  double max_translation_offset_m = 0.15;
  // Translation prior (docs/method.md §10: δ and the forward translation lie on a ridge): the
  // search maximises score − translation_prior_weight·255·W·(|t − t_anchor| / σ)², W the weight
  // sum, i.e. a deviation of σ costs `translation_prior_weight` of gray rate; δ likewise.
  double translation_prior_sigma_m = 0.05;
  double translation_prior_weight = 0.01;
  // The same for δ around the anchor's δ0 [s]: periodic structure gives δ far peaks (§10).
  double time_offset_prior_sigma_s = 0.03;

  Status Validate() const;
};

struct SearchResult {
  CalibrationState state;
  ScoreValue start, end;  ///< on the finest map
  int evaluations = 0;
  int moves = 0;
};

SearchResult AdaptiveGridSearch(WindowScorer* scorer, const CalibrationState& start,
                                const CalibrationState& anchor,
                                const AdaptiveGridSearchOptions& options);

// True when `state` is within the rotation/translation bounds around `anchor`.
bool WithinBounds(const CalibrationState& state, const CalibrationState& anchor,
                  const AdaptiveGridSearchOptions& options);

// Score over δ ∈ [−bound, bound] at fixed extrinsic, and whether a second peak (at least
// `min_separation_s` away) comes within `ratio` of the best above the floor (aliasing guard).
struct TimeOffsetProfile {
  std::vector<double> offsets_s, scores;
  double best_s = 0;
  double second_peak_s = 0;
  double second_peak_ratio = 0;  ///< (second − floor) / (best − floor)
  bool alias_suspect = false;
};
TimeOffsetProfile ProfileTimeOffset(WindowScorer* scorer, const CalibrationState& state,
                                    double bound_s, double step_s, double ratio = 0.9,
                                    double min_separation_s = 0.01);

// The same guard for a rotation axis (0 roll, 1 pitch, 2 yaw about the LiDAR axes): the score
// along the axis within ±half_range_deg of `state`. Repetitive structure (signs on poles, window
// rows) can give a second peak degrees away that scores about as well: then the axis is
// ambiguous and the estimate may sit on the wrong peak.
struct RotationAxisProfile {
  std::vector<double> offsets_deg, scores;
  double best_deg = 0;
  double second_peak_deg = 0;
  double second_peak_ratio = 0;  ///< (second − floor) / (best − floor)
  bool ambiguous = false;
};
RotationAxisProfile ProfileRotationAxis(WindowScorer* scorer, const CalibrationState& state,
                                        int axis, double half_range_deg = 4.0,
                                        double step_deg = 0.25, double ratio = 0.9,
                                        double min_separation_deg = 1.0, int level = -1);

}  // namespace stcalib
