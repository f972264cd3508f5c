// The verdict's rules (Judge, core/online/convergence.h) and the calibrator's phase transitions
// (NextPhase, core/online/online_calibrator.h), each from hand-made inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/online/convergence.h"
#include "core/online/online_calibrator.h"
#include "core/refine/jackknife.h"

namespace stcalib {
namespace {

// Evidence every rule passes: 10 used frames, acquired, inside the bounds, every axis observable,
// profiles peaking at the estimate, a small translation move, healthy, settled, the suppressed
// check holding.
ConvergenceEvidence Passing() {
  ConvergenceEvidence e;
  e.used_frames = 10;
  e.last_points = 5000;
  e.updates = 8;
  e.last_reason = "refined";
  e.window_frames = 3;
  e.acquiring = false;
  e.rotation_moved_deg = 2.0;
  e.rotation_bound_deg = 5.0;
  e.time_offset_s = 0.03;
  e.time_offset_bound_s = 0.15;
  e.time_offset_profile.offsets_s = {0.0275, 0.03, 0.0325};
  e.time_offset_profile.scores = {0.9, 1.0, 0.9};
  e.time_offset_profile.best_s = 0.03;
  e.translation_move_m = Eigen::Vector3d(0.02, -0.03, 0.05);
  e.prior_sigma_translation_m = 0.05;
  e.final_health = 0.97;
  e.settle_deg = 0.05;
  RefineJackknife jackknife;
  jackknife.frames = 10;
  jackknife.blocks = 3;
  jackknife.std.head<3>() = Eigen::Vector3d(0.08, 0.05, 0.02);
  e.rotation_jackknife = jackknife;
  HealthCheckResult check;
  check.decided = check.holds = true;
  check.reason = "holds";
  e.suppressed_check = check;
  e.suppressed_check_frames = 9;
  return e;
}

// The first failing rule's name (empty when all pass), checking that the reason is its detail.
std::string FirstFailure(const ConvergenceEvidence& e,
                         const ConvergenceOptions& options = ConvergenceOptions()) {
  const Judgement j = Judge(e, options);
  EXPECT_EQ(j.rules.size(), ConvergenceRuleNames().size());
  for (const RuleOutcome& rule : j.rules) {
    if (rule.passed) continue;
    EXPECT_FALSE(j.converged);
    EXPECT_EQ(j.reason, "not converged: " + rule.detail);
    return rule.name;
  }
  EXPECT_TRUE(j.converged);
  EXPECT_EQ(j.reason, "converged");
  return "";
}

TEST(Judge, EvidenceThatPassesEveryRuleConverges) {
  EXPECT_EQ(FirstFailure(Passing()), "");
  const std::vector<std::string> names = ConvergenceRuleNames();
  ASSERT_EQ(names.size(), 15u);
  EXPECT_EQ(names.front(), "frames_used");
  EXPECT_EQ(names.back(), kSuppressedCheckRule);
}

TEST(Judge, EachRuleRefusesItsOwnFailure) {
  ConvergenceEvidence e = Passing();
  e.used_frames = 0;
  e.skipped_frames = 4;
  e.first_reason = "frame skipped: truncated";
  EXPECT_EQ(FirstFailure(e), "frames_used");
  EXPECT_NE(Judge(e, {}).reason.find("all 4 frames were skipped"), std::string::npos);

  e = Passing();
  e.last_points = 29;
  EXPECT_EQ(FirstFailure(e), "features");

  e = Passing();
  e.updates = 0;
  EXPECT_EQ(FirstFailure(e), "updated");

  e = Passing();
  e.used_frames = 2;
  EXPECT_EQ(FirstFailure(e), "enough_frames");

  e = Passing();
  e.acquiring = true;
  EXPECT_EQ(FirstFailure(e), "one_hypothesis_dominates");

  e = Passing();
  e.rotation_moved_deg = 4.6;  // within the 0.5° margin of the 5° bound
  EXPECT_EQ(FirstFailure(e), "inside_bounds");
  e = Passing();
  e.time_offset_s = -0.149;
  EXPECT_EQ(FirstFailure(e), "inside_bounds");
  e.time_offset_estimated = false;  // δ held at its start ran to nothing
  e.time_offset_profile = TimeOffsetProfile();
  EXPECT_EQ(FirstFailure(e), "");

  e = Passing();
  e.unobservable_axes = {"roll_deg"};
  EXPECT_EQ(FirstFailure(e), "observable");

  e = Passing();
  e.rotation_profiles[1].best_deg = 0.5;
  EXPECT_EQ(FirstFailure(e), "rotation_profiles");
  EXPECT_NE(Judge(e, {}).reason.find("peaks +0.50 deg away on pitch_deg"), std::string::npos);
  e = Passing();
  e.rotation_profiles[0].ambiguous = true;
  EXPECT_EQ(FirstFailure(e), "rotation_profiles");

  e = Passing();
  e.time_offset_profile.best_s = 0.045;  // 15 ms from the estimate's 30 ms
  EXPECT_EQ(FirstFailure(e), "time_offset_profile");

  e = Passing();
  e.translation_move_m.y() = -0.11;  // beyond 2 × 5 cm
  EXPECT_EQ(FirstFailure(e), "translation_within_prior");
  EXPECT_NE(Judge(e, {}).reason.find("-11.0 cm from the start on y_m"), std::string::npos);

  // Windows 15 cm apart across travel (y, with travel along z) fail; along travel they may.
  e = Passing();
  e.along_travel_axis = 2;
  e.translation_spread_m = Eigen::Vector3d(0.03, 0.149, 0.5);
  EXPECT_EQ(FirstFailure(e), "translation_spread");
  EXPECT_NE(Judge(e, {}).reason.find("spread 14.9 cm on y_m"), std::string::npos);
  e.translation_spread_m.y() = 0.07;
  EXPECT_EQ(FirstFailure(e), "");
  ConvergenceOptions no_limit;
  no_limit.max_translation_spread_m = 0;
  e.translation_spread_m.y() = 0.3;
  EXPECT_EQ(FirstFailure(e, no_limit), "");

  e = Passing();
  e.final_health = 0.85;
  EXPECT_EQ(FirstFailure(e), "health");

  e = Passing();
  e.settle_deg = 0.31;
  EXPECT_EQ(FirstFailure(e), "settled");

  e = Passing();
  e.rotation_jackknife->std.x() = 0.19;  // under 0.2°: a claim
  EXPECT_EQ(FirstFailure(e), "");
  e.rotation_jackknife->std.x() = 0.2;  // roll: leaving blocks out moves it 0.2°
  EXPECT_EQ(FirstFailure(e), kJackknifeRule);
  EXPECT_NE(Judge(e, {}).reason.find("roll_deg is not pinned down"), std::string::npos);
  e.rotation_jackknife->frames = 0;  // too few frames to leave a block out: nothing to judge
  EXPECT_EQ(FirstFailure(e), "");
  e.rotation_jackknife.reset();  // not measured is no pass
  EXPECT_EQ(FirstFailure(e), kJackknifeRule);

  e = Passing();
  e.suppressed_check->holds = false;
  EXPECT_EQ(FirstFailure(e), kSuppressedCheckRule);
  e.suppressed_check.reset();  // not measured is no pass
  EXPECT_EQ(FirstFailure(e), kSuppressedCheckRule);
  ConvergenceOptions off;
  off.check_suppressed_health = false;
  EXPECT_EQ(FirstFailure(e, off), "");
}

// Every rule is judged even after one fails, so a report lists all that fail; the reason is the
// first.
TEST(Judge, ListsEveryFailingRuleAndGivesTheFirstAsTheReason) {
  ConvergenceEvidence e = Passing();
  e.final_health = 0.5;
  e.settle_deg = 2.0;
  e.unobservable_axes = {"yaw_deg", "z_m"};
  const Judgement j = Judge(e, ConvergenceOptions());
  int failed = 0;
  for (const RuleOutcome& rule : j.rules) failed += !rule.passed;
  EXPECT_EQ(failed, 3);
  EXPECT_EQ(FirstFailure(e), "observable");
}

// A partial claim (docs/method.md §7): translation axes and δ the drive does not constrain are
// held at their start and named; every other rule still guards the claim; a rotation axis is
// never held.
TEST(Judge, APartialClaimHoldsTranslationOrTimeOffsetNeverTheRotation) {
  ConvergenceEvidence e = Passing();
  e.unobservable_axes = {"x_m", "time_offset_s"};
  e.time_offset_profile.best_s = 0.1;  // δ held: its profile does not apply
  Judgement j = Judge(e, ConvergenceOptions());
  EXPECT_TRUE(j.converged) << j.reason;
  EXPECT_EQ(j.held_axes, (std::vector<std::string>{"x_m", "time_offset_s"}));
  EXPECT_EQ(j.reason,
            "converged, partly: held at the start (not observable in this drive): x_m, "
            "time_offset_s");
  // δ held holds the translation along travel (camera z here) with it.
  e.along_travel_axis = 2;
  EXPECT_EQ(Judge(e, ConvergenceOptions()).held_axes,
            (std::vector<std::string>{"x_m", "z_m", "time_offset_s"}));

  // δ held by the polish's measurement: δ and the translation along travel (camera z here).
  e = Passing();
  e.time_offset_held = true;
  e.along_travel_axis = 2;
  e.time_offset_profile.best_s = 0.09;
  j = Judge(e, ConvergenceOptions());
  EXPECT_TRUE(j.converged) << j.reason;
  EXPECT_EQ(j.held_axes, (std::vector<std::string>{"z_m", "time_offset_s"}));
  // ... and the rules guard what is claimed as before.
  e.final_health = 0.5;
  EXPECT_EQ(FirstFailure(e), "health");
  EXPECT_TRUE(Judge(e, ConvergenceOptions()).held_axes.empty());

  // Not held, δ's profile peaking away refuses; a rotation axis is never held.
  e = Passing();
  e.time_offset_profile.best_s = 0.09;
  EXPECT_EQ(FirstFailure(e), "time_offset_profile");
  e = Passing();
  e.unobservable_axes = {"pitch_deg", "time_offset_s"};
  EXPECT_EQ(FirstFailure(e), "observable");

  // A whole claim holds nothing.
  EXPECT_TRUE(Judge(Passing(), ConvergenceOptions()).held_axes.empty());
}

// Hypotheses' per-frame fine scores, made by hand: `base` per frame for the best, the rivals
// below it by `gap` on every frame but the frames listed in `wins`, where they beat it by `gap`.
std::vector<double> Scores(int frames, double base, double gap, std::vector<int> wins = {}) {
  std::vector<double> scores;
  for (int f = 0; f < frames; ++f) {
    const bool win = std::find(wins.begin(), wins.end(), f) != wins.end();
    scores.push_back(base + (win ? gap : -gap) + 0.1 * (f % 3));
  }
  return scores;
}

CalibrationState Turned(double deg) {
  return Step(CalibrationState(), Eigen::Vector3d(0, 0, deg) * M_PI / 180.0,
              Eigen::Vector3d::Zero(), 0.0);
}

// One hypothesis dominates when it has been compared over enough frames and every rival not on
// its peak trails it by at least min_t standard errors of the per-frame gain (frames that share
// sweeps counted once); the best is the highest sum wherever it is listed.
TEST(Dominance, OneHypothesisDominatesWhenEveryRivalTrailsOnTheFramesSeen) {
  const DominanceOptions options;
  ASSERT_EQ(options.min_frames, 6);
  // Nine frames: the rival 3° away trails by 20 on every frame, the one 1° away is on the peak.
  const std::vector<CalibrationState> states = {Turned(3), Turned(0), Turned(1)};
  std::vector<std::vector<double>> scores = {Scores(9, 100, 20), Scores(9, 100, 0),
                                             Scores(9, 100, 5)};
  Dominance d = JudgeDominance(scores, states, 3, options);
  EXPECT_EQ(d.best, 1);
  EXPECT_EQ(d.frames, 9);
  EXPECT_TRUE(d.dominant) << d.detail;
  EXPECT_NEAR(d.rivals[0].rotation_deg, 3.0, 1e-9);
  EXPECT_FALSE(d.rivals[0].merged);
  EXPECT_GT(d.rivals[0].t_statistic, options.min_t);
  EXPECT_NEAR(d.rivals[0].score_share, 20.0 / 100.1, 1e-3);
  EXPECT_TRUE(d.rivals[2].merged);  // within merge_deg: the same peak, whatever its margin

  // Five frames are too few, however clear.
  scores = {Scores(5, 100, 20), Scores(5, 100, 0), Scores(5, 100, 5)};
  d = JudgeDominance(scores, states, 3, options);
  EXPECT_FALSE(d.dominant);
  EXPECT_EQ(d.detail, "5 frames seen, 6 needed");

  // The far rival beats the best on 4 of 9 frames: its deficit is within the noise.
  scores = {Scores(9, 100, 20, {0, 2, 4, 6}), Scores(9, 100, 0), Scores(9, 100, 5)};
  d = JudgeDominance(scores, states, 3, options);
  EXPECT_EQ(d.best, 1);
  EXPECT_FALSE(d.dominant);
  EXPECT_LT(d.rivals[0].t_statistic, options.min_t);
  EXPECT_NE(d.detail.find("1 rival(s)"), std::string::npos) << d.detail;
  EXPECT_NE(DescribeRivals(d).find("3.00 deg"), std::string::npos) << DescribeRivals(d);

  // The same gains with frames that each share sweeps with two others: a third of the evidence.
  scores = {Scores(9, 100, 20, {0}), Scores(9, 100, 0), Scores(9, 100, 5)};
  const double t_independent = JudgeDominance(scores, states, 1, options).rivals[0].t_statistic;
  const double t_shared = JudgeDominance(scores, states, 3, options).rivals[0].t_statistic;
  EXPECT_NEAR(t_shared, t_independent / std::sqrt(3.0), 1e-9);

  // No hypothesis: nothing dominates.
  EXPECT_FALSE(JudgeDominance({}, {}, 1, options).dominant);
}

// A run still acquiring at its end is refused by the dominance rule, naming its runners-up.
TEST(Judge, AStillAcquiringRunNamesItsRunnersUp) {
  ConvergenceEvidence e = Passing();
  e.acquiring = true;
  e.dominance = JudgeDominance({Scores(9, 100, 0), Scores(9, 100, 20, {0, 2, 4, 6})},
                               {Turned(0), Turned(4)}, 3);
  const Judgement j = Judge(e, ConvergenceOptions());
  EXPECT_FALSE(j.converged);
  EXPECT_NE(j.reason.find("still acquiring: no hypothesis dominates"), std::string::npos)
      << j.reason;
  EXPECT_NE(j.reason.find("4.00 deg"), std::string::npos) << j.reason;
  e.acquiring = false;
  EXPECT_TRUE(Judge(e, ConvergenceOptions()).converged);
}

// The jackknife's std: sqrt((n − 1) / n · Σ (θ_i − θ̄)²) per component.
TEST(Jackknife, StdOfLeaveOneOutEstimates) {
  EXPECT_EQ(JackknifeStd<3>({}), Eigen::Vector3d::Zero());
  EXPECT_EQ(JackknifeStd<3>({Eigen::Vector3d(1, 2, 3)}), Eigen::Vector3d::Zero());
  // Two estimates ±a about their mean: sqrt(1/2 · 2a²) = a.
  const Eigen::Vector3d s =
      JackknifeStd<3>({Eigen::Vector3d(0.1, 0, -1), Eigen::Vector3d(-0.1, 0, 1)});
  EXPECT_NEAR(s.x(), 0.1, 1e-12);
  EXPECT_NEAR(s.y(), 0.0, 1e-12);
  EXPECT_NEAR(s.z(), 1.0, 1e-12);
  // Four estimates 0, 0, 0, 4 (mean 1): sqrt(3/4 · (1 + 1 + 1 + 9)) = 3.
  const Eigen::Vector3d four = JackknifeStd<3>({Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                             Eigen::Vector3d::Zero(), Eigen::Vector3d(4, 0, 0)});
  EXPECT_NEAR(four.x(), 3.0, 1e-12);
}

PhaseInputs Inputs(int window_size, bool dominant, double health) {
  PhaseInputs in;
  in.window_size = window_size;
  in.window_frames = 3;
  in.dominant = dominant;
  in.health = health;
  in.lost_health = 0.9;
  return in;
}

TEST(Phase, FillingThenAcquiringUntilOneHypothesisDominates) {
  EXPECT_EQ(NextPhase(Phase::kFilling, Inputs(2, false, 1.0)), Phase::kFilling);
  EXPECT_EQ(NextPhase(Phase::kFilling, Inputs(3, false, 1.0)), Phase::kAcquiring);
  EXPECT_EQ(NextPhase(Phase::kAcquiring, Inputs(3, false, 1.0)), Phase::kAcquiring);
  EXPECT_EQ(NextPhase(Phase::kAcquiring, Inputs(3, true, 0.95)), Phase::kTracking);
  EXPECT_EQ(NextPhase(Phase::kAcquiring, Inputs(3, true, 0.5)), Phase::kLost);
}

TEST(Phase, TrackingAndLostFollowTheHealthAndNeverGoBack) {
  EXPECT_EQ(NextPhase(Phase::kTracking, Inputs(3, false, 0.89)), Phase::kLost);
  EXPECT_EQ(NextPhase(Phase::kLost, Inputs(3, false, 0.9)), Phase::kTracking);
  EXPECT_EQ(NextPhase(Phase::kLost, Inputs(3, false, 0.1)), Phase::kLost);
  // A shrunk window (never happens) does not send an acquired calibrator back to filling.
  EXPECT_EQ(NextPhase(Phase::kTracking, Inputs(1, false, 1.0)), Phase::kTracking);
  EXPECT_EQ(PhaseName(Phase::kLost), "lost");
  EXPECT_EQ(PhaseName(Phase::kFilling), "filling");
}

}  // namespace
}  // namespace stcalib
