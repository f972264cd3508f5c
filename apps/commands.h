#pragma once

#include <random>
#include <string>

#include "core/features/image_features.h"
#include "core/io/bag_drive.h"
#include "core/io/drive.h"
#include "core/score/calibration_frame.h"
#include "core/types/calibration.h"
#include "core/types/status.h"

namespace stcalib::cli {

// Exit codes shared by every subcommand.
constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;  ///< bad input, unreadable data, or a negative result
constexpr int kExitUsage = 2;    ///< unknown subcommand, missing or invalid flag
// calibrate: a partial claim. The rotation (and the axes observed) is claimed and written; the
// axes the drive does not constrain keep their start values, marked held.
constexpr int kExitPartial = 3;
// check: the calibration is off (some axis lies beyond its tolerance of the drive's optimum).
constexpr int kExitCheckOff = 4;
// check: the drive cannot tell (it does not resolve the rotation to within the tolerance).
constexpr int kExitCannotTell = 5;

int RunInfo();
int RunProject();
int RunSimulate();
int RunFeatures();
int RunCalibrate();
int RunDemo();
int RunEvalTemporal();
int RunCheck();
int RunConvert();
int RunReport();
// The one argument after the subcommand that is not a flag (`report RUN_DIR`); empty if none.
const std::string& PositionalArgument();
// The command line as given (argv joined by spaces), for the outputs that name it.
const std::string& CommandLineText();

// The frame's LiDAR edge points projected at `state` on its image (darkened), green where within
// 2 px of an image edge of their direction, red elsewhere, with `title` and a legend.
cv::Mat DrawEdgeOverlay(const cv::Mat& image, const CalibrationFrame& frame,
                        const CalibrationState& state, const std::string& title);

// The report's strip (docs/output.md): DIR/frames is made afresh, and up to 4 of `frames`,
// spread evenly over them, are drawn at every view as frames/<prefix>F.png (F: the frame's
// index). The paths written go to `written` (optional).
struct StripView {
  std::string prefix;  ///< file name before the frame index
  CalibrationState state;
  std::string title;  ///< drawn after "frame F "
};
Status WriteFrameStrip(const Drive& drive,
                       const std::vector<std::shared_ptr<const CalibrationFrame>>& frames,
                       const std::vector<StripView>& views, const std::string& dir,
                       std::vector<std::string>* written = nullptr);

// Prints "stcalib <command>: error: <message>" to stderr and returns kExitFailure.
int ReportError(const std::string& command, const Status& status);
// Prints a usage error and returns kExitUsage.
int UsageError(const std::string& command, const std::string& message);
// Reads ground_truth.json beside a simulated drive's calibration (for a camera other than
// image_02, its entry under `cameras`); *found is false (and the status ok) when the drive has
// none.
Status ReadGroundTruth(const Drive& drive, bool* found, CalibrationState* truth);
// The LiDAR a simulated drive's ground_truth.json names ("hdl64", "vlp16", "os1-64"); empty for a
// drive without one (or one simulated before the key existed).
Status ReadSimulatedLidarName(const Drive& drive, std::string* lidar);
// The calibration a run starts from, in the camera's own frame: `init_calib` (a
// calib_velo_to_cam.txt, carried by the camera's rig transform; empty: the drive's own), perturbed by ±perturb_rot_deg on roll, pitch and yaw and ±perturb_trans_m on x, y, z with
// signs drawn from `rng` (in that order).
Status StartingCalibration(const Drive& drive, const std::string& init_calib,
                           double perturb_rot_deg, double perturb_trans_m, std::mt19937_64* rng,
                           Rigid3d* T_camera_lidar);
// Opens --drive with --calib_dir.
Status OpenDriveFromFlags(Drive* drive);
// --bag and its topic flags; the bag's tf must hold the camera–LiDAR transform unless
// --init_calib gives the start.
BagDriveOptions BagOptionsFromFlags();
// Opens --bag (with its topics) when given, else --drive with --calib_dir.
Status OpenDriveOrBagFromFlags(Drive* drive);
// --detector, --min_segment_px and --max_edge_density into `options` (features, calibrate, demo
// and check read the same image edges); an error naming the flag for an unknown detector, with
// `options` untouched.
Status ImageOptionsFromFlags(ImageFeatureOptions* options);

}  // namespace stcalib::cli
