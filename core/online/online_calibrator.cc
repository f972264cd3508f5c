#include "core/online/online_calibrator.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <limits>
#include <optional>
#include <utility>

#include "core/types/enum_names.h"

namespace stcalib {
namespace {

// The span of a lost estimate's lattice (at most the start's): a disturbance, not a new start.
// Wider, on the shared drive the fine score's side peaks 4-5° away outscore the estimate's over a
// fold-free window (docs/tuning.md#lost-span).
constexpr StartUncertainty kLostSpan{3.0, 0.05, 0.02};
// While acquiring, the estimate leaves its own peak for the best hypothesis only when that leads
// it by this many standard errors (JudgeDominance's t): a few frames' scores are ambiguous, and a
// jump to a side peak costs the frames until the next jump back.
// Measured: docs/tuning.md#lattice-steps
constexpr double kJumpStandardErrors = 2.0;

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

CalibrationState KeepObservableAxes(const CalibrationState& old, const CalibrationState& candidate,
                                    const std::array<bool, kNumAxes>& observable) {
  const Eigen::Vector3d rotation =
      LogSO3(old.T_camera_lidar.linear().transpose() * candidate.T_camera_lidar.linear());
  const Eigen::Vector3d translation =
      candidate.T_camera_lidar.translation() - old.T_camera_lidar.translation();
  Eigen::Vector3d r = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    if (observable[k]) r[k] = rotation[k];
    if (observable[3 + k]) t[k] = translation[k];
  }
  return Step(old, r, t, observable[6] ? candidate.time_offset_s - old.time_offset_s : 0.0);
}

Status OnlineCalibratorOptions::Validate() const {
  if (window_frames < 1) return Status::Error("online: window_frames must be >= 1");
  if (refine_frames < 1) return Status::Error("online: refine_frames must be >= 1");
  if (!(refined_score_tolerance >= 0 && refined_score_tolerance < 1)) {
    return Status::Error("online: refined_score_tolerance must be in [0, 1)");
  }
  if (!(tracking_max_lag_deg >= 0)) {
    return Status::Error("online: tracking_max_lag_deg must be >= 0");
  }
  if (tracking_update_every < 1) {
    return Status::Error("online: tracking_update_every must be >= 1");
  }
  if (!(horizontal_weight >= 0 && horizontal_weight <= 1)) {
    return Status::Error("online: horizontal_weight must be in [0, 1]");
  }
  if (!(start_uncertainty.rotation_deg > 0 && start_uncertainty.translation_m > 0 &&
        start_uncertainty.time_offset_s > 0)) {
    return Status::Error("online: every start_uncertainty figure must be > 0");
  }
  const Status fits = HypothesisLattice::CheckFits(start_uncertainty, LatticeSteps());
  if (!fits.ok()) {
    return Status::Error("online: start_uncertainty " + StartUncertaintyText(start_uncertainty) +
                         ": " + fits.message());
  }
  STCALIB_RETURN_IF_ERROR(search.Validate());
  return refine.Validate();
}

double TrackingRotationShare(double gain, double rotation_rad, double max_lag_rad) {
  if (max_lag_rad > 0 && (1.0 - gain) * rotation_rad > max_lag_rad) {
    return 1.0 - max_lag_rad / rotation_rad;
  }
  return gain;
}

namespace {
constexpr EnumNames<Phase, 4> kPhaseNames = {{{Phase::kFilling, "filling"},
                                              {Phase::kAcquiring, "acquiring"},
                                              {Phase::kTracking, "tracking"},
                                              {Phase::kLost, "lost"}}};
}  // namespace

std::string PhaseName(Phase phase) { return EnumName(kPhaseNames, phase); }

Phase NextPhase(Phase current, const PhaseInputs& in) {
  const Phase acquired = in.health >= in.lost_health ? Phase::kTracking : Phase::kLost;
  switch (current) {
    case Phase::kFilling:
      if (in.window_size < in.window_frames) return Phase::kFilling;
      return in.dominant ? acquired : Phase::kAcquiring;
    case Phase::kAcquiring:
      return in.dominant ? acquired : Phase::kAcquiring;
    case Phase::kTracking:
    case Phase::kLost:
      return acquired;
  }
  return current;
}

namespace {
constexpr EnumNames<OnlineCalibratorOptions::Folds, 3> kFoldsNames = {
    {{OnlineCalibratorOptions::Folds::kKeep, "keep"},
     {OnlineCalibratorOptions::Folds::kDrop, "drop"},
     {OnlineCalibratorOptions::Folds::kDropWhenTracking, "drop_when_tracking"}}};
}  // namespace

std::string FoldsName(OnlineCalibratorOptions::Folds folds) { return EnumName(kFoldsNames, folds); }

bool ParseFolds(const std::string& name, OnlineCalibratorOptions::Folds* folds) {
  return ParseEnumName(kFoldsNames, name, folds);
}

std::string FoldsChoices() { return EnumNameChoices(kFoldsNames); }

OnlineCalibratorOptions WithSharedSettings(const OnlineCalibratorOptions& options) {
  OnlineCalibratorOptions out = options;
  out.search.time_offset_bound_s = options.time_offset_bound_s;
  out.refine.time_offset_bound_s = options.time_offset_bound_s;
  out.score.horizontal_weight = options.horizontal_weight;
  out.refine.horizontal_weight = options.horizontal_weight;
  return out;
}

OnlineCalibratorOptions WithStartUncertainty(const OnlineCalibratorOptions& options,
                                             double initial_time_offset_s) {
  OnlineCalibratorOptions out = options;
  const StartUncertainty& u = options.start_uncertainty;
  // The bounds are norms over the three axes.
  constexpr double kBasinDeg = 1.0;  // the band-pass score's peak, docs/method.md §10
  const double kAxes = std::sqrt(3.0);
  out.search.max_rotation_offset_deg =
      std::max(out.search.max_rotation_offset_deg, kAxes * u.rotation_deg + kBasinDeg);
  out.search.max_translation_offset_m =
      std::max(out.search.max_translation_offset_m, kAxes * u.translation_m + 0.05);
  out.search.translation_prior_sigma_m =
      std::max(out.search.translation_prior_sigma_m, u.translation_m);
  out.refine.prior_sigma_translation_m =
      std::max(out.refine.prior_sigma_translation_m, u.translation_m);
  out.search.time_offset_prior_sigma_s =
      std::max(out.search.time_offset_prior_sigma_s, u.time_offset_s);
  out.refine.prior_sigma_time_s = std::max(out.refine.prior_sigma_time_s, u.time_offset_s);
  out.time_offset_bound_s =
      std::max(out.time_offset_bound_s, std::abs(initial_time_offset_s) + u.time_offset_s);
  return out;
}

OnlineCalibrator::OnlineCalibrator(const OnlineCalibratorOptions& options,
                                   const CalibrationState& initial)
    : options_(WithSharedSettings(options)), state_(initial), acquisition_(options.refine_frames) {
  CHECK(options_.Validate().ok()) << options_.Validate().message();
  state_.time_offset_s =
      std::clamp(state_.time_offset_s, -options_.time_offset_bound_s, options_.time_offset_bound_s);
  anchor_ = state_;
  frames_since_update_ = options_.tracking_update_every;
  OnlineCalibratorOptions fold_free = options_;
  fold_free.horizontal_weight = kFoldFreeHorizontalWeight;
  fold_free_options_ = WithSharedSettings(fold_free);
  // The lattice around the start; too large a lattice is a usage error the CLI reports first.
  const Status centred =
      acquisition_.Centre(state_, {}, options_.horizontal_weight, options_.start_uncertainty);
  CHECK(centred.ok()) << centred.message();
}

const std::shared_ptr<const CalibrationFrame>& OnlineCalibrator::InUse(
    const WindowFrame& frame) const {
  const bool drop = options_.folds == OnlineCalibratorOptions::Folds::kDrop || folds_dropped_;
  return drop ? frame.without_folds : frame.all;
}

std::vector<const CalibrationFrame*> OnlineCalibrator::LatestFrames(int count,
                                                                    bool with_folds) const {
  std::vector<const CalibrationFrame*> frames;
  const size_t n = std::min<size_t>(window_.size(), count);
  for (size_t k = window_.size() - n; k < window_.size(); ++k) {
    const WindowFrame& frame = window_[k];
    frames.push_back(with_folds ? frame.all.get() : InUse(frame).get());
  }
  return frames;
}

std::vector<const CalibrationFrame*> OnlineCalibrator::HealthWindow() const {
  return LatestFrames(options_.window_frames, /*with_folds=*/true);
}

WindowScorer* OnlineCalibrator::HealthScorer(const std::vector<const CalibrationFrame*>& window,
                                             WindowScorer* scorer,
                                             std::optional<WindowScorer>* own) const {
  const std::vector<const CalibrationFrame*> health_window = HealthWindow();
  if (health_window == window) return scorer;
  own->emplace(health_window, ScoreOptionsInUse());
  return &**own;
}

std::vector<const CalibrationFrame*> OnlineCalibrator::SearchWindow() const {
  return LatestFrames(options_.window_frames);
}

std::vector<std::shared_ptr<const CalibrationFrame>> OnlineCalibrator::RecentFrames() const {
  std::vector<std::shared_ptr<const CalibrationFrame>> frames;
  for (const WindowFrame& frame : window_) frames.push_back(InUse(frame));
  return frames;
}

FrameReport OnlineCalibrator::SkipFrame(int frame, const std::string& why) const {
  FrameReport report;
  report.frame = frame;
  report.acquiring = acquiring();
  report.phase = phase_;
  report.before = report.after = state_;
  report.skipped = true;
  report.reason = "frame skipped: " + why + "; estimate kept";
  LOG(WARNING) << "frame " << frame << " skipped: " << why;
  return report;
}

std::vector<const CalibrationFrame*> OnlineCalibrator::RefineWindow() const {
  return LatestFrames(options_.refine_frames);
}

std::string OnlineCalibrator::RefusalReason(const CalibrationFrame& frame) const {
  const bool finite_motion = std::isfinite(frame.e0_s) && std::isfinite(frame.camera_time_s) &&
                             frame.twist.linear_m_s.allFinite() &&
                             frame.twist.angular_rad_s.allFinite();
  if (!finite_motion) return "non-finite stamp gap or motion";
  if (!(frame.camera_time_s > last_camera_time_s_)) {
    return "image stamp not after the previous frame's (duplicated or out of order)";
  }
  if (frame.image.empty() || frame.distance_px[0].empty() || frame.distance_px[1].empty()) {
    return "no image edges (black, blank or unreadable image)";
  }
  return "";
}

FrameReport OnlineCalibrator::AddFrame(std::shared_ptr<const CalibrationFrame> frame,
                                       bool update_now) {
  const std::string why = RefusalReason(*frame);
  if (!why.empty()) return SkipFrame(frame->index, why);
  last_camera_time_s_ = frame->camera_time_s;
  const bool refit = DropFoldsOnceAcquired();
  FrameReport report;
  report.frame = frame->index;
  report.acquiring = acquiring();
  report.before = report.after = state_;
  report.phase = phase_;
  AdmitToWindow(*frame);
  const std::vector<const CalibrationFrame*> frames = SearchWindow();
  for (const CalibrationFrame* f : frames) report.points += static_cast<int>(f->size());
  if (report.points < 30) {
    report.reason = "too few LiDAR edge points in the image (" + std::to_string(report.points) +
                    "): estimate kept";
    return report;
  }
  // The estimate on the search window; the health reads every point, folds included.
  WindowScorer scorer(frames, ScoreOptionsInUse());
  std::optional<WindowScorer> own_health_scorer;
  WindowScorer* health_scorer = HealthScorer(frames, &scorer, &own_health_scorer);
  report.score_before = scorer.Evaluate(state_, -1);
  report.gray_rate_before = scorer.GrayRate(state_);
  report.health_before = HealthScore(health_scorer, state_, kHealthRotationDeg, kHealthTranslationM,
                                     nullptr, &health_cache_);
  const int window_size = static_cast<int>(frames.size());
  UpdatePhase(window_size, report.health_before);
  const std::string wait = WhyNoUpdate(window_size, update_now || refit, report.health_before);
  if (!wait.empty()) return KeepEstimate(report, wait);
  // The paper's update: search (from the best hypothesis while acquiring or lost), refine, choose.
  const bool compared_hypotheses = Update(&scorer, refit, &report);
  MeasureEstimate(&scorer, health_scorer, report.accepted, &report);
  RememberIfHealthy(report.health, window_size);
  // The acquisition ends when one hypothesis dominates and the estimate sits on its peak.
  const std::vector<Hypothesis>& hypotheses = acquisition_.hypotheses();
  const bool dominant =
      compared_hypotheses && acquisition_.dominance().dominant && !hypotheses.empty() &&
      RotationErrorDeg(hypotheses.front().state.T_camera_lidar.linear(),
                       state_.T_camera_lidar.linear()) < DominanceOptions().merge_deg;
  UpdatePhase(window_size, report.health, dominant);
  report.phase = phase_;
  return report;
}

bool OnlineCalibrator::DropFoldsOnceAcquired() {
  // From the first frame after the acquisition (its last update and a polish right after it read
  // the frames the estimate was acquired on). Once dropped they stay out, of a lost estimate's
  // lattice too. The first frame without them that updates does so at once and by a full step
  // (the refit): the estimate was acquired with the folds, and its translation carries their
  // bias.
  if (options_.folds == OnlineCalibratorOptions::Folds::kDropWhenTracking && !acquiring() &&
      !folds_dropped_) {
    folds_dropped_ = true;
    refit_pending_ = true;
    // A lattice re-centred while lost holds frames with their folds: score them again as read
    // from now on.
    if (phase_ == Phase::kLost) RecentreLattice(acquisition_.lattice().centre(), LostSpan());
  }
  return refit_pending_;
}

void OnlineCalibrator::AdmitToWindow(const CalibrationFrame& frame) {
  WindowFrame in_window;
  in_window.all = PruneToImage(frame, state_, options_.point_margin);
  in_window.without_folds = options_.folds == OnlineCalibratorOptions::Folds::kKeep
                                ? in_window.all
                                : WithoutFolds(in_window.all);
  window_.push_back(std::move(in_window));
  while (static_cast<int>(window_.size()) >
         std::max(options_.window_frames, options_.refine_frames)) {
    window_.pop_front();
  }
  // The lattice scores the frame once, while the estimate is not (or no longer) acquired.
  if (phase_ != Phase::kTracking) {
    acquisition_.AddFrame(*InUse(window_.back()), ScoreOptionsInUse().horizontal_weight);
  }
}

std::string OnlineCalibrator::WhyNoUpdate(int window_size, bool update_now, double health_before) {
  if (phase_ == Phase::kFilling) {
    return "window filling (" + std::to_string(window_size) + " of " +
           std::to_string(options_.window_frames) + " frames): estimate kept";
  }
  if (phase_ == Phase::kTracking && !update_now &&
      ++frames_since_update_ < options_.tracking_update_every) {
    RememberIfHealthy(health_before, window_size);
    return "tracking: healthy, next update in " +
           std::to_string(options_.tracking_update_every - frames_since_update_) +
           " frame(s): estimate kept";
  }
  frames_since_update_ = 0;
  return "";
}

bool OnlineCalibrator::Update(WindowScorer* scorer, bool full_step, FrameReport* report) {
  // The lattice's hypotheses are read while acquiring or lost (or when the estimate's health says
  // it is lost now).
  const bool read_hypotheses = phase_ == Phase::kAcquiring || phase_ == Phase::kLost ||
                               report->health_before < options_.lost_health;
  // The refinement's frames, every point of their maps: the hypotheses' and candidates' judge.
  const std::vector<const CalibrationFrame*> refine_window = RefineWindow();
  WindowScorer long_scorer(refine_window, ScoreOptionsInUse());
  AdaptiveGridSearchOptions search_options = options_.search;
  Search(scorer, &long_scorer, search_options, read_hypotheses, report);
  const auto start = std::chrono::steady_clock::now();
  report->refine = Refine(refine_window, report->search.state, report->search.state, anchor_,
                          RefineOptionsInUse());
  report->refine_ms = MillisecondsSince(start);
  Choose(Candidates(report), &long_scorer, search_options, full_step, report);
  refit_pending_ = false;
  state_ = report->after;
  return read_hypotheses;
}

StartUncertainty OnlineCalibrator::LostSpan() const {
  const StartUncertainty& start = options_.start_uncertainty;
  return {std::min(start.rotation_deg, kLostSpan.rotation_deg),
          std::min(start.translation_m, kLostSpan.translation_m),
          std::min(start.time_offset_s, kLostSpan.time_offset_s)};
}

void OnlineCalibrator::RecentreLattice(const CalibrationState& centre,
                                       const StartUncertainty& span) {
  // The span is at most the start's, whose lattice Validate() admitted.
  const Status centred =
      acquisition_.Centre(centre, RefineWindow(), ScoreOptionsInUse().horizontal_weight, span);
  CHECK(centred.ok()) << centred.message();
}

void OnlineCalibrator::UpdatePhase(int window_size, double health, bool dominant) {
  PhaseInputs in;
  in.window_size = window_size;
  in.window_frames = options_.window_frames;
  in.dominant = dominant;
  in.health = health;
  in.lost_health = options_.lost_health;
  const Phase before = phase_;
  phase_ = NextPhase(phase_, in);
  if (phase_ == Phase::kLost && before != Phase::kLost) {
    // Re-acquire around the last healthy estimate: the lattice, over a disturbance's span (a lost
    // estimate was good a moment ago), scores the window's frames anew.
    RecentreLattice(has_last_healthy_ ? last_healthy_ : state_, LostSpan());
  }
}

FrameReport OnlineCalibrator::Polish() {
  FrameReport report;
  report.frame = -1;
  report.before = report.after = state_;
  const std::vector<const CalibrationFrame*> frames = RefineWindow();
  if (frames.empty() || acquiring() || last_health_ < options_.lost_health) {
    report.reason = frames.empty() ? "polish: no frames"
                    : acquiring()  ? "polish: still acquiring"
                                   : "polish: the last window is not healthy";
    return report;
  }
  const auto start = std::chrono::steady_clock::now();
  // Rotation, δ and the translation along the direction of travel (see the header).
  RefineOptions refine_options = RefineOptionsInUse();
  refine_options.translation = RefineOptions::Translation::kAlongTravel;
  refine_options.place_at_time_offset = true;
  report.refine = Refine(frames, state_, state_, anchor_, refine_options);
  // The forward translation and δ move together or not at all: where the window cannot separate
  // them, one alone would slide along their ridge. Then the rotation is refined again with both
  // held, so that it does not follow their drift. (With δ not estimated there is no ridge and the
  // forward translation moves alone when its std allows.)
  const RefineResult pair = report.refine;
  const bool pair_observable = pair.usable && pair.covariance_ok &&
                               pair.forward_std_m < kPolishForwardStdM &&
                               (!refine_options.estimate_time_offset || pair.observable[6]);
  if (!pair_observable) {
    refine_options.translation = RefineOptions::Translation::kHeld;
    refine_options.estimate_time_offset = false;
    report.refine = Refine(frames, state_, state_, anchor_, refine_options);
  }
  report.refine_ms = MillisecondsSince(start);
  report.time_forward.measured =
      pair.usable && pair.covariance_ok && options_.refine.estimate_time_offset;
  if (report.time_forward.measured) {
    report.time_forward.time_offset_std_s = pair.std_dev[6];
    report.time_forward.forward_std_m = pair.forward_std_m;
    report.time_forward.correlation = pair.time_forward_correlation;
    report.time_forward.forward_camera = pair.forward_camera;
  }
  if (!report.refine.usable) {
    report.reason = "polish: refinement failed (" + report.refine.message + ")";
    return report;
  }
  std::array<bool, kNumAxes> move = report.refine.observable;
  for (int k = 3; k < kNumAxes; ++k) move[k] = pair_observable;
  if (!refine_options.estimate_time_offset) move[6] = false;
  CalibrationState polished = KeepObservableAxes(state_, report.refine.state, move);
  // The refined rotation is taken only where the window's score agrees that it is no worse than
  // the online one (with the same translation and δ): the refinement's cost and the score weigh
  // the frames' misfits differently, and a move only one of them prefers is as likely to be
  // wrong as right (docs/tuning.md#polish-rotation).
  bool rotation_kept = false;
  {
    CalibrationState online_rotation = polished;
    online_rotation.T_camera_lidar.linear() = state_.T_camera_lidar.linear();
    WindowScorer window_scorer(frames, ScoreOptionsInUse());
    if (window_scorer.Evaluate(polished, -1).score <
        window_scorer.Evaluate(online_rotation, -1).score) {
      polished = online_rotation;
      rotation_kept = true;
    }
  }
  if (!WithinBounds(polished, anchor_, options_.search)) {
    report.reason = "polish: the refined estimate leaves the bounds";
    return report;
  }
  report.after = state_ = polished;
  report.accepted = true;
  report.time_forward.separated = report.time_forward.measured && pair_observable;
  char pair_text[160] = "";
  if (pair.covariance_ok) {
    std::snprintf(pair_text, sizeof(pair_text),
                  "; forward translation and δ %s (std %.1f cm, %.1f ms, correlation %+.2f)",
                  pair_observable ? "refined" : "held", 100 * pair.forward_std_m,
                  1000 * pair.std_dev[6], pair.time_forward_correlation);
  }
  report.reason = "polish: refined over " + std::to_string(frames.size()) + " frames" + pair_text +
                  (rotation_kept ? "; rotation kept (the window's score prefers it)" : "");
  // On the search window (the health on HealthWindow), like a frame's.
  const std::vector<const CalibrationFrame*> window = SearchWindow();
  WindowScorer scorer(window, ScoreOptionsInUse());
  std::optional<WindowScorer> own_health_scorer;
  MeasureEstimate(&scorer, HealthScorer(window, &scorer, &own_health_scorer), true, &report);
  return report;
}

void OnlineCalibrator::RememberIfHealthy(double health, size_t window_size) {
  if (health >= options_.lost_health && static_cast<int>(window_size) >= options_.window_frames) {
    has_last_healthy_ = true;
    last_healthy_ = state_;
  }
}

FrameReport OnlineCalibrator::KeepEstimate(FrameReport report, const std::string& reason) {
  report.reason = reason;
  report.phase = phase_;
  report.score_after = report.score_before;
  report.gray_rate_after = report.gray_rate_before;
  report.health = last_health_ = report.health_before;
  return report;
}

void OnlineCalibrator::MeasureEstimate(WindowScorer* scorer, WindowScorer* health_scorer,
                                       bool moved, FrameReport* report) {
  report->score_after = scorer->Evaluate(state_, -1);
  report->gray_rate_after = scorer->GrayRate(state_);
  // The health of an unchanged estimate is the one measured before.
  report->health = moved ? HealthScore(health_scorer, state_, kHealthRotationDeg,
                                       kHealthTranslationM, nullptr, &health_cache_)
                         : report->health_before;
  last_health_ = report->health;
}

void OnlineCalibrator::Search(WindowScorer* scorer, WindowScorer* long_scorer,
                              const AdaptiveGridSearchOptions& search_options, bool read_hypotheses,
                              FrameReport* report) {
  const auto start = std::chrono::steady_clock::now();
  CalibrationState search_start = state_;
  int evaluations = 0;
  if (read_hypotheses) {
    // The lattice's best peaks, refined on the fine maps and compared frame by frame on the
    // refinement's frames; the search starts from the best.
    const std::vector<Hypothesis>& hypotheses = acquisition_.Update(
        scorer, long_scorer, state_, anchor_, search_options,
        SharedSweepFrames(LatestFrames(static_cast<int>(window_.size()), /*with_folds=*/true)),
        &evaluations);
    // On the estimate's own peak the search refines the estimate; elsewhere it starts afresh
    // from the best hypothesis: while acquiring, once that leads the estimate's own by
    // kJumpStandardErrors; once acquired (a lost estimate), it leaves the last healthy
    // estimate's peak only for a hypothesis that dominates the others.
    const bool acquired = phase_ == Phase::kTracking || phase_ == Phase::kLost;
    if (acquired && has_last_healthy_) search_start = last_healthy_;
    const bool leads = acquired ? acquisition_.dominance().dominant
                                : acquisition_.LeadOverIncumbent() >= kJumpStandardErrors;
    if (!hypotheses.empty() && leads &&
        RotationErrorDeg(hypotheses.front().state.T_camera_lidar.linear(),
                         search_start.T_camera_lidar.linear()) >= DominanceOptions().merge_deg) {
      search_start = hypotheses.front().state;
    }
    report->from_hypotheses =
        search_start.T_camera_lidar.matrix() != state_.T_camera_lidar.matrix() ||
        search_start.time_offset_s != state_.time_offset_s;
    VLOG(1) << "frame " << report->frame << ": best hypothesis "
            << RotationErrorDeg(search_start.T_camera_lidar.linear(),
                                state_.T_camera_lidar.linear())
            << " deg from the estimate; " << acquisition_.dominance().detail << "; "
            << DescribeRivals(acquisition_.dominance());
  }
  report->search = AdaptiveGridSearch(scorer, search_start, anchor_, search_options);
  report->search.evaluations += evaluations;
  report->search_ms = MillisecondsSince(start);
}

std::vector<OnlineCalibrator::Candidate> OnlineCalibrator::Candidates(FrameReport* report) const {
  // A candidate keeps the axes the refinement found unobservable where they were: a degenerate
  // scene (open road, poles only) must not move what it cannot see. Without a covariance the
  // refined estimate cannot move and the search result moves freely.
  std::string held;
  for (int k = 0; k < kNumAxes; ++k) {
    if (!report->refine.observable[k]) held += std::string(", held ") + kAxisNames[k];
  }
  std::vector<Candidate> candidates;
  auto add = [&](const CalibrationState& candidate, const std::string& name, bool hold,
                 bool refined) {
    candidates.push_back(
        {hold ? KeepObservableAxes(state_, candidate, report->refine.observable) : candidate,
         hold ? name + held : name, refined});
  };
  const bool hold_search = report->refine.covariance_ok && !held.empty();
  if (report->refine.usable) add(report->refine.state, "refined", true, true);
  add(report->search.state, report->from_hypotheses ? "search from the best hypothesis" : "search",
      hold_search, false);
  return candidates;
}

void OnlineCalibrator::Choose(const std::vector<Candidate>& candidates, WindowScorer* long_scorer,
                              const AdaptiveGridSearchOptions& search_options, bool full_step,
                              FrameReport* report) const {
  // Judged on all the refinement's frames (a longer and steadier window than the search's): the
  // best candidate within the bounds, when it scores at least as well as the current estimate.
  report->after = state_;
  report->reason = "no candidate scored better: estimate kept";
  double best = long_scorer->Evaluate(state_, -1).score;
  size_t chosen = candidates.size();
  for (size_t c = 0; c < candidates.size(); ++c) {
    if (!WithinBounds(candidates[c].state, anchor_, search_options)) continue;
    const double value = long_scorer->Evaluate(candidates[c].state, -1).score;
    if (value < best) continue;
    best = value;
    chosen = c;
    report->after = candidates[c].state;
    report->accepted = true;
    report->reason = candidates[c].name;
  }
  // The refinement's rotation in place of the best-scoring one when it scores close enough: the
  // score map's peak can sit a few tenths of a degree from the refinement's optimum (the score
  // finds the peak, the refinement where on it). The translation and δ stay the chosen ones':
  // edges pin the translation down only to a few cm (the polish holds its lateral and vertical
  // axes too), and the refinement's δ runs along its ridge with the forward translation.
  if (options_.refined_score_tolerance > 0 && !candidates.empty() && candidates.front().refined &&
      chosen != 0 && !(report->from_hypotheses && report->acquiring)) {
    CalibrationState rotated = report->after;
    rotated.T_camera_lidar.linear() = candidates.front().state.T_camera_lidar.linear();
    const double value = WithinBounds(rotated, anchor_, search_options)
                             ? long_scorer->Evaluate(rotated, -1).score
                             : -std::numeric_limits<double>::infinity();
    if (value >= best - options_.refined_score_tolerance * std::abs(best)) {
      char share[112];
      const double percent = best != 0 ? 100.0 * (value - best) / std::abs(best) : 0.0;
      std::snprintf(share, sizeof(share), " (its rotation only: score %.1f %% %s the best%s)",
                    std::abs(percent), percent >= 0 ? "over" : "under",
                    percent >= 0 ? "" : ", within the tolerance");
      report->after = rotated;
      report->accepted = true;
      report->reason = candidates.front().name + share;
    }
  }
  // While tracking, move only part of the way (a first-order filter over frames): single windows
  // scatter, their average does not. A lost estimate jumps, in rotation only once acquired (and
  // healthy once): the translation and δ were estimated over the acquisition's frames, a lost
  // window is suspect, and a KITTI run's lost window at frame 28 moved the translation 5 cm with a
  // full jump.
  // The first update without the folds (full_step) moves the whole way, unless it is lost.
  const bool acquired = !report->acquiring && has_last_healthy_;
  if (report->accepted && full_step && !report->from_hypotheses) {
    report->reason = "folds dropped, a full step: " + report->reason;
  } else if (report->accepted && (!report->from_hypotheses || acquired) &&
             options_.tracking_gain < 1.0) {
    const CalibrationState& c = report->after;
    const double g = options_.tracking_gain;
    const Eigen::Vector3d rotation =
        LogSO3(state_.T_camera_lidar.linear().transpose() * c.T_camera_lidar.linear());
    const double g_rotation =
        report->from_hypotheses
            ? 1.0
            : TrackingRotationShare(g, rotation.norm(),
                                    options_.tracking_max_lag_deg * M_PI / 180.0);
    report->after = Step(state_, g_rotation * rotation,
                         g * (c.T_camera_lidar.translation() - state_.T_camera_lidar.translation()),
                         g * (c.time_offset_s - state_.time_offset_s));
  }
}

}  // namespace stcalib
