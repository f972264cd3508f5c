#pragma once

#include <deque>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "core/refine/refine.h"
#include "core/score/calibration_frame.h"
#include "core/score/score.h"
#include "core/search/adaptive_grid_search.h"
#include "core/types/calibration.h"
#include "core/types/status.h"

namespace stcalib {

struct OnlineCalibratorOptions {
  // The defaults are set for real streets (KITTI drive 0013, tree-lined) and serve simulated
  // drives as well; `stcalib calibrate`'s flags take their defaults from here.
  int window_frames = 3;  ///< sliding window of frames searched together
  // Many frames: a few can prefer a side peak degrees off. An acquisition ends only when the grid
  // agrees with the estimate on a full refinement window: drives shorter than about
  // refine_frames + 5 frames want fewer. Measured: docs/tuning.md#refine-frames
  int refine_frames = 20;  ///< the refinement uses this many latest frames
  // The refinement reads the points of each frame's latest refine_map_sweeps sweeps only (its
  // own first; 0 = the whole local map, FrameSourceOptions::local_map). The search and the score
  // read the whole map.
  int refine_map_sweeps = 0;
  // score.horizontal_weight, refine.horizontal_weight and both time_offset_bound_s are set from
  // the fields below (one setting, one home) by WithSharedSettings, which the calibrator applies.
  ScoreOptions score;
  AdaptiveGridSearchOptions search;
  RefineOptions refine;
  // Horizontal LiDAR edges are the less faithful ones (foliage tops scatter; the tops of cars
  // seen from above show a roof sliver in the image), so they weigh less than vertical ones.
  // Measured: docs/tuning.md#horizontal-weight
  double horizontal_weight = 0.2;  ///< w of docs/method.md §6, for the score and the refinement
  // w once the folds are dropped (Folds::kDropWhenTracking, from the first frame after the
  // acquisition): in every window, refinement and health from then on, and in the polish. The
  // folds are the horizontal edges that bias (a top's corner seen from above); without them the
  // rest carry roll, which vertical edges (trunks, poles) constrain only through their height.
  // Measured: docs/tuning.md#tracking-horizontal-weight
  double tracking_horizontal_weight = 0.35;
  double time_offset_bound_s = 0.15;  ///< |δ| bound for search and refinement [s]
  // Health (docs/method.md §7) below this at the current estimate, or a window not yet full, means
  // the estimate may be far off: the search runs coarse-to-fine from the widest map instead of
  // on the finest one only.
  double lost_health = 0.9;
  // The polish moves δ with the forward translation only when its refinement puts the forward
  // translation's std under this [m] (and δ's under refine.observable_time_s). The covariance
  // treats the edge residuals as independent, which neighbouring points of one edge are not, so
  // the std is optimistic; near the translation prior's σ it is the prior's, with little from the
  // data. Measured: docs/tuning.md#polish-forward-std
  double polish_forward_std_m = 0.035;
  // The refinement's robust loss once acquired (tracking, refit and polish); refine.loss and
  // refine.loss_scale_px while acquiring. About a quarter of the LiDAR edge points have no image
  // edge near them even at the truth (an outline between two surfaces of one grey, a trunk
  // against a dark wall); under refine's Cauchy loss each still pulls towards whatever edge lies
  // within the distance map's basin, and as these pulls do not cancel they turn the estimate. A
  // redescending loss (Tukey) gives a point farther than its scale from every edge no pull at
  // all. It needs a start within a few pixels, which the acquisition gives; while acquiring it
  // slows the pull from ±2°. Measured: docs/tuning.md#acquired-loss
  RefineOptions::Loss acquired_loss = RefineOptions::Loss::kTukey;
  double acquired_loss_scale_px = 5.0;      ///< [px]
  bool acquired_loss_when_tracking = true;  ///< also in tracking updates (else polish only)
  bool coarse_until_window_full = true;
  // No update before the search window holds window_frames frames: one frame's score can have
  // its best optimum degrees away. Measured: docs/tuning.md#wait-for-full-window
  bool wait_for_full_window = true;
  // Points are kept when they project inside the image shrunk by this share of its size on
  // each side (negative: grown), at the estimate when their frame arrives. A band-pass score is
  // near zero on average, so points just outside the image cost nothing: keep them (pruning at a
  // wrong estimate would favour it).
  double point_margin = -0.1;
  // When lost, first an exhaustive rotation grid of ±lost_grid_deg at lost_grid_step_deg around
  // the estimate on the finest map of the refinement's frames (RotationGridSearch); the search
  // then starts from its best point on the finest map. 0 = no grid. The band-pass peak is narrow
  // (about ±1°) but global: a ±3° grid finds it.
  double lost_grid_deg = 3.0;
  double lost_grid_step_deg = 0.5;
  // A start farther off than ±lost_grid_deg (ForStartUncertainty sets it): the acquisition's first
  // grids span ±wide_grid_deg around the start [deg]; once one agrees with the estimate on
  // wide_grid_agreement_frames frames, every later grid (acquiring or lost) spans ±lost_grid_deg
  // around that grid's best rotation. 0 = no wide stage (the grids stay around the start).
  double wide_grid_deg = 0;
  int wide_grid_agreement_frames = 5;
  // The wide grids also run at δ0 ± this and ± half of it [s] (0 = at the estimate's δ only).
  double wide_time_offset_s = 0;
  // Acquisition: from the start, the grid runs on every frame (not only when lost) until, on a
  // full refinement window, its best point agrees with the estimate within one grid step (on
  // each axis; √3 steps in all). A few frames can have their global optimum far off; the frames a
  // full window holds do not.
  bool acquire_with_grid = true;
  // While acquiring, after the grid, δ is scanned over its whole bound at the grid's rotation and
  // the search starts from the best δ (unless the profile has a second peak nearly as high).
  bool acquire_time_offset = true;
  // The scan's δ is taken only when the estimate's δ scores less than this share of the way from
  // the profile's lowest score to its best: where the two nearly tie, the local search decides
  // (the scan's best wanders while the rotation is still off).
  // Measured: docs/tuning.md#acquire-time-offset-keep-ratio
  double acquire_time_offset_keep_ratio = 0.9;
  // When lost, also search from the last healthy estimate and offer the result as a candidate.
  bool search_from_last_healthy = true;
  // While tracking (not lost; once acquired, a lost update's translation and δ too), an accepted
  // update moves this share of the way to the new estimate: a first-order filter that averages the
  // scatter of single windows (on a street they scatter by a few tenths of a degree). Not the
  // first update without the folds (Folds::kDropWhenTracking): it moves the whole way.
  double tracking_gain = 0.3;
  // ... but the rotation never lags an accepted update's estimate by more than this
  // (TrackingRotationShare): a move beyond a single window's scatter is taken as a correction,
  // but for this remainder (0 = off: tracking_gain alone) [deg]. With the gain alone a start
  // that the first search left far off closes only tracking_gain of the gap per update.
  // Measured: docs/tuning.md#tracking-max-lag
  double tracking_max_lag_deg = 0.3;
  // Candidates are judged by their window score (the score map: a wide basin, but its peak can sit
  // a few tenths of a degree from the refinement's optimum). The refined rotation, with the chosen
  // candidate's translation and δ, is taken in place of the best-scoring candidate when it scores
  // within this share of the best (candidates and the current estimate): the refinement knows
  // where on the peak, the score only where the peak is. Beyond the share the refinement has
  // followed a few frames' misfits off the peak. Not on a coarse window while acquiring (its
  // refinement starts from a search still finding the peak). 0 = the best score wins.
  // Measured: docs/tuning.md#refined-score-tolerance
  double refined_score_tolerance = 0.1;
  // While tracking (acquisition over, a full window, health at least lost_health), the search
  // and refinement run on every n-th frame only; the frames between join the window and have
  // their health measured, and a frame whose health falls below lost_health runs at once (so does
  // the first frame without the folds, Folds::kDropWhenTracking). With
  // n = window_frames every frame lies in exactly one searched window and in every refinement
  // that covers it: the same data, read once instead of n times. 1 = update on every frame.
  int tracking_update_every = 3;
  // The LiDAR edges' folds (LidarEdgeOptions::fold_height_tolerance_m): kept, dropped from every
  // window, or dropped once acquired (from the first frame after the acquisition: the grid, the δ
  // scan and the updates that acquire read them; tracking, refinement, polish and the verdict's
  // profiles do not). Whatever the choice, the health (a frame's, the lost test's, the verdict's
  // final health) reads every point: see HealthWindow.
  // Folds bias the vertical translation and KITTI's roll, but the first frames' search needs
  // them: kDropWhenTracking, the default, keeps them for the acquisition only. The frame they are
  // first dropped on updates at once and by a full step (the acquired translation carries the
  // folds' bias, into which a polish would otherwise refine the rotation).
  // kDropWhenTracking without the grid's acquisition (acquire_with_grid off, lost_grid_deg 0)
  // keeps them: there is no acquisition to end. Once dropped, they stay out of every later
  // window, a lost estimate's grid and search included. Measured: docs/tuning.md#folds
  enum class Folds { kKeep, kDrop, kDropWhenTracking };
  Folds folds = Folds::kDropWhenTracking;

