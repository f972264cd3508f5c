#pragma once

#include <deque>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "core/online/acquisition.h"
#include "core/refine/refine.h"
#include "core/score/calibration_frame.h"
#include "core/score/score.h"
#include "core/search/adaptive_grid_search.h"
#include "core/search/hypothesis_lattice.h"
#include "core/types/calibration.h"
#include "core/types/status.h"

namespace stcalib {

// The refinement's robust loss once acquired (tracking updates and the polish); refine.loss while
// acquiring. About a quarter of the LiDAR edge points have no image edge near them even at the
// truth; under a Cauchy loss each still pulls towards whatever edge lies within the distance map's
// basin. A redescending loss (Tukey) gives a point farther than its scale from every edge no pull
// at all; it needs a start within a few pixels, which the acquisition gives.
// Measured: docs/tuning.md#acquired-loss
inline constexpr RefineOptions::Loss kAcquiredLoss = RefineOptions::Loss::kTukey;
inline constexpr double kAcquiredLossScalePx = 5.0;
// w (docs/method.md §6) once the folds are dropped (Folds::kDropWhenTracking). The folds are the
// horizontal edges that bias (a top's corner seen from above); without them the rest carry roll.
// Measured: docs/tuning.md#tracking-horizontal-weight
inline constexpr double kFoldFreeHorizontalWeight = 0.35;
// The polish moves δ with the forward translation only when its refinement puts the forward
// translation's std under this [m] (and δ's under refine.observable_time_s): the covariance is
// optimistic, and near the prior's σ the std is the prior's. Measured:
// docs/tuning.md#polish-forward-std
inline constexpr double kPolishForwardStdM = 0.035;

struct OnlineCalibratorOptions {
  // The defaults are set for real streets (KITTI drive 0013, tree-lined) and serve simulated
  // drives as well; `stcalib calibrate`'s flags take their defaults from here.
  int window_frames = 3;  ///< sliding window of frames searched together
  // The refinement, the candidates' judge and the acquisition's dominance read this many latest
  // frames. Measured: docs/tuning.md#refine-frames
  int refine_frames = 20;  ///< frames of the refinement and the hypotheses' judge [frames]
  // score.horizontal_weight, refine.horizontal_weight and both time_offset_bound_s are set from
  // the fields below (one setting, one home) by WithSharedSettings, which the calibrator applies.
  ScoreOptions score;                ///< the score (its horizontal_weight shared)
  AdaptiveGridSearchOptions search;  ///< the local search (its δ bound shared)
  RefineOptions refine;              ///< the refinement (its weight and δ bound shared)
  // Horizontal LiDAR edges are the less faithful ones (foliage tops scatter), so they weigh less
  // than vertical ones. Measured: docs/tuning.md#horizontal-weight
  double horizontal_weight = 0.2;     ///< w of docs/method.md §6, while the folds are read
  double time_offset_bound_s = 0.15;  ///< |δ| bound for search and refinement [s]
  // How far the start may be off on each axis: the acquisition's lattice spans it, and the search
  // bounds and priors hold it (WithStartUncertainty). docs/method.md §6
  StartUncertainty start_uncertainty;  ///< [deg, m, s] per axis
  // Health (docs/method.md §7) under this at an acquired estimate means lost: it re-acquires.
  double lost_health = 0.9;  ///< health under which an acquired estimate is lost [0..1]
  // Points are kept when they project inside the image shrunk by this share of its size on each
  // side (negative: grown), at the estimate when their frame arrives. A band-pass score is near
  // zero on average, so points just outside the image cost nothing: keep them.
  double point_margin = -0.1;  ///< share of the image size on each side [ratio]
  // While tracking, an accepted update moves this share of the way to the new estimate: a
  // first-order filter over windows that scatter by a few tenths of a degree.
  double tracking_gain = 0.3;  ///< share of the way a tracking update moves [0..1]
  // ... but the rotation never lags an accepted update's estimate by more than this
  // (TrackingRotationShare; 0 = tracking_gain alone) [deg]. Measured:
  // docs/tuning.md#tracking-max-lag
  double tracking_max_lag_deg = 0.3;  ///< [deg]
  // The refined rotation (with the chosen candidate's translation and δ) is taken in place of the
  // best-scoring candidate when it scores within this share of the best: the score finds the
  // peak, the refinement where on it. 0 = the best score wins.
  // Measured: docs/tuning.md#refined-score-tolerance
  double refined_score_tolerance = 0.1;  ///< share of the best score [0..1)
  // While tracking (healthy), the search and refinement run on every n-th frame only; the frames
  // between join the window and have their health measured. 1 = update on every frame.
  int tracking_update_every = 3;  ///< frames per update while tracking [frames]
  // The LiDAR edges' folds (LidarEdgeOptions::fold_height_tolerance_m): kept, dropped from every
  // window, or dropped once acquired (the default: the acquisition reads them; tracking,
  // refinement, polish and the verdict's profiles do not, at kFoldFreeHorizontalWeight). The
  // health reads every point whatever the choice (HealthWindow). The first frame without them
  // updates at once and by a full step. Measured: docs/tuning.md#folds
  enum class Folds { kKeep, kDrop, kDropWhenTracking };
  Folds folds = Folds::kDropWhenTracking;  ///< which windows read the folds

