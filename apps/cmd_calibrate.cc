// stcalib calibrate: online calibration of a drive (docs/method.md §9).
#include <glog/logging.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "apps/calibrate_job.h"
#include "apps/commands.h"
#include "apps/flags.h"
#include "apps/plot.h"
#include "apps/report.h"
#include "core/io/image.h"
#include "core/io/kitti_calib.h"
#include "core/io/text.h"
#include "core/online/convergence.h"
#include "core/online/frame_prefetcher.h"
#include "core/search/adaptive_grid_search.h"

namespace stcalib::cli {
namespace {

namespace fs = std::filesystem;

nlohmann::json MatrixJson(const Rigid3d& T) {
  nlohmann::json values = nlohmann::json::array();
  for (int k = 0; k < 16; ++k) values.push_back(T.matrix()(k / 4, k % 4));
  return values;
}

nlohmann::json ErrorJson(const CalibrationError& e) {
  return {{"rotation_deg", e.rotation_deg},
          {"roll_deg", e.roll_deg},
          {"pitch_deg", e.pitch_deg},
          {"yaw_deg", e.yaw_deg},
          {"translation_m", e.translation_norm_m},
          {"x_m", e.translation_m.x()},
          {"y_m", e.translation_m.y()},
          {"z_m", e.translation_m.z()},
          {"time_offset_s", e.time_offset_s}};
}

std::string Csv(const std::string& s) { return "\"" + s + "\""; }

// What the final refinement (OnlineCalibrator::Polish) did.
nlohmann::json PolishJson(const FrameReport& polish) {
  const Eigen::Vector3d dt =
      polish.after.T_camera_lidar.translation() - polish.before.T_camera_lidar.translation();
  return {{"applied", polish.accepted},
          {"reason", polish.reason},
          {"rotation_change_deg", RotationErrorDeg(polish.before.T_camera_lidar.linear(),
                                                   polish.after.T_camera_lidar.linear())},
          {"translation_change_m", dt.norm()},
          {"time_offset_change_s", polish.after.time_offset_s - polish.before.time_offset_s}};
}

}  // namespace

namespace {

// "image_02,image_03" → its names (empty entries dropped).
std::vector<std::string> SplitCameras(const std::string& list) {
  std::vector<std::string> names;
  std::string name;
  for (char c : list + ",") {
    if (c != ',') {
      name += c;
    } else if (!name.empty()) {
      names.push_back(name);
      name.clear();
    }
  }
  return names;
}

}  // namespace

CalibrateJob CalibrateJobFromFlags() {
  CalibrateJob job;
  job.drive_dir = FLAGS_drive;
  job.calib_dir = FLAGS_calib_dir;
  job.init_calib = FLAGS_init_calib;
  job.cameras = SplitCameras(FLAGS_cameras);
  job.rig_joint = FLAGS_rig_joint;
  job.bag = BagOptionsFromFlags();
  job.out_dir = FLAGS_out;
  job.perturb_rot_deg = FLAGS_perturb_rot_deg;
  job.perturb_trans_m = FLAGS_perturb_trans_m;
  job.perturb_time_s = FLAGS_perturb_time_s;
  job.seed = FLAGS_seed;
  job.first_frame = FLAGS_first_frame;
  job.num_frames = FLAGS_num_frames;
  job.disturb_frame = FLAGS_disturb_frame;
  job.disturb_rot_deg = FLAGS_disturb_rot_deg;
  job.polish = FLAGS_polish;
  OnlineCalibratorOptions& o = job.online;
  o.window_frames = FLAGS_window_frames;
  o.time_offset_bound_s = FLAGS_time_offset_bound_s;
  o.point_margin = FLAGS_point_margin;
  ParseFolds(FLAGS_lidar_folds, &o.folds);
  o.horizontal_weight = FLAGS_horizontal_weight;
  o.search.search_time_offset = FLAGS_estimate_time_offset;
  o.search.translation_prior_sigma_m = FLAGS_prior_sigma_translation_m;
  o.search.time_offset_prior_sigma_s = FLAGS_prior_sigma_time_s;
  o.refine.estimate_time_offset = FLAGS_estimate_time_offset;
  ParseLoss(FLAGS_loss, &o.refine.loss);  // CalibrateFlagsError checked both names
  o.refine.prior_sigma_translation_m = FLAGS_prior_sigma_translation_m;
  o.refine.prior_sigma_time_s = FLAGS_prior_sigma_time_s;
  o.refine_frames = FLAGS_refine_frames;
  o.tracking_gain = FLAGS_tracking_gain;
  o.tracking_max_lag_deg = FLAGS_tracking_max_lag_deg;
  o.refined_score_tolerance = FLAGS_refined_score_tolerance;
  o.tracking_update_every = FLAGS_tracking_update_every;
  o.refine.observable_rotation_deg = FLAGS_observable_rotation_deg;
  job.source.local_map.sweeps = FLAGS_local_map_sweeps;
  job.source.local_map.use_ndt = FLAGS_use_ndt;
  job.source.lidar.remove_dynamic = FLAGS_remove_dynamic;
  job.source.suppress_texture = FLAGS_suppress_texture;
  job.source.bandpass_score = FLAGS_bandpass_score;
  // CalibrateFlagsError has checked the detector's name.
  CHECK(ImageOptionsFromFlags(&job.source.image).ok()) << FLAGS_detector;
  job.convergence.health_check.min_health = FLAGS_min_health;
  job.convergence.min_final_health = o.lost_health;  // lost is never converged
  // CalibrateFlagsError has checked the figures.
  CHECK(ParseStartUncertainty(FLAGS_init_uncertainty, &o.start_uncertainty).ok())
      << FLAGS_init_uncertainty;
  o = WithStartUncertainty(o, job.perturb_time_s);
  return job;
}

bool TimeOffsetHeld(const CalibrateOutcome& outcome) {
  return std::count(outcome.held_axes.begin(), outcome.held_axes.end(),
                    std::string(kAxisNames[kNumAxes - 1])) > 0;
}

std::string TimeOffsetRestsOn(const CalibrateOutcome& outcome) {
  if (!outcome.time_offset_estimated || TimeOffsetHeld(outcome)) return "start";
  return outcome.time_forward.separated ? "window" : "forward_translation_prior";
}

std::string TimeOffsetPriorNote(const CalibrateOutcome& outcome) {
  const TimeForwardPair& pair = outcome.time_forward;
  if (TimeOffsetHeld(outcome) && pair.measured) {
    char numbers[160];
    std::snprintf(numbers, sizeof(numbers),
                  " (with the forward translation free: std %.1f ms and %.1f cm, correlation "
                  "%+.2f)",
                  1000 * pair.time_offset_std_s, 100 * pair.forward_std_m, pair.correlation);
    return "time offset: held at its start, with the translation along travel: this drive does "
           "not separate the two" +
           std::string(numbers) + "\n";
  }
  if (TimeOffsetRestsOn(outcome) != "forward_translation_prior") return "";
  const std::string consequence =
      "so it rests on that translation's prior, as does the translation along travel (time "
      "offset error = forward error / speed)";
  if (!pair.measured) {
    return "time offset: estimated with the forward translation held (the polish, which frees "
           "both, did not measure them), " +
           consequence + "\n";
  }
  char numbers[128];
  std::snprintf(numbers, sizeof(numbers),
                "; with both free: std %.1f ms and %.1f cm, correlation %+.2f",
                1000 * pair.time_offset_std_s, 100 * pair.forward_std_m, pair.correlation);
  return "time offset: not separated from the forward translation in this drive, " + consequence +
         numbers + "\n";
}

namespace {

// One camera's run: its drive, start, calibrator and what its frames did.
struct CameraRun {
  Drive drive;
  // The start's signs, then the disturbance's: the seed's own for every camera, so that each
  // starts (and is disturbed) as far from its reference as a single-camera run would.
  std::mt19937_64 rng;
  std::unique_ptr<OnlineCalibrator> calibrator;
  std::shared_ptr<const CalibrationFrame> last_frame;
  double frame_ms_sum = 0;
  int frames_used = 0;
  std::string out_dir;  ///< empty: nothing is written
};

// The camera's reference (simulated truth, else the drive's calibration) and start.
Status StartCamera(const CalibrateJob& job, CameraRun* run, CalibrateOutcome* outcome) {
  const Drive& drive = run->drive;
  outcome->camera = drive.camera_name;
  STCALIB_RETURN_IF_ERROR(ReadGroundTruth(drive, &outcome->has_truth, &outcome->reference_state));
  outcome->T_rectified_camera = RectifiedFromCamera(drive.camera);
  outcome->T_camera_reference = drive.camera.T_camera_reference;
  if (outcome->has_truth) {
    outcome->reference = "ground truth (simulated)";
  } else {
    outcome->reference_state.T_camera_lidar = drive.T_camera_lidar;
    outcome->reference = drive.store
                             ? "drive calibration (" + drive.drive_dir + ": /tf_static)"
                             : "drive calibration (" + drive.calib_dir + "/calib_velo_to_cam.txt)";
  }
  CalibrationState initial;
  STCALIB_RETURN_IF_ERROR(StartingCalibration(drive, job.init_calib, job.perturb_rot_deg,
                                              job.perturb_trans_m, &run->rng,
                                              &initial.T_camera_lidar));
  initial.time_offset_s = job.perturb_time_s;
  outcome->initial = initial;
  outcome->initial_error = ComputeCalibrationError(initial, outcome->reference_state);
  return Status::Ok();
}

// The camera's verdict and polish, and its outputs in run.out_dir; the camera's exit code.
int FinishCamera(const CalibrateJob& job, int first, int last,
                 std::chrono::steady_clock::time_point run_start, CameraRun* run,
                 CalibrateOutcome* outcome) {
  const char* kCommand = "calibrate";
  const Drive& drive = run->drive;
  OnlineCalibrator& calibrator = *run->calibrator;
  const CalibrationState& initial = outcome->initial;
  const int frames_used = run->frames_used;
  const std::shared_ptr<const CalibrationFrame>& last_frame = run->last_frame;
  outcome->mean_frame_ms = run->frame_ms_sum / std::max(1, frames_used);
  std::error_code ec;
  Status status = Status::Ok();
  // The verdict, and the polish of a converged estimate (core/online/convergence.h): the app
  // only formats them.
  const ConvergenceVerdict verdict =
      JudgeAndPolish(&calibrator, outcome->reports, initial, job.online, job.convergence,
                     job.polish ? &outcome->polish : nullptr);
  if (!job.polish) outcome->polish.reason = "polish: off (--nopolish)";
  VLOG(1) << outcome->polish.reason;
  outcome->estimate = verdict.estimate;
  outcome->error = ComputeCalibrationError(outcome->estimate, outcome->reference_state);
  outcome->converged = verdict.converged;
  outcome->held_axes = verdict.held_axes;
  outcome->reason = verdict.reason;
  outcome->alias_suspect = verdict.time_offset_profile.alias_suspect;
  outcome->time_offset_estimated = job.online.refine.estimate_time_offset;
  outcome->time_forward = verdict.time_forward;
  const ReportedUncertainty reported = ReportUncertainty(
      verdict, outcome->time_offset_estimated, job.online.refine.observable_translation_m);
  outcome->observable = reported.observable;
  outcome->has_std = reported.has_std;
  outcome->std_dev = reported.std_dev;
  auto verdict_code = [&]() {
    if (outcome->converged) return outcome->held_axes.empty() ? kExitOk : kExitPartial;
    std::fprintf(stderr, "stcalib calibrate: %s%s\n", CameraPrefix(job, *outcome).c_str(),
                 outcome->reason.c_str());
    return kExitFailure;
  };
  // docs/method.md §9: --out is optional; without it nothing is written (the caller prints the
  // estimate) and none of the files' contents are made.
  if (run->out_dir.empty()) return verdict_code();
  const TimeOffsetProfile& profile = verdict.time_offset_profile;
  nlohmann::json profiles_json;
  for (int axis = 0; axis < 3; ++axis) {
    const RotationAxisProfile& p = verdict.rotation_profiles[axis];
    profiles_json[kAxisNames[axis]] = {{"best_offset_deg", p.best_deg},
                                       {"second_peak_offset_deg", p.second_peak_deg},
                                       {"second_peak_ratio", p.second_peak_ratio}};
  }
  nlohmann::json health_check_json = nullptr;
  if (verdict.health_checked) {
    const HealthCheckResult& h = verdict.health_check;
    health_check_json = {{"decided", h.decided},
                         {"holds", h.holds},
                         {"mean_health", h.mean_health},
                         {"mean_neighbour_gain", h.mean_neighbour_gain},
                         {"reason", h.reason}};
  }
  const FrameReport empty_report;
  const FrameReport* final_report_ptr = &empty_report;
  for (const FrameReport& r : outcome->reports) {
    if (!r.skipped) final_report_ptr = &r;
  }
  // The score, gray rate and health at the final estimate: the polish's when it was taken.
  const FrameReport& final_report = outcome->polish.accepted ? outcome->polish : *final_report_ptr;
  const int skipped = verdict.skipped_frames;
  const std::vector<std::string>& unobservable = verdict.unobservable_axes;
  // The covariance is the refinement the verdict read, except along the direction of travel
  // (ReportUncertainty): there δ and the forward translation are reported from the polish's solve
  // with both free.
  const RefineResult& refine = verdict.refine;
  const TimeForwardPair& pair = verdict.time_forward;

  // Outputs.
  const std::string out = run->out_dir;
  auto fail = [&](const Status& s) { return ReportError(kCommand, s); };
  if (outcome->converged) {
    // A partial claim marks what it held in both files (the values there are the start's).
    std::string held, time_held;
    for (const std::string& axis : outcome->held_axes) {
      if (axis == kAxisNames[kNumAxes - 1]) {
        time_held = "held at the start: not observable in this drive";
      } else {
        held += (held.empty() ? "" : ", ") + axis;
      }
    }
    if (!held.empty()) held = "held at the start (not observable in this drive): " + held;
    // The file's frame is calib_velo_to_cam's own (KITTI's camera 0 for every KITTI camera).
    status = WriteVeloToCam(out + "/calib_velo_to_cam.txt", EstimateInFileFrame(*outcome), held);
    if (!status.ok()) return fail(status);
    status = WriteTimeOffset(out + "/" + kTimeOffsetFileName, outcome->estimate.time_offset_s,
                             time_held);
    if (!status.ok()) return fail(status);
  } else {
    // Never leave a file that claims success.
    fs::remove(out + "/calib_velo_to_cam.txt", ec);
    fs::remove(out + "/" + kTimeOffsetFileName, ec);
  }
  nlohmann::json std_json, observable_json;
  for (int k = 0; k < kNumAxes; ++k) {
    std_json[kAxisNames[k]] =
        reported.has_std[k] ? nlohmann::json(reported.std_dev[k]) : nlohmann::json(nullptr);
    observable_json[kAxisNames[k]] = reported.observable[k];
  }
  constexpr int kTime = kNumAxes - 1;
  const bool time_estimated = outcome->time_offset_estimated;
  auto measured_or_null = [&](double value) {
    return pair.measured ? nlohmann::json(value) : nlohmann::json(nullptr);
  };
  const nlohmann::json time_forward_json = {
      {"rests_on", TimeOffsetRestsOn(*outcome)},
      {"measured", pair.measured},
      {"time_offset_std_s", measured_or_null(pair.time_offset_std_s)},
      {"forward_std_m", measured_or_null(pair.forward_std_m)},
      {"correlation", measured_or_null(pair.correlation)},
      {"time_offset_std_given_forward_prior_s", refine.covariance_ok && time_estimated
                                                    ? nlohmann::json(refine.std_dev[kTime])
                                                    : nlohmann::json(nullptr)}};
  const Eigen::Vector3d rpy_deg = MountRollPitchYawDeg(outcome->estimate.T_camera_lidar.linear());
  const Eigen::Vector3d start_rpy_deg =
      MountRollPitchYawDeg(outcome->initial.T_camera_lidar.linear());
  const Eigen::Vector3d start_t = outcome->initial.T_camera_lidar.translation();
  nlohmann::json rules_json = nlohmann::json::array();
  for (const RuleOutcome& rule : verdict.rules) {
    rules_json.push_back({{"name", rule.name}, {"passed", rule.passed}, {"detail", rule.detail}});
  }
  // Per frame, over all frames (those without an update count as 0 ms), and per update.
  double search_ms = 0, refine_ms = 0, update_ms = 0;
  int updates = 0;
  for (const FrameReport& r : outcome->reports) {
    search_ms += r.search_ms / outcome->reports.size();
    refine_ms += r.refine_ms / outcome->reports.size();
    if (r.ran_update()) {
      update_ms += r.search_ms + r.refine_ms;
      ++updates;
    }
  }
  if (updates > 0) update_ms /= updates;
  // The acquisition's hypotheses as last compared (best first), with each runner-up's margins.
  nlohmann::json hypotheses_json = nlohmann::json::array();
  {
    const Acquisition& acquisition = calibrator.acquisition();
    const Dominance& dominance = acquisition.dominance();
    for (size_t k = 0; k < acquisition.hypotheses().size(); ++k) {
      const Hypothesis& h = acquisition.hypotheses()[k];
      const Eigen::Vector3d h_rpy = MountRollPitchYawDeg(h.state.T_camera_lidar.linear());
      const Eigen::Vector3d t = h.state.T_camera_lidar.translation();
      nlohmann::json entry = {
          {"best", static_cast<int>(k) == dominance.best},
          {"incumbent", h.incumbent},
          {"rpy_deg", {{"roll", h_rpy.x()}, {"pitch", h_rpy.y()}, {"yaw", h_rpy.z()}}},
          {"translation_m", {{"x", t.x()}, {"y", t.y()}, {"z", t.z()}}},
          {"time_offset_s", h.state.time_offset_s}};
      if (!h.incumbent) entry["lattice_score"] = h.lattice_score;
      if (static_cast<int>(k) != dominance.best && k < dominance.rivals.size()) {
        const RivalMargin& r = dominance.rivals[k];
        entry["rotation_from_best_deg"] = r.rotation_deg;
        entry["score_share_below_best"] = r.score_share;
        entry["standard_errors_below_best"] =
            std::isfinite(r.t_statistic) ? nlohmann::json(r.t_statistic) : nlohmann::json(nullptr);
        entry["same_peak_as_best"] = r.merged;
      }
      hypotheses_json.push_back(entry);
    }
  }
  nlohmann::json result = {
      {"T_camera_lidar", MatrixJson(outcome->estimate.T_camera_lidar)},
      {"time_offset_s", outcome->estimate.time_offset_s},
      {"rpy_deg", {{"roll", rpy_deg.x()}, {"pitch", rpy_deg.y()}, {"yaw", rpy_deg.z()}}},
      {"std", std_json},
      {"translation_refinement_spread",
       {{"x_m", verdict.refinement_spread_m.x()},
        {"y_m", verdict.refinement_spread_m.y()},
        {"z_m", verdict.refinement_spread_m.z()},
        {"updates", verdict.refinement_spread_updates}}},
      {"observable", observable_json},
      {"unobservable_axes", unobservable},
      {"rotation_profiles", profiles_json},
      {"suppressed_health_check", health_check_json},
      {"converged", outcome->converged},
      {"claim", !outcome->converged          ? "none"
                : outcome->held_axes.empty() ? "whole"
                                             : "partial"},
      {"held_axes", outcome->held_axes},
      {"reason", outcome->reason},
      {"phase", PhaseName(calibrator.phase())},
      {"hypotheses", hypotheses_json},
      {"dominance",
       {{"frames", calibrator.acquisition().dominance().frames},
        {"dominant", calibrator.acquisition().dominance().dominant},
        {"detail", calibrator.acquisition().dominance().detail}}},
      {"verdict_rules", rules_json},
      {"alias_suspect", outcome->alias_suspect},
      {"time_offset_peak_s", profile.best_s},
      {"alias_second_peak_s", profile.second_peak_s},
      {"alias_second_peak_ratio", profile.second_peak_ratio},
      {"time_forward_correlation",
       pair.measured ? pair.correlation : refine.time_forward_correlation},
      {"time_offset_vs_forward", time_forward_json},
      {"score", final_report.score_after.score},
      {"gray_rate", final_report.gray_rate_after},
      {"health", final_report.health},
      {"frames", {{"first", first}, {"last", last}, {"used", frames_used}, {"skipped", skipped}}},
      {"timing_ms",
       {{"per_frame_mean", outcome->mean_frame_ms},
        {"search_mean", search_ms},
        {"refine_mean", refine_ms},
        {"updates", updates},
        {"update_mean", update_ms},
        {"total",
         std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - run_start)
             .count()}}},
      {"polish", PolishJson(outcome->polish)},
      {"reference", outcome->reference},
      {"motion", outcome->motion},
      {"initial_error", ErrorJson(outcome->initial_error)},
      {"start",
       {{"rpy_deg",
         {{"roll", start_rpy_deg.x()}, {"pitch", start_rpy_deg.y()}, {"yaw", start_rpy_deg.z()}}},
        {"translation_m", {{"x", start_t.x()}, {"y", start_t.y()}, {"z", start_t.z()}}},
        {"time_offset_s", outcome->initial.time_offset_s}}},
      {"stcalib_version", StcalibVersion()},
      {"command", CommandLineText()},
      {"input", job.bag.bag_dir.empty() ? job.drive_dir : job.bag.bag_dir},
      {"camera", outcome->camera},
  };
  if (outcome->has_truth) {
    result["error"] = ErrorJson(outcome->error);
  } else {
    result["agreement_with_drive_calibration"] = ErrorJson(outcome->error);
  }
  status = WriteTextFile(out + "/result.json", result.dump(2) + "\n");
  if (!status.ok()) return fail(status);

