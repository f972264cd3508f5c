#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/refine/jackknife.h"
#include "core/refine/refine.h"
#include "core/score/calibration_frame.h"
#include "core/types/calibration.h"
#include "core/types/status.h"

namespace stcalib {

// Does a given calibration hold on a drive (docs/method.md §7, "Checking a calibration")? The
// drive's own optimum near it is found by refining from it (the rotation with the translation and
// δ held, then every axis together), and that optimum's spread over the drive by a delete-a-block
// jackknife (blocks of the frames that share sweeps). With d the optimum's offset from the
// calibration, σ its jackknife std (at least the refinement's), n the blocks and t the one-sided
// 99 % quantile of Student's t with n − 1 degrees of freedom:
//   the rotation is off       when its angle |d| > tolerance + t·σ along d;
//   the rotation is resolved  when t·σ ≤ tolerance on every rotation axis;
//   a translation axis or δ is judged the same way, axis by axis; the translation along the
//   direction of travel is never resolved (δ trades with it, docs/method.md §10).
// Answer: off when the rotation or a resolved translation axis or δ is off; otherwise cannot tell
// when the rotation is not resolved (or too few frames), else holds. A calibration within
// the tolerance is then called off with a probability under 1 % per test, if the blocks are
// independent and the drive's optimum is unbiased (docs/results.md#check gives the measured
// rates).
// The check reads each frame's own sweep only (no local map): frames that share no sweep are
// blocks of one frame, which gives the jackknife as many blocks as frames (10 frames: t = 2.82
// instead of 6.96 with the 3-sweep map's blocks of 3). Measured: docs/results.md#check
inline constexpr int kCheckLocalMapSweeps = 1;

RefineOptions CheckRefineOptions();

struct CalibrationCheckOptions {
  double tolerance_rotation_deg = 0.3;    ///< a rotation this close to the optimum holds [deg]
  double tolerance_translation_m = 0.05;  ///< a translation axis this close holds [m]
  double tolerance_time_s = 0.01;         ///< δ this close holds [s]
  int min_blocks = 3;                     ///< fewer jackknife blocks: cannot tell
  int min_points_per_frame = 30;          ///< fewer LiDAR edge points in the image: frame unused
  double point_margin = 0.02;             ///< points kept inside the image shrunk by this share
  // The refinement: calibrate's while acquiring (Cauchy loss at 1 px, w = 0.2, 12 iterations): a
  // local optimum. A wider loss or more iterations reach farther but let the optimum wander off
  // on weak scenes (2.5° on the highway) and call a correct calibration off. Measured:
  // docs/results.md#check
  RefineOptions refine = CheckRefineOptions();

  Status Validate() const;
  double Tolerance(int axis) const;  ///< in the axis' unit (kAxisNames)
};

// The one-sided 99 % quantile of Student's t with `dof` ≥ 1 degrees of freedom.
double StudentT99(int dof);

enum class CheckAnswer { kHolds, kOff, kCannotTell };
std::string CheckAnswerName(CheckAnswer answer);  ///< "holds", "off", "cannot tell"

struct AxisCheck {
  double offset = 0;      ///< the drive's optimum − the checked calibration (axis unit)
  double std = 0;         ///< max(jackknife std, refinement std) (axis unit)
  double tolerance = 0;   ///< (axis unit)
  bool resolved = false;  ///< t·std ≤ tolerance
  bool off = false;       ///< resolved and |offset| > tolerance + t·std (this axis alone)
};

struct CalibrationCheckResult {
  CheckAnswer answer = CheckAnswer::kCannotTell;
  int frames_used = 0;  ///< frames with enough LiDAR edge points in the image
  int blocks = 0;       ///< jackknife blocks
  int block_frames = 0;
  double t_quantile = 0;  ///< t of the tests (StudentT99(blocks − 1))
  // The rotation's angle from the drive's optimum and its std along that direction [deg].
  double rotation_offset_deg = 0, rotation_std_deg = 0;
  CalibrationState optimum;  ///< the drive's optimum near the checked calibration
  std::array<AxisCheck, kNumAxes> axes;
  std::string reason;  ///< the answer and its evidence, in words
};

// `frames` in time order; `calibration` the calibration checked (with its δ).
CalibrationCheckResult CheckCalibration(
    const std::vector<std::shared_ptr<const CalibrationFrame>>& frames,
    const CalibrationState& calibration, const CalibrationCheckOptions& options);

}  // namespace stcalib