  Status Validate() const;
};

// The share of an accepted update's rotation (`rotation_rad`, its angle from the current
// estimate) that a tracking update takes: `gain`, or more where that would leave the estimate
// farther than `max_lag_rad` from the update's (0 = no limit); then exactly that far.
double TrackingRotationShare(double gain, double rotation_rad, double max_lag_rad);

// OnlineCalibratorOptions::Folds by name: keep | drop | drop_when_tracking.
std::string FoldsName(OnlineCalibratorOptions::Folds folds);
// False, `folds` untouched, when `name` is none of them.
bool ParseFolds(const std::string& name, OnlineCalibratorOptions::Folds* folds);
// The names, for a message: "keep, drop or drop_when_tracking".
std::string FoldsChoices();

// δ against the translation along the direction of travel, from a solve with both free (the
// polish's first). While tracking, the forward translation is held by its prior, so a tracking
// refinement's δ std is conditional on that prior: on a straight road at constant speed δ is then
// only as right as the start's forward translation (δ error = forward error ÷ speed), however
// small its std (measured: docs/tuning.md#time-forward-pair).
struct TimeForwardPair {
  bool measured = false;         ///< the solve estimated δ and gave a covariance
  bool separated = false;        ///< both observable, and the pair moved with the window's data
  double time_offset_std_s = 0;  ///< δ's std with the forward translation free [s]
  double forward_std_m = 0;      ///< the forward translation's std [m]
  double correlation = 0;        ///< of δ with the forward translation
  // The direction of travel that translation is along (unit, camera frame).
  Eigen::Vector3d forward_camera = Eigen::Vector3d::UnitZ();
};

// The calibrator's phase (docs/method.md §7). Filling: the search window is not full yet.
// Acquiring: every frame is scored once over the hypothesis lattice around the start; the best
// few hypotheses are refined and the estimate follows the best, until one dominates the others
// over the frames seen (JudgeDominance). Tracking: acquired and healthy; updates every
// tracking_update_every frames, each moving part of the way. Lost: acquired, but the health at
// the estimate fell under lost_health; the lattice, centred on the last healthy estimate, gives
// the hypotheses again until the health returns.
enum class Phase { kFilling, kAcquiring, kTracking, kLost };
std::string PhaseName(Phase phase);  ///< filling | acquiring | tracking | lost

// What a phase transition reads.
struct PhaseInputs {
  int window_size = 0;     ///< frames in the search window now
  int window_frames = 0;   ///< the search window's length
  bool dominant = false;   ///< one hypothesis dominates and the estimate is on it
  double health = 0;       ///< at the estimate on the latest window
  double lost_health = 0;  ///< under it an acquired estimate is lost
};
// The phase after `current` given `in`. Filling ends when the window is full (into acquiring);
// acquiring ends only when one hypothesis dominates; tracking and lost follow the health. No
// phase goes back to filling or acquiring.
Phase NextPhase(Phase current, const PhaseInputs& in);

struct FrameReport {
  int frame = 0;
  Phase phase = Phase::kFilling;  ///< the calibrator's phase after this frame
  CalibrationState before, after;
  bool accepted = false;
  bool skipped = false;  ///< the frame was refused (bad data): nothing changed, see `reason`
  std::string reason;    ///< why the update was (not) taken
  ScoreValue score_before, score_after;              ///< on the finest score map
  double gray_rate_before = 0, gray_rate_after = 0;  ///< on the plain IDT
  double health_before = 0;                          ///< docs/method.md §7, at `before`
  double health = 0;                                 ///< docs/method.md §7, at `after`
  // The search started away from the estimate, from the best hypothesis (acquiring or lost) or,
  // lost, from the last healthy estimate: the update jumps to its choice.
  bool from_hypotheses = false;
  bool acquiring = false;  ///< the calibrator was still acquiring when the frame arrived
  SearchResult search;
  RefineResult refine;
  TimeForwardPair time_forward;  ///< set by the polish only
  double search_ms = 0, refine_ms = 0;
  int points = 0;
  // Whether this frame ran the search and refinement (refused, window-filling frames and tracking
  // frames between updates do not).
  bool ran_update() const { return search.evaluations > 0; }
};

// `candidate` on its observable axes, `old` on the others (rotation about the LiDAR axes,
// translation, time offset, in kAxisNames order).
CalibrationState KeepObservableAxes(const CalibrationState& old, const CalibrationState& candidate,
                                    const std::array<bool, kNumAxes>& observable);

// Online calibration (docs/method.md §7): frames in time order; per frame (once acquired, per
// tracking_update_every frames while healthy) a search step and a refine over the window; an update
// is taken only when the window score does not get worse and the axes it moves are observable (an
// unobservable axis keeps its value); |δ| stays within its bound. It only sequences the stages; the
// maths lives in score/, search/ and refine/. `options` with its shared settings
// (horizontal_weight, time_offset_bound_s) copied into score, search and refine: the options an
// OnlineCalibrator runs with. Use it to run a stage alone with the calibrator's settings.
OnlineCalibratorOptions WithSharedSettings(const OnlineCalibratorOptions& options);

// `options` with its search bounds and priors holding options.start_uncertainty (never narrowed):
// the rotation bound covers the lattice plus a basin, the translation and δ priors (whose σ the
// verdict's translation rule reads) are at least as wide as the start's error, and the δ bound
// reaches δ0 ± that error. `initial_time_offset_s`: δ0.
OnlineCalibratorOptions WithStartUncertainty(const OnlineCalibratorOptions& options,
                                             double initial_time_offset_s);

class OnlineCalibrator {
 public:
  OnlineCalibrator(const OnlineCalibratorOptions& options, const CalibrationState& initial);