  std::string csv =
      "frame,accepted,from_hypotheses,points,gray_rate,health,roll_deg,pitch_deg,yaw_deg,x_m,y_m,z_"
      "m,"
      "time_offset_s,rotation_error_deg,translation_error_m,time_offset_error_s,search_ms,refine_"
      "ms,phase,reason,roll_std_deg,pitch_std_deg,yaw_std_deg,x_std_m,y_std_m,z_std_m,time_offset_"
      "std_s\n";
  std::vector<double> xs, rot_err, trans_err_cm, dt_ms, roll_e, pitch_e, yaw_e;
  for (const FrameReport& r : outcome->reports) {
    const CalibrationError e = ComputeCalibrationError(r.after, outcome->reference_state);
    const Eigen::Vector3d rpy = MountRollPitchYawDeg(r.after.T_camera_lidar.linear());
    char row[512];
    std::snprintf(
        row, sizeof(row),
        "%d,%d,%d,%d,%.4f,%.4f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.6f,%.5f,%.5f,%.6f,%.2f,%.2f,",
        r.frame, r.accepted, r.from_hypotheses, r.points, r.gray_rate_after, r.health, rpy.x(),
        rpy.y(), rpy.z(), r.after.T_camera_lidar.translation().x(),
        r.after.T_camera_lidar.translation().y(), r.after.T_camera_lidar.translation().z(),
        r.after.time_offset_s, e.rotation_deg, e.translation_norm_m, e.time_offset_s, r.search_ms,
        r.refine_ms);
    csv += row + PhaseName(r.phase) + "," + Csv(r.reason);
    // The frame's refinement std per axis (empty without one): the report's bands.
    const bool has_std = r.ran_update() && r.refine.usable && r.refine.covariance_ok;
    for (int k = 0; k < kNumAxes; ++k) {
      char value[32] = "";
      if (has_std) {
        std::snprintf(value, sizeof(value), "%.6g", r.refine.std_dev[k]);  // deg, m, s
      }
      csv += std::string(",") + value;
    }
    csv += "\n";
    xs.push_back(r.frame);
    rot_err.push_back(e.rotation_deg);
    roll_e.push_back(e.roll_deg);
    pitch_e.push_back(e.pitch_deg);
    yaw_e.push_back(e.yaw_deg);
    trans_err_cm.push_back(100 * e.translation_norm_m);
    dt_ms.push_back(1000 * r.after.time_offset_s);
  }
  status = WriteTextFile(out + "/per_frame.csv", csv);
  if (!status.ok()) return fail(status);
  // The polish, drawn as one more step after the last frame.
  const bool polished = outcome->polish.accepted && !xs.empty();
  if (polished) {
    const CalibrationError e = outcome->error;
    xs.push_back(xs.back() + 1);
    rot_err.push_back(e.rotation_deg);
    roll_e.push_back(e.roll_deg);
    pitch_e.push_back(e.pitch_deg);
    yaw_e.push_back(e.yaw_deg);
    trans_err_cm.push_back(100 * e.translation_norm_m);
    dt_ms.push_back(1000 * outcome->estimate.time_offset_s);
  }

