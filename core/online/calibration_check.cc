#include "core/online/calibration_check.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/score/score.h"
#include "core/types/enum_names.h"
#include "core/types/format.h"

namespace stcalib {
namespace {

constexpr EnumNames<CheckAnswer, 3> kAnswerNames = {{{CheckAnswer::kHolds, "holds"},
                                                     {CheckAnswer::kOff, "off"},
                                                     {CheckAnswer::kCannotTell, "cannot tell"}}};

// An axis offset in its display unit: degrees, centimetres, milliseconds.
double DisplayValue(int axis, double value) {
  return axis < 3 ? value : axis < 6 ? 100 * value : 1000 * value;
}
const char* DisplayUnit(int axis) { return axis < 3 ? "deg" : axis < 6 ? "cm" : "ms"; }

}  // namespace

Status CalibrationCheckOptions::Validate() const {
  if (!(tolerance_rotation_deg > 0) || !(tolerance_translation_m > 0) || !(tolerance_time_s > 0)) {
    return Status::Error("check: tolerances must be positive");
  }
  if (min_blocks < 2 || min_points_per_frame < 1) {
    return Status::Error("check: min_blocks must be >= 2, min points >= 1");
  }
  if (!(point_margin >= 0 && point_margin < 0.5)) {
    return Status::Error("check: point_margin must be in [0, 0.5)");
  }
  return refine.Validate();
}

double CalibrationCheckOptions::Tolerance(int axis) const {
  return axis < 3 ? tolerance_rotation_deg : axis < 6 ? tolerance_translation_m : tolerance_time_s;
}

RefineOptions CheckRefineOptions() {
  RefineOptions refine;
  refine.horizontal_weight = 0.2;
  return refine;
}

double StudentT99(int dof) {
  CHECK_GE(dof, 1);
  static constexpr double kQuantile[] = {31.821, 6.965, 4.541, 3.747, 3.365, 3.143, 2.998,
                                         2.896,  2.821, 2.764, 2.718, 2.681, 2.650, 2.624,
                                         2.602,  2.583, 2.567, 2.552, 2.539, 2.528};
  constexpr int kTabulated = sizeof(kQuantile) / sizeof(kQuantile[0]);
  if (dof <= kTabulated) return kQuantile[dof - 1];
  // Beyond 20: 2.528 at 20, 2.457 at 30, 2.423 at 40, 2.326 in the limit; linear in 1/dof.
  return 2.326 + (2.528 - 2.326) * 20.0 / dof;
}

std::string CheckAnswerName(CheckAnswer answer) { return EnumName(kAnswerNames, answer); }

CalibrationCheckResult CheckCalibration(
    const std::vector<std::shared_ptr<const CalibrationFrame>>& frames,
    const CalibrationState& calibration, const CalibrationCheckOptions& options) {
  CHECK(options.Validate().ok()) << options.Validate().message();
  CalibrationCheckResult result;
  result.optimum = calibration;
  for (int axis = 0; axis < kNumAxes; ++axis) {
    result.axes[axis].tolerance = options.Tolerance(axis);
  }
  // The frames' points that fall inside the image at the checked calibration.
  std::vector<std::shared_ptr<const CalibrationFrame>> pruned;
  std::vector<const CalibrationFrame*> used;
  for (const auto& frame : frames) {
    pruned.push_back(PruneToImage(*frame, calibration, options.point_margin));
    if (static_cast<int>(pruned.back()->size()) >= options.min_points_per_frame) {
      used.push_back(pruned.back().get());
    }
  }
  result.frames_used = static_cast<int>(used.size());
  result.block_frames = SharedSweepFrames(used);
  result.blocks = result.frames_used / result.block_frames;
  if (result.blocks < options.min_blocks) {
    result.reason = "cannot tell: " + std::to_string(result.frames_used) + " of " +
                    std::to_string(frames.size()) + " frames have " +
                    std::to_string(options.min_points_per_frame) +
                    " LiDAR edge points in the image: " + std::to_string(result.blocks) +
                    " blocks of " + std::to_string(result.block_frames) +
                    " frames (the frames that share sweeps), at least " +
                    std::to_string(options.min_blocks) + " needed";
    return result;
  }
  // Rotation with the translation and δ held: the rotation axes' offsets and spread.
  const RefineOptions& full_options = options.refine;
  RefineOptions rotation_options = full_options;
  rotation_options.translation = RefineOptions::Translation::kHeld;
  rotation_options.estimate_time_offset = false;
  const RefineResult rotation =
      Refine(used, calibration, calibration, calibration, rotation_options);
  // Every axis together, from there: the translation's and δ's.
  const RefineResult full = Refine(used, rotation.state, calibration, calibration, full_options);
  if (!rotation.usable || !full.usable) {
    result.reason = "cannot tell: the refinement failed: " +
                    (rotation.usable ? full.message : rotation.message);
    return result;
  }
  result.optimum = full.state;
  const RefineJackknife rotation_spread =
      JackknifeRefine(used, rotation.state, calibration, rotation_options, result.block_frames,
                      /*min_frames=*/2);
  const RefineJackknife full_spread = JackknifeRefine(used, full.state, calibration, full_options,
                                                      result.block_frames, /*min_frames=*/2);
  const auto rotation_offsets = AxisOffsets(rotation.state, calibration);
  const auto full_offsets = AxisOffsets(full.state, calibration);
  const int blocks_measured = result.blocks - std::max(rotation_spread.failed, full_spread.failed);
  const double t = StudentT99(std::max(1, blocks_measured - 1));
  result.t_quantile = t;
  for (int axis = 0; axis < kNumAxes; ++axis) {
    AxisCheck& a = result.axes[axis];
    const bool is_rotation = axis < 3;
    const RefineResult& refined = is_rotation ? rotation : full;
    a.offset = is_rotation ? rotation_offsets[axis] : full_offsets[axis];
    const double covariance_std = refined.covariance_ok ? refined.std_dev[axis] : 1e9;
    a.std = std::max(covariance_std, (is_rotation ? rotation_spread : full_spread).std[axis]);
    // Along the direction of travel the refinement holds the translation by its prior (δ trades
    // with it, docs/method.md §10): that axis is not resolved, whatever its std says.
    const bool along_travel =
        axis >= 3 && axis < 6 && std::abs(full.forward_camera[axis - 3]) > 0.5;
    a.resolved = !along_travel && t * a.std <= a.tolerance;
    a.off = a.resolved && std::abs(a.offset) > a.tolerance + t * a.std;
  }
  // The rotation as one angle: its offset and the std along the offset's direction.
  const Eigen::Vector3d d = rotation_offsets.head<3>();
  result.rotation_offset_deg = d.norm();
  double variance = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double u = d.norm() > 0 ? d[axis] / d.norm() : 1.0 / std::sqrt(3.0);
    variance += u * u * result.axes[axis].std * result.axes[axis].std;
  }
  result.rotation_std_deg = std::sqrt(variance);
  const bool rotation_off =
      result.rotation_offset_deg > options.tolerance_rotation_deg + t * result.rotation_std_deg;
  std::string unresolved_rotation, off_others, unresolved_others;
  for (int axis = 0; axis < kNumAxes; ++axis) {
    const AxisCheck& a = result.axes[axis];
    std::string& unresolved = axis < 3 ? unresolved_rotation : unresolved_others;
    if (!a.resolved) unresolved += (unresolved.empty() ? "" : ", ") + std::string(kAxisNames[axis]);
    if (axis >= 3 && a.off) {
      off_others += (off_others.empty() ? "" : ", ") + std::string(kAxisNames[axis]) +
                    FormatNumbers(" %+.1f ", DisplayValue(axis, a.offset)) + DisplayUnit(axis) +
                    FormatNumbers(" (std %.1f)", DisplayValue(axis, a.std));
    }
  }
  const std::string evidence =
      FormatNumbers("%.0f frames in %.0f blocks of %.0f, t = %.2f", result.frames_used,
                    result.blocks, result.block_frames, t);
  const std::string rotation_text = FormatNumbers(
      "the rotation lies %.2f deg from the drive's optimum (std %.2f deg along it; "
      "tolerance %.2f deg)",
      result.rotation_offset_deg, result.rotation_std_deg, options.tolerance_rotation_deg);
  if (rotation_off || !off_others.empty()) {
    result.answer = CheckAnswer::kOff;
    result.reason = rotation_off ? "off: " + rotation_text + " (" + evidence + ")"
                                 : "off: " + off_others + " beyond the tolerance + t·std; " +
                                       rotation_text + " (" + evidence + ")";
  } else if (!unresolved_rotation.empty()) {
    result.answer = CheckAnswer::kCannotTell;
    result.reason = "cannot tell: this drive does not resolve " + unresolved_rotation +
                    " to the tolerance (t·std over it); " + rotation_text + " (" + evidence + ")";
  } else {
    result.answer = CheckAnswer::kHolds;
    result.reason = "holds: " + rotation_text +
                    (unresolved_others.empty() ? ""
                                               : "; not resolved "
                                                 "by this drive (not checked): " +
                                                     unresolved_others) +
                    " (" + evidence + ")";
  }
  return result;
}

}  // namespace stcalib
