#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/io/bag_drive.h"
#include "core/online/convergence.h"
#include "core/online/frame_source.h"
#include "core/online/online_calibrator.h"
#include "core/online/rig_check.h"
#include "core/types/calibration.h"

namespace stcalib::cli {

// One run of `stcalib calibrate` (also what `stcalib demo` runs).
struct CalibrateJob {
  std::string drive_dir, calib_dir, init_calib, out_dir;
  // KITTI camera folders to calibrate in one pass over the LiDAR (--cameras); empty: image_02.
  // With more than one, each camera's outputs go to out_dir/<camera>/ and the rig's summary to
  // out_dir (WriteRigSummary).
  std::vector<std::string> cameras;
  // With several cameras: also refine one LiDAR extrinsic for the rig over every claimed
  // camera's frames, the rig's camera-to-camera transforms imposed (--rig_joint).
  bool rig_joint = false;
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
  std::string camera;  ///< its folder (KITTI) or "image_02" for a bag
  // The camera's rectified optical frame from its frame (RectifiedFromCamera), and its frame from
  // calib_velo_to_cam's (CameraCalibration::T_camera_reference): the rig's geometry.
  Rigid3d T_rectified_camera = Rigid3d::Identity();
  Rigid3d T_camera_reference = Rigid3d::Identity();
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
  std::array<bool, kNumAxes> has_std{};    ///< result.json's `std`: false where it is null
  std::array<double, kNumAxes> std_dev{};  ///< [deg, m, s] (ReportUncertainty)
  // The rig's joint refinement as this camera sees it (job.rig_joint; joint: the camera took
  // part), with its error against the reference.
  bool joint = false;
  CalibrationState joint_estimate;
  CalibrationError joint_error;
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
// Runs the job and writes its outputs, one outcome per camera (job.cameras' order); returns the
// exit code (0 when every camera converged, kExitPartial when one converged partly and none
// failed, else kExitFailure).
int RunCalibrateJob(const CalibrateJob& job, std::vector<CalibrateOutcome>* outcomes);
// "image_03: " before a camera's messages when the job has several cameras, else "".
std::string CameraPrefix(const CalibrateJob& job, const CalibrateOutcome& outcome);

// The camera as the rig check reads it (core/online/rig_check.h).
RigCamera ToRigCamera(const CalibrateOutcome& outcome);
// Every pair of cameras (a before b in the job's order) as the rig check compares them.
std::vector<CameraPairCheck> CompareRigPairs(const std::vector<CalibrateOutcome>& outcomes);
// The estimate in calib_velo_to_cam.txt's frame (KITTI's camera 0): what the camera's file holds.
Rigid3d EstimateInFileFrame(const CalibrateOutcome& outcome);
// The rig's result.json in job.out_dir: every camera's claim, estimate and std, and the pairs.
Status WriteRigSummary(const CalibrateJob& job, const std::vector<CalibrateOutcome>& outcomes,
                       const std::vector<CameraPairCheck>& pairs);

}  // namespace stcalib::cli