  const std::string vs =
      outcome->has_truth ? "error vs ground truth" : "difference from the drive calibration";
  std::vector<Series> dt_series = {{"delta", dt_ms, cv::Scalar(0, 120, 200)}};
  if (outcome->has_truth) {  // the true δ as a flat grey line
    dt_series.push_back(
        {"truth", std::vector<double>(xs.size(), 1000 * outcome->reference_state.time_offset_s),
         cv::Scalar(140, 140, 140)});
  }
  // An axis the verdict did not observe is marked "held" in the legend: its line is the start's
  // value, not an estimate.
  auto label = [&](const char* name, int axis) {
    return std::string(name) + (outcome->observable[axis] ? "" : " (held)");
  };
  std::string held_translation;
  for (int k = 3; k < 6; ++k) {
    if (!outcome->observable[k]) {
      held_translation +=
          (held_translation.empty() ? "; held: " : ", ") + std::string(kAxisNames[k]).substr(0, 1);
    }
  }
  // δ unobserved is not held at its start: it rests on the forward translation's prior.
  if (!outcome->observable[6]) dt_series.front().name = "delta (on the prior)";
  std::vector<cv::Mat> panels = {
      PlotPanel("rotation " + vs + " [deg]", xs,
                {{"total", rot_err, cv::Scalar(0, 0, 0)},
                 {label("roll", 0), roll_e, cv::Scalar(0, 0, 220)},
                 {label("pitch", 1), pitch_e, cv::Scalar(0, 160, 0)},
                 {label("yaw", 2), yaw_e, cv::Scalar(220, 0, 0)}}),
      PlotPanel("translation " + vs + " [cm]" + held_translation, xs,
                {{"|t|", trans_err_cm, cv::Scalar(120, 0, 120)}}),
      PlotPanel("time offset estimate [ms]" +
                    std::string(polished ? "; each panel's last step: the polish" : ""),
                xs, dt_series)};
  cv::Mat convergence;
  cv::vconcat(panels, convergence);
  std::vector<std::pair<std::string, cv::Mat>> pictures = {{"convergence.png", convergence}};
  if (last_frame) {  // overlays on the last frame that was used
    cv::Mat image;
    status = drive.LoadImage(last_frame->index, &image);
    if (!status.ok()) return fail(status);
    pictures.emplace_back(
        "overlay_before.png",
        DrawEdgeOverlay(image, *last_frame, outcome->initial, "before: initial calibration"));
    pictures.emplace_back(
        "overlay_after.png",
        DrawEdgeOverlay(image, *last_frame, outcome->estimate, "after: estimate"));
  }
  for (const auto& [name, picture] : pictures) {
    status = WriteImage(out + "/" + name, picture);
    if (!status.ok()) return fail(status);
    outcome->pictures.push_back(out + "/" + name);
  }
  // The report's strip: frames of the refinement's window at the start and at the estimate.
  status = WriteFrameStrip(drive, calibrator.RecentFrames(),
                           {{"start_", outcome->initial, "at the start"},
                            {"estimate_", outcome->estimate, "at the estimate"}},
                           out, &outcome->pictures);
  if (!status.ok()) return fail(status);
  status = WriteRunReport(out);
  if (!status.ok()) return fail(status);
  return verdict_code();
}

// The rig's joint refinement (job.rig_joint) over the claimed cameras' latest frames, from the
// first claimed camera's estimate; each camera's δ difference to it is held at the two estimates'.
void RefineRig(const std::vector<CameraRun>& runs, std::vector<CalibrateOutcome>* outcomes) {
  int anchor = -1;
  std::vector<RigCameraFrames> cameras;
  for (size_t k = 0; k < runs.size(); ++k) {
    const CalibrateOutcome& outcome = (*outcomes)[k];
    if (!outcome.converged) continue;
    if (anchor < 0) anchor = static_cast<int>(k);
    RigCameraFrames camera;
    camera.frames = runs[k].calibrator->RecentFrames();
    camera.T_camera_reference = outcome.T_camera_reference;
    camera.time_offset_shift_s =
        outcome.estimate.time_offset_s - (*outcomes)[anchor].estimate.time_offset_s;
    cameras.push_back(camera);
  }
  if (anchor < 0) return;
  const CalibrateOutcome& first = (*outcomes)[anchor];
  CalibrationState start;
  start.T_camera_lidar = EstimateInFileFrame(first);
  start.time_offset_s = first.estimate.time_offset_s;
  const RefineResult joint =
      RefineRigJointly(cameras, start, runs[anchor].calibrator->RefineOptionsInUse());
  if (!joint.usable) {
    LOG(WARNING) << "the rig's joint refinement failed: " << joint.message;
    return;
  }
  size_t part = 0;
  for (size_t k = 0; k < runs.size(); ++k) {
    CalibrateOutcome& outcome = (*outcomes)[k];
    if (!outcome.converged) continue;
    outcome.joint = true;
    outcome.joint_estimate.T_camera_lidar = outcome.T_camera_reference * joint.state.T_camera_lidar;
    outcome.joint_estimate.time_offset_s =
        joint.state.time_offset_s + cameras[part++].time_offset_shift_s;
    outcome.joint_error = ComputeCalibrationError(outcome.joint_estimate, outcome.reference_state);
  }
}

}  // namespace

