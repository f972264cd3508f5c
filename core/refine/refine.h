#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "core/score/calibration_frame.h"
#include "core/types/calibration.h"
#include "core/types/status.h"

namespace stcalib {

// Joint refinement of rotation, translation and time offset over a window of frames with Ceres
// (docs/method.md §6): one EdgeAlignmentCost per frame (a residual per LiDAR edge point, each under
// the robust loss), plus a weak CalibrationPriorCost towards the search result.
// ceres::Covariance then gives per-axis standard deviations; an axis is observable when its std
// is under a threshold.
struct RefineOptions {
  enum class Loss { kHuber, kCauchy, kTukey };
  Loss loss = Loss::kCauchy;
  double loss_scale_px = 1.0;      ///< robust-loss scale [px]
  double horizontal_weight = 0.5;  ///< w of docs/method.md §6
  // Weak priors: rotation towards the search result, translation and δ towards the mount (the
  // initial calibration); they hold only what the data leaves free (δ against the forward
  // translation on a straight road, docs/method.md §10).
  double prior_sigma_rotation_deg = 2.0;  ///< [deg]
  // Lateral and vertical (with Translation::kAlongTravel, forward too) [m].
  double prior_sigma_translation_m = 0.05;
  // Along the direction of travel the translation is held firmly (per point, i.e. the sigma is
  // scaled by √N): there data cannot tell it from δ on a straight road (docs/method.md §10).
  double prior_sigma_forward_m = 0.05;
  double prior_sigma_time_s = 0.03;   ///< [s]
  double time_offset_bound_s = 0.15;  ///< |δ| bound [s]
  bool estimate_time_offset = true;
  // How the translation may move. kAlongTravel: only along the direction of travel (a
  // one-dimensional manifold through the start; the window's last LiDAR velocity, in the camera
  // frame), under the weak prior_sigma_translation_m instead of the firm forward prior, so that
  // the data decides where δ and the forward translation sit wherever it separates the two
  // (speed changes, turns) and the covariance says where it does not.
  enum class Translation { kFree, kAlongTravel, kHeld };
  Translation translation = Translation::kFree;
  // Hold the local map's earlier sweeps (merged at the LiDAR stamps, off by δ) at the start's δ
  // (CalibrationFrame::offset_rates), else they bias δ and the forward translation; off while
  // tracking, where it holds a δ still far off. Measured: docs/tuning.md#place-at-time-offset
  bool place_at_time_offset = false;
  int max_points_per_frame = 300;
  int max_iterations = 12;
  // Observability thresholds on the standard deviations.
  double observable_rotation_deg = 0.15;
  double observable_translation_m = 0.04;
  double observable_time_s = 0.006;

  Status Validate() const;
};

// RefineOptions::Loss by name: huber | cauchy | tukey. ParseLoss: false, `loss` untouched, when
// `name` is none of them. LossChoices: the names, for a message ("huber, cauchy or tukey").
std::string LossName(RefineOptions::Loss loss);
bool ParseLoss(const std::string& name, RefineOptions::Loss* loss);
std::string LossChoices();

// Axes in result order: roll, pitch, yaw (about the LiDAR axes) [deg], x, y, z (translation of
// T_camera_lidar) [m], time offset [s].
constexpr int kNumAxes = 7;
extern const std::array<const char*, kNumAxes> kAxisNames;  // roll_deg, ..., time_offset_s

// The offsets of `state` from `reference` per axis, in result order and units: the rotation of
// R_refᵀ·R (about the LiDAR axes) [deg], the translation [m], δ [s] (ComputeCalibrationError).
Eigen::Matrix<double, kNumAxes, 1> AxisOffsets(const CalibrationState& state,
                                               const CalibrationState& reference);

struct RefineResult {
  CalibrationState state;
  bool usable = false;
  std::string message;
  int residuals = 0;
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  bool covariance_ok = false;
  Eigen::Matrix<double, kNumAxes, 1> std_dev = Eigen::Matrix<double, kNumAxes, 1>::Constant(1e9);
  Eigen::Matrix<double, kNumAxes, kNumAxes> correlation =
      Eigen::Matrix<double, kNumAxes, kNumAxes>::Identity();
  std::array<bool, kNumAxes> observable{};
  // Correlation of δ with the translation along the direction of travel (camera frame), and the
  // standard deviation of that translation [m].
  double time_forward_correlation = 0;
  double forward_std_m = 1e9;
  // That direction (unit, camera frame): the window's last LiDAR velocity, or the camera axis
  // when the window is not moving.
  Eigen::Vector3d forward_camera = Eigen::Vector3d::UnitZ();
};

// `rotation_prior` holds the rotation (the search result), `mount_prior` the translation and
// the time offset (the initial calibration and δ0).
RefineResult Refine(const std::vector<const CalibrationFrame*>& window,
                    const CalibrationState& start, const CalibrationState& rotation_prior,
                    const CalibrationState& mount_prior, const RefineOptions& options);

}  // namespace stcalib
