#pragma once

#include <string>
#include <vector>

#include "core/score/score.h"
#include "core/search/adaptive_grid_search.h"
#include "core/search/hypothesis_lattice.h"
#include "core/types/calibration.h"

namespace stcalib {

// A hypothesis the acquisition carries from frame to frame (docs/method.md §7): a peak of the
// lattice's window score, refined on the fine maps.
struct Hypothesis {
  bool incumbent = false;    ///< refined from the estimate itself, not from a lattice point
  size_t lattice_index = 0;  ///< its lattice point (the best δ and translation of its rotation)
  double lattice_score = 0;  ///< the window's coarse score there
  CalibrationState state;    ///< refined on the fine maps (rotation and δ)
  std::vector<double> frame_scores;  ///< fine score per frame of the refinement's window
};

// A runner-up measured against the best hypothesis over the same frames.
struct RivalMargin {
  double rotation_deg = 0;   ///< its rotation's distance from the best's [deg]
  double time_offset_s = 0;  ///< its δ − the best's [s]
  // (best − rival) ÷ best, of the fine scores summed over the frames.
  double score_share = 0;
  // The mean per-frame score gain of the best over the rival (each frame's gain relative to the
  // mean |score| of the hypotheses on it) ÷ its standard error, with the frames that share sweeps
  // counted once: how many standard errors the best is ahead.
  double t_statistic = 0;
  bool merged = false;  ///< refined onto the best's peak: no rival
};

// Whether one hypothesis dominates the others over the frames seen: the rule that ends the
// acquisition (Judge's `one_hypothesis_dominates`, docs/method.md §7).
struct Dominance {
  int frames = 0;                   ///< frames the hypotheses were compared over
  int best = -1;                    ///< index of the best hypothesis (highest fine score), -1: none
  std::vector<RivalMargin> rivals;  ///< one per hypothesis (the best's own entry is empty)
  bool dominant = false;
  std::string detail;  ///< what was measured; the rivals still standing when not dominant
};
struct DominanceOptions {
  int min_frames = 6;  ///< frames seen before any hypothesis may dominate
  // A rival refined to within this of the best is on the same peak (the fine score's peak is
  // about ±1° wide, docs/method.md §10) [deg].
  double merge_deg = 1.5;
  // Every rival must trail the best by this many standard errors (one-sided, about 2.3 %
  // false-alarm rate for independent frames).
  double min_t = 2.0;
};
// `frame_scores[k][f]`: hypothesis k's fine score on frame f (every hypothesis over the same
// frames); `states[k]` its refined state; `shared_sweep_frames`: frames that share each sweep
// (their differences are not independent: the standard error counts n ÷ this frames). Pure.
Dominance JudgeDominance(const std::vector<std::vector<double>>& frame_scores,
                         const std::vector<CalibrationState>& states, int shared_sweep_frames,
                         const DominanceOptions& options = DominanceOptions());

// The acquisition's state: the lattice around its centre, the window's running scores, and the
// hypotheses carried forward.
class Acquisition {
 public:
  // Hypotheses kept after non-maximum suppression.
  static constexpr int kHypotheses = 6;
  // Fine-map points per frame the lattice reads (evenly thinned).
  static constexpr int kLatticePoints = 256;

  explicit Acquisition(int window_frames) : max_frames_(window_frames), window_(window_frames) {}
  // A new lattice around `centre` over `span`, which scores `frames` (oldest first) at once.
  Status Centre(const CalibrationState& centre, const std::vector<const CalibrationFrame*>& frames,
                double horizontal_weight, const StartUncertainty& span);
  // Scores `frame` once over the lattice and adds it to the window.
  void AddFrame(const CalibrationFrame& frame, double horizontal_weight);
  // The best kHypotheses peaks of the window's score and the `incumbent` (the estimate), each
  // refined in rotation and δ on `search`'s fine maps (a lattice peak from the state it had on
  // the previous frame when it is the same lattice rotation), and scored frame by frame on
  // `judge`'s frames; then the dominance among them. Best first.
  const std::vector<Hypothesis>& Update(WindowScorer* search, WindowScorer* judge,
                                        const CalibrationState& incumbent,
                                        const CalibrationState& anchor,
                                        const AdaptiveGridSearchOptions& options,
                                        int shared_sweep_frames, int* evaluations);
  // How many standard errors the best hypothesis leads the incumbent by (0 when the incumbent is
  // the best or on its peak).
  double LeadOverIncumbent() const;
  const std::vector<Hypothesis>& hypotheses() const { return hypotheses_; }
  const Dominance& dominance() const { return dominance_; }
  const HypothesisLattice& lattice() const { return lattice_; }
  bool centred() const { return lattice_.size() > 0; }
  int frames() const { return window_.frames(); }

 private:
  int max_frames_;  // the lattice's window, the refinement's frames
  HypothesisLattice lattice_;
  LatticeWindow window_;
  std::vector<float> scratch_;
  std::vector<Hypothesis> hypotheses_;
  Dominance dominance_;
};

// One line per runner-up for a message: "roll/pitch/yaw offset, δ, score share, t".
std::string DescribeRivals(const Dominance& dominance);

}  // namespace stcalib