RigCamera ToRigCamera(const CalibrateOutcome& outcome) {
  RigCamera camera;
  camera.name = outcome.camera;
  camera.claimed = outcome.converged;
  camera.T_camera_lidar = outcome.estimate.T_camera_lidar;
  camera.T_rectified_camera = outcome.T_rectified_camera;
  camera.T_camera_reference = outcome.T_camera_reference;
  camera.std_dev = outcome.std_dev;
  camera.has_std = outcome.has_std;
  return camera;
}

std::vector<CameraPairCheck> CompareRigPairs(const std::vector<CalibrateOutcome>& outcomes) {
  std::vector<CameraPairCheck> pairs;
  for (size_t a = 0; a < outcomes.size(); ++a) {
    for (size_t b = a + 1; b < outcomes.size(); ++b) {
      pairs.push_back(CompareCameraPair(ToRigCamera(outcomes[a]), ToRigCamera(outcomes[b])));
    }
  }
  return pairs;
}

Rigid3d EstimateInFileFrame(const CalibrateOutcome& outcome) {
  return outcome.T_camera_reference.inverse() * outcome.estimate.T_camera_lidar;
}

Status WriteRigSummary(const CalibrateJob& job, const std::vector<CalibrateOutcome>& outcomes,
                       const std::vector<CameraPairCheck>& pair_checks) {
  nlohmann::json cameras = nlohmann::json::array();
  for (const CalibrateOutcome& outcome : outcomes) {
    const Eigen::Vector3d rpy_deg = MountRollPitchYawDeg(outcome.estimate.T_camera_lidar.linear());
    nlohmann::json std_json;
    for (int k = 0; k < kNumAxes; ++k) {
      std_json[kAxisNames[k]] =
          outcome.has_std[k] ? nlohmann::json(outcome.std_dev[k]) : nlohmann::json(nullptr);
    }
    cameras.push_back(
        {{"camera", outcome.camera},
         {"folder", outcome.camera},
         {"converged", outcome.converged},
         {"claim", !outcome.converged          ? "none"
                   : outcome.held_axes.empty() ? "whole"
                                               : "partial"},
         {"held_axes", outcome.held_axes},
         {"reason", outcome.reason},
         {"T_camera_lidar", MatrixJson(outcome.estimate.T_camera_lidar)},
         {"time_offset_s", outcome.estimate.time_offset_s},
         {"rpy_deg", {{"roll", rpy_deg.x()}, {"pitch", rpy_deg.y()}, {"yaw", rpy_deg.z()}}},
         {"std", std_json},
         {"reference", outcome.reference},
         {outcome.has_truth ? "error" : "agreement_with_drive_calibration",
          ErrorJson(outcome.error)}});
    if (outcome.joint) {  // beside the camera's own estimate: the rig's joint one
      cameras.back()["joint"] = {
          {"T_camera_lidar", MatrixJson(outcome.joint_estimate.T_camera_lidar)},
          {"time_offset_s", outcome.joint_estimate.time_offset_s},
          {outcome.has_truth ? "error" : "agreement_with_drive_calibration",
           ErrorJson(outcome.joint_error)}};
    }
  }
  nlohmann::json pairs = nlohmann::json::array();
  bool rig_consistent = true;
  for (const CameraPairCheck& pair : pair_checks) {
    nlohmann::json entry = {{"from", pair.from},
                            {"to", pair.to},
                            {"compared", pair.compared},
                            {"T_to_from_rig", MatrixJson(pair.T_to_from_rig)},
                            {"baseline_rig_m", pair.T_to_from_rig.translation().norm()}};
    rig_consistent = rig_consistent && pair.consistent;
    if (pair.compared) {
      entry["T_to_from_estimated"] = MatrixJson(pair.T_to_from_estimated);
      entry["rotation_disagreement_deg"] = pair.rotation_deg;
      entry["translation_disagreement_m"] = pair.translation_m;
      entry["baseline_error_m"] = pair.baseline_m;
      entry["rotation_disagreement_std_deg"] = pair.rotation_std_deg;
      entry["translation_disagreement_std_m"] = pair.translation_std_m;
      entry["consistent"] = pair.consistent;
    }
    pairs.push_back(entry);
  }
  const nlohmann::json rig = {
      {"cameras", cameras},
      {"camera_pairs", pairs},
      {"rig_consistent", rig_consistent},
      {"stcalib_version", StcalibVersion()},
      {"command", CommandLineText()},
      {"input", job.drive_dir},
  };
  return WriteTextFile(job.out_dir + "/result.json", rig.dump(2) + "\n");
}

