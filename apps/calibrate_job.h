#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/io/bag_drive.h"
#include "core/online/convergence.h"
#include "core/online/frame_source.h"
#include "core/online/online_calibrator.h"
#include "core/types/calibration.h"

namespace stcalib::cli {

// One run of `stcalib calibrate` (also what `stcalib demo` runs).
struct CalibrateJob {
  std::string drive_dir, calib_dir, init_calib, out_dir;
  BagDriveOptions bag;  ///< a ROS 2 bag instead of the drive when bag.bag_dir is set
  double perturb_rot_deg = 0, perturb_trans_m = 0, perturb_time_s = 0;
  uint64_t seed = 1;
  int first_frame = 0, num_frames = 0;
  int disturb_frame = -1;
  double disturb_rot_deg = 2.0;
  bool polish = true;  ///< OnlineCalibrator::Polish() after the last frame
  OnlineCalibratorOptions online;
  FrameSourceOptions source;
  ConvergenceOptions convergence;
  bool progress = true;
};

struct CalibrateOutcome {
  bool converged = false;              ///< a claim, whole or partial
  std::vector<std::string> held_axes;  ///< held at their start values: a partial claim when any
  bool alias_suspect = false;
  std::string reason;
  bool has_truth = false;
  std::string reference;  ///< "ground truth (simulated)" or "drive calibration"
  std::string motion;     ///< where Tv comes from: DriveMotion::SourceName
  CalibrationState reference_state, initial, estimate;
  CalibrationError error, initial_error;
  std::vector<FrameReport> reports;
  FrameReport polish;                 ///< the final refinement (OnlineCalibrator::Polish), if run
  bool time_offset_estimated = true;  ///< δ was estimated (else held at δ0)
  TimeForwardPair time_forward;       ///< δ against the forward translation (the verdict's)
  // Per axis (kAxisNames order), whether the estimate is observed (result.json's `observable`):
  // an axis that is not rests on its start or its prior and is shown as held.
  std::array<bool, kNumAxes> observable{};
  std::vector<std::string> pictures;
  double mean_frame_ms = 0;
};

CalibrateJob CalibrateJobFromFlags();
// What is wrong with the calibration flags that CalibrateJobFromFlags reads by name (--loss,
// --lidar_folds, --detector); empty when nothing is.
std::string CalibrateFlagsError();
// What δ rests on: "window" (the polish separated it from the forward translation),
// "forward_translation_prior" (it did not, or did not run), "start" (δ not estimated).
std::string TimeOffsetRestsOn(const CalibrateOutcome& outcome);
// One line (with its newline) saying that δ rests on the forward translation's prior, with the
// pair's std and correlation when measured; empty when δ was separated or not estimated.
std::string TimeOffsetPriorNote(const CalibrateOutcome& outcome);
// Runs the job and writes its outputs; returns the exit code (0 when converged, kExitPartial when
// converged partly).
int RunCalibrateJob(const CalibrateJob& job, CalibrateOutcome* outcome);

}  // namespace stcalib::cli
