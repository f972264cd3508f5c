#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <deque>
#include <string>
#include <vector>

#include "core/score/calibration_frame.h"
#include "core/types/calibration.h"
#include "core/types/status.h"

namespace stcalib {

// What the user knows of the start (`stcalib calibrate --init_uncertainty`): each axis of the
// initial calibration may be off by up to these figures. The acquisition's lattice spans them
// (docs/method.md §6). The defaults are a start measured with some care; wider ones
// (5°, 20 cm, 100 ms) acquire from farther but claim less on the development suite.
// Measured: docs/results.md#hypothesis-lattice
struct StartUncertainty {
  double rotation_deg = 3.0;    ///< per axis (roll, pitch, yaw) [deg]
  double translation_m = 0.05;  ///< per axis (x, y, z) [m]
  double time_offset_s = 0.03;  ///< δ0's error [s]
};
// "ROT_DEG,TRANS_M,TIME_S" (three positive numbers), else an error naming the text and what is
// wrong with it.
Status ParseStartUncertainty(const std::string& text, StartUncertainty* uncertainty);
// The figures as ParseStartUncertainty reads them ("5,0.2,0.1").
std::string StartUncertaintyText(const StartUncertainty& uncertainty);

// The lattice's steps per camera axis (x right, y down, z forward): about twice the half-width
// of the coarse score's peak on that axis, so that the truth lies within half a step of a lattice
// point and still scores well above the side peaks there. A rotation about camera y moves the
// many vertical edges across the image (a narrow peak), one about camera x moves them along
// themselves (wider), one about the optical axis turns the image (widest); the translation across
// the view moves near points sideways, along the view and vertically barely.
// Measured: docs/tuning.md#lattice-steps
struct LatticeSteps {
  Eigen::Vector3d rotation_deg{1.0, 0.75, 2.0};  ///< about camera x, y, z [deg]
  Eigen::Vector3d translation_m{0.2, 0.4, 0.4};  ///< along camera x, y, z [m]
  double time_offset_s = 0.04;                   ///< [s]
};

// A fixed set of calibration hypotheses around a centre: every combination of rotation offsets
// (about the camera axes, applied on the camera side: R = Exp(Δ)·R_centre), δ offsets and
// translation offsets (camera frame), each axis at k·step for |k| ≤ K, the least K with
// K·step + step/2 ≥ span: every start within the span lies within half a step of a lattice point
// (one value, the centre's, where the span is at most half a step). Hypothesis index
// h = (rotation · num_time_offsets + time offset) · num_translations + translation.
class HypothesisLattice {
 public:
  // The most hypotheses a lattice may hold: each window frame keeps a float per hypothesis.
  static constexpr size_t kMaxHypotheses = 4'000'000;
  // Error (naming the figures) when the lattice would hold more than `max_hypotheses`.
  static Status Create(const CalibrationState& centre, const StartUncertainty& span,
                       const LatticeSteps& steps, HypothesisLattice* lattice,
                       size_t max_hypotheses = kMaxHypotheses);
  // The number of hypotheses Create would make (no allocation).
  static size_t CountFor(const StartUncertainty& span, const LatticeSteps& steps);
  // Error (naming the count and the limit) when that number exceeds `max_hypotheses`.
  static Status CheckFits(const StartUncertainty& span, const LatticeSteps& steps,
                          size_t max_hypotheses = kMaxHypotheses);

  size_t size() const { return rotations_.size() * time_offsets_s_.size() * translations_.size(); }
  size_t num_rotations() const { return rotations_.size(); }
  size_t num_time_offsets() const { return time_offsets_s_.size(); }
  size_t num_translations() const { return translations_.size(); }
  const CalibrationState& centre() const { return centre_; }
  const LatticeSteps& steps() const { return steps_; }
  size_t RotationOf(size_t h) const { return h / (time_offsets_s_.size() * translations_.size()); }
  // The rotation's cell: its offsets in steps about camera x, y and z.
  const Eigen::Vector3i& RotationCell(size_t r) const { return rotation_cells_[r]; }
  // Offsets of hypothesis h from the centre: rotation [rad] (about the camera axes), translation
  // [m] (camera frame), δ [s].
  Eigen::Vector3d RotationOffsetRad(size_t h) const { return rotations_[RotationOf(h)]; }
  Eigen::Vector3d TranslationOffsetM(size_t h) const {
    return translations_[h % translations_.size()];
  }
  double TimeOffsetOffsetS(size_t h) const {
    return time_offsets_s_[(h / translations_.size()) % time_offsets_s_.size()];
  }
  CalibrationState State(size_t h) const;

 private:
  CalibrationState centre_;
  LatticeSteps steps_;
  std::vector<Eigen::Vector3i> rotation_cells_;
  std::vector<Eigen::Vector3d> rotations_;     // [rad], one per rotation cell
  std::vector<double> time_offsets_s_;         // offsets from the centre's δ [s]
  std::vector<Eigen::Vector3d> translations_;  // offsets [m]
};

// The coarse score of `frame` at every hypothesis of `lattice`: over up to `max_points` of its
// edge points (evenly thinned), the coarse map (CalibrationFrame::coarse_map, nearest cell) at
// each projected point, vertical points weighted 1 − w and horizontal ones w; points that leave
// the image or fall behind the camera add nothing. `scores` is resized to lattice.size(). The
// motion model carries the points over e0 + δ exactly at each of the lattice's δ; the rest is
// one 3×3 product per rotation and point, an addition per translation. Allocates only `scores`
// and per-frame scratch (not per hypothesis).
void ScoreFrameOnLattice(const CalibrationFrame& frame, const HypothesisLattice& lattice,
                         double horizontal_weight, int max_points, std::vector<float>* scores);

// The window's score of every hypothesis: the sum of its frames' score vectors. A frame's vector
// is added when it arrives and subtracted when it leaves; nothing is scored again.
class LatticeWindow {
 public:
  explicit LatticeWindow(int max_frames) : max_frames_(max_frames) {}
  // Adds a frame's score vector; the oldest frame leaves once the window holds max_frames.
  void Add(int frame_index, std::vector<float> scores);
  void Clear();
  // The score vector of the frame that left the window last (its memory, to be filled again),
  // or an empty one.
  std::vector<float> TakeSpare() { return std::move(spare_); }
  int frames() const { return static_cast<int>(frames_.size()); }
  const std::vector<double>& sums() const { return sums_; }
  // The window's frame indices, oldest first.
  std::vector<int> FrameIndices() const;

 private:
  int max_frames_;
  std::deque<std::pair<int, std::vector<float>>> frames_;
  std::vector<double> sums_;
  std::vector<float> spare_;
};

// The best `count` hypotheses by `sums` with pairwise distinct rotations (non-maximum
// suppression): each is the best δ and translation of its rotation, and no two rotations lie
// within `min_separation_cells` − 1 steps of each other on every axis. Best first.
std::vector<size_t> TopHypotheses(const HypothesisLattice& lattice, const std::vector<double>& sums,
                                  int count, int min_separation_cells = 2);

}  // namespace stcalib
