// The verdict's rules (Judge, core/online/convergence.h) and the calibrator's phase transitions
// (NextPhase, core/online/online_calibrator.h), each from hand-made inputs.
#include <gtest/gtest.h>

#include <string>

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
  e.acquisition_frames = 20;
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
  RotationJackknife jackknife;
  jackknife.frames = 10;
  jackknife.blocks = 3;
  jackknife.std_deg = Eigen::Vector3d(0.08, 0.05, 0.02);
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
  EXPECT_EQ(FirstFailure(e), "acquired");

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
  e.rotation_jackknife->std_deg.x() = 0.19;  // under 0.2°: a claim
  EXPECT_EQ(FirstFailure(e), "");
  e.rotation_jackknife->std_deg.x() = 0.2;  // roll: leaving blocks out moves it 0.2°
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
  e.unobservable_axes = {"z_m"};
  const Judgement j = Judge(e, ConvergenceOptions());
  int failed = 0;
  for (const RuleOutcome& rule : j.rules) failed += !rule.passed;
  EXPECT_EQ(failed, 3);
  EXPECT_EQ(FirstFailure(e), "observable");
}

// A run still acquiring at its end claims only when its last rotation grid agreed with the
// estimate over every frame it used, and over at least 8: a ten-frame drive can claim, three
// frames cannot, and a grid that agreed on fewer frames than the run had does not count.
TEST(Judge, AShortRunClaimsWhenItsGridAgreedOnAllItsFrames) {
  ConvergenceEvidence e = Passing();
  e.acquiring = true;
  e.used_frames = 10;
  e.grid_agreement_frames = 10;
  EXPECT_EQ(FirstFailure(e), "");
  e.grid_agreement_frames = 0;  // the last grid did not agree
  EXPECT_EQ(FirstFailure(e), "acquired");
  e.used_frames = 30;  // 30 frames: a full window of 20 is needed
  e.grid_agreement_frames = 19;
  EXPECT_EQ(FirstFailure(e), "acquired");
  e.grid_agreement_frames = 20;
  EXPECT_EQ(FirstFailure(e), "");
  e.used_frames = 5;  // too few frames however the grid agreed
  e.grid_agreement_frames = 5;
  EXPECT_EQ(FirstFailure(e), "acquired");
}

// The jackknife's std: sqrt((n − 1) / n · Σ (θ_i − θ̄)²) per component.
TEST(Jackknife, StdOfLeaveOneOutEstimates) {
  EXPECT_EQ(JackknifeStd({}), Eigen::Vector3d::Zero());
  EXPECT_EQ(JackknifeStd({Eigen::Vector3d(1, 2, 3)}), Eigen::Vector3d::Zero());
  // Two estimates ±a about their mean: sqrt(1/2 · 2a²) = a.
  const Eigen::Vector3d s =
      JackknifeStd({Eigen::Vector3d(0.1, 0, -1), Eigen::Vector3d(-0.1, 0, 1)});
  EXPECT_NEAR(s.x(), 0.1, 1e-12);
  EXPECT_NEAR(s.y(), 0.0, 1e-12);
  EXPECT_NEAR(s.z(), 1.0, 1e-12);
  // Four estimates 0, 0, 0, 4 (mean 1): sqrt(3/4 · (1 + 1 + 1 + 9)) = 3.
  const Eigen::Vector3d four = JackknifeStd({Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                             Eigen::Vector3d::Zero(), Eigen::Vector3d(4, 0, 0)});
  EXPECT_NEAR(four.x(), 3.0, 1e-12);
}

PhaseInputs Inputs(int window_size, bool grid_agreed, double health, bool acquisition = true) {
  PhaseInputs in;
  in.window_size = window_size;
  in.window_frames = 3;
  in.acquisition = acquisition;
  in.grid_agreed = grid_agreed;
  in.health = health;
  in.lost_health = 0.9;
  return in;
}

TEST(Phase, FillingThenAcquiringUntilTheGridAgrees) {
  EXPECT_EQ(NextPhase(Phase::kFilling, Inputs(2, false, 1.0)), Phase::kFilling);
  EXPECT_EQ(NextPhase(Phase::kFilling, Inputs(3, false, 1.0)), Phase::kAcquiring);
  EXPECT_EQ(NextPhase(Phase::kAcquiring, Inputs(3, false, 1.0)), Phase::kAcquiring);
  EXPECT_EQ(NextPhase(Phase::kAcquiring, Inputs(3, true, 0.95)), Phase::kTracking);
  EXPECT_EQ(NextPhase(Phase::kAcquiring, Inputs(3, true, 0.5)), Phase::kLost);
}

TEST(Phase, WithoutAnAcquisitionFillingGoesStraightToTheHealthsPhase) {
  EXPECT_EQ(NextPhase(Phase::kFilling, Inputs(2, false, 1.0, false)), Phase::kFilling);
  EXPECT_EQ(NextPhase(Phase::kFilling, Inputs(3, false, 1.0, false)), Phase::kTracking);
  EXPECT_EQ(NextPhase(Phase::kFilling, Inputs(3, false, 0.2, false)), Phase::kLost);
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