  // Whether the search reads the frames' coarse score levels (their pyramid): only without the
  // rotation grid (lost_grid_deg = 0), where a lost or filling window searches coarse to fine.
  // With the grid every search starts on the finest map, and a frame source can leave the
  // pyramid out (its blurs cost time on every frame; measured: docs/tuning.md#reads-coarse-levels).
  bool ReadsCoarseLevels() const { return lost_grid_deg <= 0; }
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
// Acquiring: a rotation grid around the start runs on every update until it agrees with the
// estimate on a full refinement window. Tracking: acquired and healthy; updates every
// tracking_update_every frames, each moving part of the way. Lost: acquired, but the health at
// the estimate fell under lost_health; searches coarse-to-fine until healthy again.
enum class Phase { kFilling, kAcquiring, kTracking, kLost };
std::string PhaseName(Phase phase);  ///< filling | acquiring | tracking | lost

// What a phase transition reads.
struct PhaseInputs {
  int window_size = 0;       ///< frames in the search window now
  int window_frames = 0;     ///< the search window's length
  bool acquisition = true;   ///< the calibrator acquires with a rotation grid at all
  bool grid_agreed = false;  ///< a grid agreed with the estimate on a full refinement window
  double health = 0;         ///< at the estimate on the latest window
  double lost_health = 0;    ///< under it an acquired estimate is lost
};
// The phase after `current` given `in`. Filling ends when the window is full (into acquiring,
// or straight to tracking/lost without an acquisition); acquiring ends only when the grid
// agreed; tracking and lost follow the health. No phase goes back to filling or acquiring.
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
  bool coarse_search = false;
  bool acquiring = false;  ///< the calibrator was still acquiring when the frame arrived
  // Frames of this update's rotation grid when its best rotation agreed with the estimate (within
  // one grid step); 0 when it did not or no grid ran.
  int grid_agreement_frames = 0;
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

// What the user knows of the start (`stcalib calibrate --init_uncertainty`): each axis of the
// initial calibration may be off by up to these figures.
struct StartUncertainty {
  double rotation_deg = 0;   ///< per axis (roll, pitch, yaw) [deg]
  double translation_m = 0;  ///< per axis (x, y, z) [m]
  double time_offset_s = 0;  ///< δ0's error [s]
};
// "ROT_DEG,TRANS_M,TIME_S" (three non-negative numbers; empty: all zero), else an error naming
// the text and what is wrong with it.
Status ParseStartUncertainty(const std::string& text, StartUncertainty* uncertainty);
// `options` widened for a start that far off, never narrowed (a zero figure leaves its settings;
// the defaults hold a start within about ±3°, ±5 cm and ±30 ms): the acquisition grid covers the
// rotation error plus a basin (lost_grid_deg), the search's bounds hold the truth, and the
// translation and δ priors (whose σ the verdict's translation rule reads) are at least as wide
// as the start's error. `initial_time_offset_s`: δ0, around which the δ bound must reach.
OnlineCalibratorOptions ForStartUncertainty(const OnlineCalibratorOptions& options,
                                            const StartUncertainty& uncertainty,
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
  // The rotation grid's per-frame scores (acquiring or lost), kept across frames.
  const RotationGridCache& grid_cache() const { return grid_cache_; }
  // Still acquiring (OnlineCalibratorOptions::acquire_with_grid with a grid): the rotation grid
  // has not yet agreed with the estimate on a full refinement window.
  bool acquiring() const {
    return Acquires() && (phase_ == Phase::kFilling || phase_ == Phase::kAcquiring);
  }
  Phase phase() const { return phase_; }
  // The final step of a run: refines the rotation, δ and the translation along the direction of
  // travel over the latest refine_frames frames from the estimate (the lateral and vertical
  // translation held). While tracking, the estimate moves only tracking_gain of the way per update
  // and each move is judged on the score map, whose peak can sit a few tenths of a degree from the
  // refinement's optimum: the search is for finding the peak, the refinement for where on it.
  // While tracking, the forward translation is held at the start's and δ absorbs its error (δ
  // error = forward error ÷ speed); over the whole window, speed changes and turns can separate
  // the two. The forward translation and δ move together when both are observable (forward std
  // under polish_forward_std_m, δ std under refine.observable_time_s); otherwise both stay and the
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
  // dropped, at tracking_horizontal_weight.
  const ScoreOptions& ScoreOptionsInUse() const {
    return (folds_dropped_ ? fold_free_options_ : options_).score;
  }
  // `polish`: for the final polish (OnlineCalibratorOptions::acquired_loss).
  RefineOptions RefineOptionsInUse(bool polish = false) const {
    RefineOptions refine = (folds_dropped_ ? fold_free_options_ : options_).refine;
    if (!acquiring() && (polish || options_.acquired_loss_when_tracking)) {
      refine.loss = options_.acquired_loss;
      refine.loss_scale_px = options_.acquired_loss_scale_px;
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
  // to report->after (by a full step when `full_step`).
  void Update(WindowScorer* scorer, bool full_step, FrameReport* report);
  std::vector<const CalibrationFrame*> RefineWindow() const;  ///< latest refine_frames
  // The rotation grid around `centre` (its translation and δ): ±lost_grid_deg, or while `wide`
  // ±wide_grid_deg, at several δ when wide_time_offset_s is set (the best pair).
  RotationGridResult AcquisitionGrid(WindowScorer* long_scorer, const CalibrationState& centre,
                                     const AdaptiveGridSearchOptions& search_options, bool wide);
  // Rotation grid (when lost or acquiring; ends acquisition when it agrees with the estimate on
  // a full window) then the adaptive search: fills report->search and search_ms.
  void Search(WindowScorer* scorer, WindowScorer* long_scorer,
              AdaptiveGridSearchOptions* search_options, FrameReport* report);
  // The refined estimate, the search result and, when lost, a search from the last healthy
  // estimate; the axes the refinement found unobservable held.
  std::vector<Candidate> Candidates(WindowScorer* scorer,
                                    const AdaptiveGridSearchOptions& search_options,
                                    FrameReport* report) const;
  // The best candidate within the bounds that scores at least as well as the estimate on the
  // refinement's frames, moved by tracking_gain while tracking (after the acquisition, a lost
  // update's translation and δ too; the whole way when `full_step` and not lost): fills
  // report->after.
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

  // Whether there is an acquisition at all (acquire_with_grid with a grid).
  bool Acquires() const { return options_.acquire_with_grid && options_.lost_grid_deg > 0; }
  // phase_ after this frame's window size, health and whether a grid agreed.
  void UpdatePhase(int window_size, double health, bool grid_agreed = false);

  OnlineCalibratorOptions options_;
  CalibrationState state_;
  CalibrationState anchor_;  ///< the initial calibration: the search's bounds are around it
  Phase phase_ = Phase::kFilling;
  bool folds_dropped_ = false;  ///< OnlineCalibratorOptions::Folds::kDropWhenTracking in effect
  // options_ with horizontal_weight at tracking_horizontal_weight, shared into score and refine
  // by WithSharedSettings: what the calibrator reads once the folds are dropped.
  OnlineCalibratorOptions fold_free_options_;
  bool refit_pending_ = false;  ///< the first update without the folds has not run yet
  // The latest estimate whose health reached lost_health after a full window: when the estimate
  // is lost, a search from there is a candidate too (a disturbance or a wrong jump).
  bool has_last_healthy_ = false;
  double last_health_ = 0;  ///< health at the estimate on the latest window
  // Tracking frames since the last search and refinement (starts due: the first updates).
  int frames_since_update_ = 0;
  CalibrationState last_healthy_;
  // A frame of the window: all its points (pruned to the image) and the same without its folds
  // (the same frame with Folds::kKeep).
  struct WindowFrame {
    std::shared_ptr<const CalibrationFrame> all, without_folds;
    // The same two for the refinement (OnlineCalibratorOptions::refine_map_sweeps).
    std::shared_ptr<const CalibrationFrame> refine_all, refine_without_folds;
  };
  // The version of `frame` the calibrator reads now (OnlineCalibratorOptions::folds), for the
  // search and score or for the refinement.
  const std::shared_ptr<const CalibrationFrame>& InUse(const WindowFrame& frame,
                                                       bool refine = false) const;
  // The latest `count` frames as read now, or with every point (folds included).
  std::vector<const CalibrationFrame*> LatestFrames(int count, bool with_folds = false,
                                                    bool refine = false) const;
  std::deque<WindowFrame> window_;  // the last refine_frames frames
  // The rotation grid's per-frame scores: while acquiring the grid runs on a window that grows
  // by one frame, and each frame is scored once as long as the translation and δ stay put.
  RotationGridCache grid_cache_;
  // The grids' centre: the start's rotation, or the wide stage's result once it narrowed.
  Eigen::Matrix3d grid_center_rotation_;
  bool grid_narrowed_ = true;      ///< no wide stage, or it has ended
  HealthScoreCache health_cache_;  // the estimate's health, frame by frame
  double last_camera_time_s_ = -std::numeric_limits<double>::infinity();
};

}  // namespace stcalib