  // A frame that cannot be used (stamp not after the last frame's, no image edges, non-finite
  // motion) is refused: the report says why and the estimate and window stay as they were.
  // `update_now`: search and refine on this frame whatever tracking_update_every says (a run's
  // last frame, whose refinement the final verdict reads).
  FrameReport AddFrame(std::shared_ptr<const CalibrationFrame> frame, bool update_now = false);
  // A frame the caller could not load: recorded as skipped with `why`.
  FrameReport SkipFrame(int frame, const std::string& why) const;
  const CalibrationState& state() const { return state_; }
  // The options in effect (the shared settings copied into score, search and refine).
  const OnlineCalibratorOptions& options() const { return options_; }
  // Still acquiring: no hypothesis has dominated the others yet.
  bool acquiring() const { return phase_ == Phase::kFilling || phase_ == Phase::kAcquiring; }
  Phase phase() const { return phase_; }
  // The acquisition's lattice, hypotheses (best first) and their dominance, as of the last
  // update that read them (acquiring or lost).
  const Acquisition& acquisition() const { return acquisition_; }
  // The final step of a run: refines the rotation, δ and the translation along the direction of
  // travel over the latest refine_frames frames from the estimate (the lateral and vertical
  // translation held). While tracking, the estimate moves only tracking_gain of the way per update
  // and each move is judged on the score map, whose peak can sit a few tenths of a degree from the
  // refinement's optimum: the search is for finding the peak, the refinement for where on it.
  // While tracking, the forward translation is held at the start's and δ absorbs its error (δ
  // error = forward error ÷ speed); over the whole window, speed changes and turns can separate
  // the two. The forward translation and δ move together when both are observable (forward std
  // under kPolishForwardStdM, δ std under refine.observable_time_s); otherwise both stay and the
  // rotation is refined again with them held. The lateral and vertical translation stay because
  // edges pin them down only to a few cm. Nothing changes while acquiring, when the last frame's
  // health is below lost_health, or when the refinement fails or leaves the bounds; the report
  // says what happened. Measured: docs/tuning.md#polish
  FrameReport Polish();
  // Replaces the estimate (the paper's disturbance protocol); the bounds stay where they were.
  // The next frame updates whatever tracking_update_every says.
  void SetState(const CalibrationState& state) {
    state_ = state;
    frames_since_update_ = options_.tracking_update_every;
  }
  // The latest window_frames frames (what a search on the latest frame reads).
  std::vector<const CalibrationFrame*> SearchWindow() const;
  // The same frames with every point, folds included: what the health reads (a frame's, the lost
  // test's and so the verdict's) whatever OnlineCalibratorOptions::folds says. Folds bias where
  // the optimum sits by a few cm and tenths of a degree, but they sharpen it: without them, the
  // health of estimates close to the calibration can fall under the verdict's threshold
  // (ConvergenceOptions::min_final_health). Measured: docs/tuning.md#health-window
  std::vector<const CalibrationFrame*> HealthWindow() const;
  // Every frame the calibrator keeps (the latest max(window_frames, refine_frames), what a
  // refinement on the latest frame reads among them), oldest first, as it reads them now
  // (OnlineCalibratorOptions::folds).
  std::vector<std::shared_ptr<const CalibrationFrame>> RecentFrames() const;
  // The score's and the refinement's options as the calibrator reads them now: with the folds
  // dropped, at kFoldFreeHorizontalWeight.
  const ScoreOptions& ScoreOptionsInUse() const {
    return (folds_dropped_ ? fold_free_options_ : options_).score;
  }
  // Once acquired, at kAcquiredLoss.
  RefineOptions RefineOptionsInUse() const {
    RefineOptions refine = (folds_dropped_ ? fold_free_options_ : options_).refine;
    if (!acquiring()) {
      refine.loss = kAcquiredLoss;
      refine.loss_scale_px = kAcquiredLossScalePx;
    }
    return refine;
  }