std::string CameraPrefix(const CalibrateJob& job, const CalibrateOutcome& outcome) {
  return job.cameras.size() > 1 ? outcome.camera + ": " : "";
}

int RunCalibrateJob(const CalibrateJob& job, std::vector<CalibrateOutcome>* outcomes) {
  const char* kCommand = "calibrate";
  Status status = job.online.Validate();
  if (status.ok()) status = job.convergence.Validate();
  if (!status.ok()) return UsageError(kCommand, status.message());
  const std::vector<std::string> camera_names =
      job.cameras.empty() ? std::vector<std::string>{"image_02"} : job.cameras;
  CHECK(job.bag.bag_dir.empty() || job.cameras.empty())
      << "CalibrateFlagsError refuses --cameras with --bag";
  const size_t n = camera_names.size();
  std::vector<CameraRun> runs(n);
  outcomes->assign(n, CalibrateOutcome());
  for (size_t k = 0; k < n; ++k) {
    status = job.bag.bag_dir.empty()
                 ? OpenDrive(job.drive_dir, job.calib_dir, &runs[k].drive, camera_names[k])
                 : OpenBagDrive(job.bag, &runs[k].drive);
    if (!status.ok()) return ReportError(kCommand, status);
  }
  const Drive& drive = runs.front().drive;
  const int first = job.first_frame;
  const int last =
      job.num_frames > 0 ? first + job.num_frames - 1 : static_cast<int>(drive.NumFrames()) - 1;
  if (first < 0 || first >= static_cast<int>(drive.NumFrames()) ||
      last >= static_cast<int>(drive.NumFrames())) {
    return ReportError(kCommand,
                       Status::Error(drive.drive_dir + ": frames " + std::to_string(first) + ".." +
                                     std::to_string(last) + " out of range (" +
                                     std::to_string(drive.NumFrames()) + " frames)"));
  }
  for (size_t k = 0; k < n; ++k) {
    runs[k].rng = std::mt19937_64(job.seed);
    status = StartCamera(job, &runs[k], &(*outcomes)[k]);
    if (!status.ok()) return ReportError(kCommand, status);
  }
  // The dynamic filter judges the cameras' view as the starting calibration places the first,
  // widened by at least how far the estimate may turn from it (plus the pruning margin's few
  // degrees).
  FrameSourceOptions source_options = job.source;
  source_options.view_T_camera_lidar = outcomes->front().initial.T_camera_lidar;
  if (source_options.view_margin_deg >= 0) {
    source_options.view_margin_deg =
        std::max(source_options.view_margin_deg, job.online.search.max_rotation_offset_deg + 10.0);
  }
  std::vector<const Drive*> drives;
  for (const CameraRun& run : runs) drives.push_back(&run.drive);
  std::unique_ptr<DriveFrameSource> source;
  status = DriveFrameSource::Create(drives, source_options, &source);
  if (!status.ok()) return ReportError(kCommand, status);
  for (CalibrateOutcome& outcome : *outcomes) outcome.motion = source->motion().SourceName();

  std::error_code ec;
  if (!job.out_dir.empty()) {
    for (size_t k = 0; k < n; ++k) {
      runs[k].out_dir = n == 1 ? job.out_dir : job.out_dir + "/" + camera_names[k];
      fs::create_directories(runs[k].out_dir, ec);
      if (ec || !fs::is_directory(runs[k].out_dir)) {
        return ReportError(kCommand,
                           Status::Error(runs[k].out_dir + ": cannot create output folder"));
      }
    }
  }

  for (size_t k = 0; k < n; ++k) {
    runs[k].calibrator = std::make_unique<OnlineCalibrator>(job.online, (*outcomes)[k].initial);
  }
  const auto run_start = std::chrono::steady_clock::now();
  // The next frame is read and its features computed on a second thread while this one is
  // calibrated; a camera's frame time is its calibration plus its share of the wait for the frame.
  FramePrefetcher frames(source.get(), first, last);
  FramePrefetcher::Loaded loaded;
  for (auto t0 = std::chrono::steady_clock::now(); frames.Next(&loaded);
       t0 = std::chrono::steady_clock::now()) {
    const int i = loaded.index;
    const double wait_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    for (size_t k = 0; k < n; ++k) {
      const auto camera_t0 = std::chrono::steady_clock::now();
      CameraRun& run = runs[k];
      CalibrateOutcome* outcome = &(*outcomes)[k];
      OnlineCalibrator& calibrator = *run.calibrator;
      CameraFrameLoad& camera_load = loaded.cameras[k];
      if (!camera_load.status.ok()) {
        // Bad data in one frame (unreadable sweep or image, oxts gap): keep the estimate, go on.
        outcome->reports.push_back(calibrator.SkipFrame(i, camera_load.status.message()));
        continue;
      }
      std::shared_ptr<const CalibrationFrame> frame = std::move(camera_load.frame);
      if (i == job.disturb_frame) {
        auto sign = [&]() { return (run.rng() & 1) ? 1.0 : -1.0; };
        const Eigen::Vector3d d(sign() * job.disturb_rot_deg, sign() * job.disturb_rot_deg,
                                sign() * job.disturb_rot_deg);
        CalibrationState disturbed = calibrator.state();
        disturbed.T_camera_lidar =
            PerturbTcameraLidar(disturbed.T_camera_lidar, d, Eigen::Vector3d::Zero());
        calibrator.SetState(disturbed);
      }
      // The last frame updates, so that the verdict reads a refinement over the latest frames
      // (if it cannot be loaded, the verdict reads the last update's, at most
      // tracking_update_every - 1 frames older).
      FrameReport report = calibrator.AddFrame(frame, /*update_now=*/i == last);
      run.frame_ms_sum += wait_ms / n + std::chrono::duration<double, std::milli>(
                                            std::chrono::steady_clock::now() - camera_t0)
                                            .count();
      if (!report.skipped) {
        run.last_frame = frame;
        ++run.frames_used;
      }
      outcome->reports.push_back(report);
      if (VLOG_IS_ON(1) && report.ran_update()) {
        const CalibrationError es =
            ComputeCalibrationError(report.search.state, outcome->reference_state);
        const CalibrationError er =
            ComputeCalibrationError(report.refine.state, outcome->reference_state);
        VLOG(1) << CameraPrefix(job, *outcome) << "frame " << i << ": search " << ToString(es)
                << " | refine (usable " << report.refine.usable << ", " << report.refine.iterations
                << " iterations, " << report.refine.residuals << " residuals) " << ToString(er)
                << " | " << report.reason;
      }
      if (job.progress) {
        const CalibrationError e = ComputeCalibrationError(report.after, outcome->reference_state);
        // An updating line on a terminal, one line per frame in a log.
        const bool terminal = isatty(fileno(stderr)) && n == 1;
        std::fprintf(stderr,
                     "%scalibrate: %sframe %d/%d  %s %.3f deg, %.3f m, dt %+.1f ms  gray %.2f  "
                     "health %.2f   ",
                     terminal ? "\r" : "", CameraPrefix(job, *outcome).c_str(), i - first + 1,
                     last - first + 1, outcome->has_truth ? "error" : "vs drive calib",
                     e.rotation_deg, e.translation_norm_m, 1000 * report.after.time_offset_s,
                     report.gray_rate_after, report.health);
        if (!terminal) std::fprintf(stderr, "\n");
      }
    }
  }
  if (job.progress && isatty(fileno(stderr)) && n == 1) std::fprintf(stderr, "\n");
  // The worst camera's code: a failure over a partial claim over a whole one.
  int code = kExitOk;
  for (size_t k = 0; k < n; ++k) {
    const int camera_code = FinishCamera(job, first, last, run_start, &runs[k], &(*outcomes)[k]);
    if (camera_code == kExitFailure || (camera_code != kExitOk && code == kExitOk)) {
      code = camera_code;
    }
  }
  if (n > 1 && job.rig_joint) RefineRig(runs, outcomes);
  const std::vector<CameraPairCheck> pairs = CompareRigPairs(*outcomes);
  if (n > 1 && !job.out_dir.empty()) {
    status = WriteRigSummary(job, *outcomes, pairs);
    if (!status.ok()) return ReportError(kCommand, status);
  }
  // Two claims that put the cameras where the rig does not: one of them is wrong.
  for (const CameraPairCheck& pair : pairs) {
    if (pair.compared && !pair.consistent) {
      std::fprintf(stderr,
                   "stcalib calibrate: the rig check fails: %s and %s claim camera-to-camera "
                   "transforms %.3f deg and %.3f m from the rig's (their std allows %.3f deg "
                   "and %.3f m): one of the two claims is wrong, or the rig moved\n",
                   pair.from.c_str(), pair.to.c_str(), pair.rotation_deg, pair.translation_m,
                   kRigRotationToleranceDeg + 3 * pair.rotation_std_deg,
                   kRigTranslationToleranceM + 3 * pair.translation_std_m);
      code = kExitFailure;
    }
  }
  return code;
}