 private:
  // An estimate offered to the judge, and the reason given when it is taken.
  struct Candidate {
    CalibrationState state;
    std::string name;
    bool refined = false;  ///< the refinement's estimate (its held axes kept)
  };

  // The steps of AddFrame.
  std::string RefusalReason(const CalibrationFrame& frame) const;  ///< empty when usable
  // Drops the folds on the first frame after the acquisition (Folds::kDropWhenTracking); true
  // while the first update without them (a full step) is still to run.
  bool DropFoldsOnceAcquired();
  // The frame pruned to the image at the estimate, with and without its folds, joins the window.
  void AdmitToWindow(const CalibrationFrame& frame);
  // Why this frame runs no update (window filling; tracking between updates, unless
  // `update_now`), or empty when it does; counts the frames between tracking updates.
  std::string WhyNoUpdate(int window_size, bool update_now, double health_before);
  // Search, refinement and choice on `scorer`'s window (the search window); moves the estimate
  // to report->after (by a full step when `full_step`). True when it compared the lattice's
  // hypotheses (acquiring or lost).
  bool Update(WindowScorer* scorer, bool full_step, FrameReport* report);
  std::vector<const CalibrationFrame*> RefineWindow() const;  ///< latest refine_frames
  // While acquiring or lost: the lattice's hypotheses refined and judged; the search starts from
  // the best. Otherwise the search starts from the estimate. Fills report->search and search_ms.
  void Search(WindowScorer* scorer, WindowScorer* long_scorer,
              const AdaptiveGridSearchOptions& search_options, bool read_hypotheses,
              FrameReport* report);
  // The refined estimate and the search result, the axes the refinement found unobservable held.
  std::vector<Candidate> Candidates(FrameReport* report) const;
  // The best candidate within the bounds that scores at least as well as the estimate on the
  // refinement's frames, moved by tracking_gain while tracking (a lost update's translation and δ
  // too; the whole way when `full_step` and not lost): fills report->after.
  void Choose(const std::vector<Candidate>& candidates, WindowScorer* long_scorer,
              const AdaptiveGridSearchOptions& search_options, bool full_step,
              FrameReport* report) const;