std::string CalibrateFlagsError() {
  const std::vector<std::string> cameras = SplitCameras(FLAGS_cameras);
  for (size_t k = 0; k < cameras.size(); ++k) {
    if (!IsKittiCameraName(cameras[k])) {
      return "--cameras: '" + cameras[k] + "' is not a KITTI camera folder (image_02, image_03, …)";
    }
    if (std::count(cameras.begin(), cameras.begin() + k, cameras[k]) > 0) {
      return "--cameras names " + cameras[k] + " twice";
    }
  }
  if (!FLAGS_bag.empty() && !cameras.empty()) {
    return "--cameras names the camera folders of a --drive; a --bag has one --image_topic";
  }
  for (const auto& [name, value] : {std::pair{"--loss", &FLAGS_loss}}) {
    RefineOptions::Loss loss;
    if (!ParseLoss(*value, &loss)) return std::string(name) + " must be " + LossChoices();
  }
  StartUncertainty uncertainty;
  const Status uncertainty_status = ParseStartUncertainty(FLAGS_init_uncertainty, &uncertainty);
  if (!uncertainty_status.ok()) return uncertainty_status.message();
  const Status fits = HypothesisLattice::CheckFits(uncertainty, LatticeSteps());
  if (!fits.ok()) return "--init_uncertainty=" + FLAGS_init_uncertainty + ": " + fits.message();
  OnlineCalibratorOptions::Folds folds;
  if (!ParseFolds(FLAGS_lidar_folds, &folds)) {
    return "--lidar_folds must be " + FoldsChoices();
  }
  ImageFeatureOptions image;
  const Status image_status = ImageOptionsFromFlags(&image);
  if (!image_status.ok()) return image_status.message();
  return "";
}