  // Score, gray rate and health at the estimate (health_before reused when it did not move).
  // `scorer` when `window` (the search window as read now) is HealthWindow() (Folds::kKeep, or
  // folds not dropped yet), else a scorer of HealthWindow() built in `own`.
  WindowScorer* HealthScorer(const std::vector<const CalibrationFrame*>& window,
                             WindowScorer* scorer, std::optional<WindowScorer>* own) const;
  // `health_scorer` reads HealthWindow().
  void MeasureEstimate(WindowScorer* scorer, WindowScorer* health_scorer, bool moved,
                       FrameReport* report);
  // A frame without an update (window filling, tracking between updates): the estimate and its
  // measures stay, `reason` says why.
  FrameReport KeepEstimate(FrameReport report, const std::string& reason);
  // The estimate becomes the last healthy one when `health` reaches lost_health on a full window.
  void RememberIfHealthy(double health, size_t window_size);

  // A lost estimate's lattice span: the start's, at most kLostSpan (online_calibrator.cc).
  StartUncertainty LostSpan() const;
  // A new lattice around `centre` over `span`, scoring the refinement's frames as read now.
  void RecentreLattice(const CalibrationState& centre, const StartUncertainty& span);
  // phase_ after this frame's window size, health and whether a hypothesis dominates; on
  // becoming lost, the lattice is centred on the last healthy estimate.
  void UpdatePhase(int window_size, double health, bool dominant = false);

  OnlineCalibratorOptions options_;
  CalibrationState state_;
  CalibrationState anchor_;  ///< the initial calibration: the search's bounds are around it
  Phase phase_ = Phase::kFilling;
  bool folds_dropped_ = false;  ///< OnlineCalibratorOptions::Folds::kDropWhenTracking in effect
  // options_ with horizontal_weight at kFoldFreeHorizontalWeight, shared into score and refine
  // by WithSharedSettings: what the calibrator reads once the folds are dropped.
  OnlineCalibratorOptions fold_free_options_;
  bool refit_pending_ = false;  ///< the first update without the folds has not run yet
  // The latest estimate whose health reached lost_health after a full window: a lost estimate's
  // lattice is centred there (a disturbance or a wrong jump).
  bool has_last_healthy_ = false;
  double last_health_ = 0;  ///< health at the estimate on the latest window
  // Tracking frames since the last search and refinement (starts due: the first updates).
  int frames_since_update_ = 0;
  CalibrationState last_healthy_;
  // A frame of the window: all its points (pruned to the image) and the same without its folds
  // (the same frame with Folds::kKeep).
  struct WindowFrame {
    std::shared_ptr<const CalibrationFrame> all, without_folds;
  };
  // The version of `frame` the calibrator reads now (OnlineCalibratorOptions::folds).
  const std::shared_ptr<const CalibrationFrame>& InUse(const WindowFrame& frame) const;
  // The latest `count` frames as read now, or with every point (folds included).
  std::vector<const CalibrationFrame*> LatestFrames(int count, bool with_folds = false) const;
  std::deque<WindowFrame> window_;  // the last refine_frames frames
  Acquisition acquisition_;
  HealthScoreCache health_cache_;  // the estimate's health, frame by frame
  double last_camera_time_s_ = -std::numeric_limits<double>::infinity();
};

}  // namespace stcalib