int RunCalibrate() {
  // --bag wins over a --drive (which a flagfile may have set).
  if (FLAGS_bag.empty() && FLAGS_drive.empty())
    return UsageError("calibrate", "give --drive or --bag");
  if (!FLAGS_bag.empty() && (FLAGS_image_topic.empty() || FLAGS_cloud_topic.empty())) {
    return UsageError("calibrate", "--bag needs --image_topic and --cloud_topic");
  }
  const std::string flags_error = CalibrateFlagsError();
  if (!flags_error.empty()) return UsageError("calibrate", flags_error);
  const CalibrateJob job = CalibrateJobFromFlags();
  std::vector<CalibrateOutcome> outcomes;
  const int code = RunCalibrateJob(job, &outcomes);
  for (const CalibrateOutcome& outcome : outcomes) {
    if (outcome.reports.empty()) return code;
    const std::string camera = CameraPrefix(job, outcome);
    const CalibrationError& e = outcome.error;
    std::printf("%s%s after %zu frames (%s)\n", camera.c_str(),
                !outcome.converged          ? "NOT converged"
                : outcome.held_axes.empty() ? "converged"
                                            : "PARTLY converged",
                outcome.reports.size(), outcome.reason.c_str());
    std::printf(
        "%s%s: rotation %.3f deg (roll %+.3f, pitch %+.3f, yaw %+.3f), translation %.3f m, "
        "time offset %+.2f ms (estimate %+.2f ms)\n",
        camera.c_str(),
        outcome.has_truth ? "error vs ground truth" : "agreement with the drive calibration",
        e.rotation_deg, e.roll_deg, e.pitch_deg, e.yaw_deg, e.translation_norm_m,
        1000 * e.time_offset_s, 1000 * outcome.estimate.time_offset_s);
    std::printf("%s%s", TimeOffsetPriorNote(outcome).empty() ? "" : camera.c_str(),
                TimeOffsetPriorNote(outcome).c_str());
    if (!FLAGS_out.empty()) {
      std::printf("%smean %.1f ms per frame; outputs in %s\n", camera.c_str(),
                  outcome.mean_frame_ms,
                  (outcomes.size() > 1 ? FLAGS_out + "/" + outcome.camera : FLAGS_out).c_str());
    } else if (outcome.converged) {  // no --out: the estimate on stdout, nothing written
      std::printf("%smean %.1f ms per frame; no --out, so the estimate is printed here:\n%s",
                  camera.c_str(), outcome.mean_frame_ms,
                  VeloToCamText(EstimateInFileFrame(outcome)).c_str());
      std::printf("time_offset_s: %.9f\n", outcome.estimate.time_offset_s);
    }
  }
  for (const CalibrateOutcome& outcome : outcomes) {
    if (!outcome.joint) continue;
    const CalibrationError& e = outcome.joint_error;
    std::printf(
        "%s: rig's joint estimate: %s rotation %.3f deg (roll %+.3f, pitch %+.3f, yaw %+.3f), "
        "translation %.3f m, time offset %+.2f ms\n",
        outcome.camera.c_str(), outcome.has_truth ? "error" : "agreement", e.rotation_deg,
        e.roll_deg, e.pitch_deg, e.yaw_deg, e.translation_norm_m, 1000 * e.time_offset_s);
  }
  // The rig: each pair of cameras as their estimates place them against the rig's own.
  for (const CameraPairCheck& pair : CompareRigPairs(outcomes)) {
    if (!pair.compared) {
      std::printf("%s to %s: not compared (not both claimed)\n", pair.from.c_str(),
                  pair.to.c_str());
      continue;
    }
    std::printf(
        "%s to %s against the rig's calibration: rotation %.3f deg (expected spread %.3f), "
        "translation %.3f m (expected spread %.3f), baseline %+.3f m of %.3f: %s\n",
        pair.from.c_str(), pair.to.c_str(), pair.rotation_deg, pair.rotation_std_deg,
        pair.translation_m, pair.translation_std_m, pair.baseline_m,
        pair.T_to_from_rig.translation().norm(), pair.consistent ? "consistent" : "INCONSISTENT");
  }
  return code;
}

}  // namespace stcalib::cli
