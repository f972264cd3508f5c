#include "core/refine/refine.h"

#include <ceres/ceres.h>
#include <ceres/product_manifold.h>
#include <glog/logging.h>

#include <array>
#include <cmath>
#include <memory>
#include <string>

#include "core/refine/along_direction_manifold.h"
#include "core/types/enum_names.h"
#include "cost_functions/calibration_prior_cost.h"
#include "cost_functions/edge_alignment_cost.h"
#include "cost_functions/memoized_cost.h"

namespace stcalib {

namespace {
constexpr EnumNames<RefineOptions::Loss, 3> kLossNames = {{{RefineOptions::Loss::kHuber, "huber"},
                                                           {RefineOptions::Loss::kCauchy, "cauchy"},
                                                           {RefineOptions::Loss::kTukey, "tukey"}}};
}  // namespace

std::string LossName(RefineOptions::Loss loss) { return EnumName(kLossNames, loss); }

bool ParseLoss(const std::string& name, RefineOptions::Loss* loss) {
  return ParseEnumName(kLossNames, name, loss);
}

std::string LossChoices() { return EnumNameChoices(kLossNames); }

const std::array<const char*, kNumAxes> kAxisNames = {
    "roll_deg", "pitch_deg", "yaw_deg", "x_m", "y_m", "z_m", "time_offset_s"};

Status RefineOptions::Validate() const {
  if (!(loss_scale_px > 0) || !(prior_sigma_rotation_deg > 0) || !(prior_sigma_translation_m > 0) ||
      !(prior_sigma_time_s > 0) || !(time_offset_bound_s >= 0) || max_iterations < 1 ||
      max_points_per_frame < 0) {
    return Status::Error("refine: scales, sigmas and caps must be positive");
  }
  if (!(horizontal_weight >= 0 && horizontal_weight <= 1)) {
    return Status::Error("refine: horizontal_weight must be in [0, 1]");
  }
  return Status::Ok();
}

Eigen::Matrix<double, kNumAxes, 1> AxisOffsets(const CalibrationState& state,
                                               const CalibrationState& reference) {
  const CalibrationError error = ComputeCalibrationError(state, reference);
  Eigen::Matrix<double, kNumAxes, 1> offsets;
  offsets << error.roll_deg, error.pitch_deg, error.yaw_deg, error.translation_m,
      error.time_offset_s;
  return offsets;
}

RefineResult Refine(const std::vector<const CalibrationFrame*>& window,
                    const CalibrationState& start, const CalibrationState& rotation_prior,
                    const CalibrationState& mount_prior, const RefineOptions& options) {
  CHECK(options.Validate().ok()) << options.Validate().message();
  RefineResult result;
  result.state = start;

  // Interpolators over each frame's smoothed, capped distance map.
  std::vector<std::unique_ptr<DistanceGrid>> grids;
  std::vector<std::unique_ptr<DistanceInterpolator>> interpolators;
  const Eigen::Quaterniond q_start(start.T_camera_lidar.linear());
  double pose[7] = {q_start.x(),
                    q_start.y(),
                    q_start.z(),
                    q_start.w(),
                    start.T_camera_lidar.translation().x(),
                    start.T_camera_lidar.translation().y(),
                    start.T_camera_lidar.translation().z()};
  double delta =
      std::clamp(start.time_offset_s, -options.time_offset_bound_s, options.time_offset_bound_s);
  // The direction of travel in the camera frame (the window's last LiDAR velocity).
  // Below 0.5 m/s there is none: the camera axis stands in, and δ is then unobservable.
  const LidarTwist& last_twist = window.back()->twist;
  const bool moving = last_twist.linear_m_s.norm() > 0.5;
  const Eigen::Vector3d forward =
      moving ? Eigen::Vector3d(start.T_camera_lidar.linear() * last_twist.linear_m_s.normalized())
             : Eigen::Vector3d::UnitZ();
  result.forward_camera = forward;
  using Translation = RefineOptions::Translation;
  ceres::Problem problem;
  switch (options.translation) {
    case Translation::kFree:
      problem.AddParameterBlock(pose, 7,
                                new ceres::ProductManifold<ceres::EigenQuaternionManifold,
                                                           ceres::EuclideanManifold<3>>());
      break;
    case Translation::kAlongTravel:
      problem.AddParameterBlock(
          pose, 7,
          new ceres::ProductManifold<ceres::EigenQuaternionManifold, AlongDirectionManifold>(
              ceres::EigenQuaternionManifold(), AlongDirectionManifold(forward)));
      break;
    case Translation::kHeld:
      problem.AddParameterBlock(
          pose, 7,
          new ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::SubsetManifold>(
              ceres::EigenQuaternionManifold(), ceres::SubsetManifold(3, {0, 1, 2})));
      break;
  }
  problem.AddParameterBlock(&delta, 1);
  // The loss is applied per point inside EdgeAlignmentCost (one residual block per frame).
  std::unique_ptr<ceres::LossFunction> loss;
  switch (options.loss) {
    case RefineOptions::Loss::kCauchy:
      loss = std::make_unique<ceres::CauchyLoss>(options.loss_scale_px);
      break;
    case RefineOptions::Loss::kHuber:
      loss = std::make_unique<ceres::HuberLoss>(options.loss_scale_px);
      break;
    case RefineOptions::Loss::kTukey:
      loss = std::make_unique<ceres::TukeyLoss>(options.loss_scale_px);
      break;
  }
  for (const CalibrationFrame* frame : window) {
    if (frame->distance_px[0].empty() || frame->distance_px[1].empty() || frame->size() == 0)
      continue;
    std::array<const DistanceInterpolator*, 2> by_kind;
    double cap = frame->distance_cap_px;
    for (int kind = 0; kind < 2; ++kind) {
      const cv::Mat& map = frame->distance_px[kind];
      CHECK(map.isContinuous() && map.type() == CV_32F);
      grids.push_back(std::make_unique<DistanceGrid>(map.ptr<float>(), 0, map.rows, 0, map.cols));
      interpolators.push_back(std::make_unique<DistanceInterpolator>(*grids.back()));
      by_kind[kind] = interpolators.back().get();
      if (frame->distance_cap_px <= 0) {  // not known: one pass over the map
        double max_value = 0;
        cv::minMaxLoc(map, nullptr, &max_value);
        cap = std::max(cap, max_value);
      }
    }
    const size_t n = frame->size();
    const size_t keep =
        options.max_points_per_frame > 0 ? std::min<size_t>(n, options.max_points_per_frame) : n;
    // Points merged from earlier sweeps placed at the start's δ (RefineOptions::
    // place_at_time_offset).
    const bool place = options.place_at_time_offset && !frame->offset_rates.empty();
    CHECK(frame->offset_rates.empty() || frame->offset_rates.size() == n);
    std::vector<EdgeAlignmentCost::Point> points;
    for (size_t k = 0; k < keep; ++k) {
      const size_t i = k * n / keep;
      const double w = frame->kinds[i] == EdgeKind::kHorizontal ? options.horizontal_weight
                                                                : 1.0 - options.horizontal_weight;
      if (w <= 0) continue;
      const Eigen::Vector3d p =
          place ? Eigen::Vector3d(frame->points_lidar[i] + delta * frame->offset_rates[i])
                : frame->points_lidar[i];
      points.push_back({p, w, static_cast<int>(frame->kinds[i])});
    }
    if (points.empty()) continue;
    result.residuals += static_cast<int>(points.size());
    // Memoized: the line search, the candidate and the accepted step evaluate one point thrice.
    problem.AddResidualBlock(new MemoizedCostFunction(std::make_unique<EdgeAlignmentCost>(
                                 std::move(points), frame->twist, frame->e0_s, &frame->camera,
                                 by_kind, cap, loss.get())),
                             nullptr, pose, &delta);
  }
  if (result.residuals < 20) {
    result.message =
        "too few LiDAR edge points to refine (" + std::to_string(result.residuals) + ")";
    return result;
  }
  // Translation prior: weak across the direction of travel, per point along it (weak along it
  // too when the translation moves only along it).
  const Eigen::Matrix3d along = forward * forward.transpose();
  const double forward_sigma_m =
      options.translation == Translation::kAlongTravel
          ? options.prior_sigma_translation_m
          : options.prior_sigma_forward_m / std::sqrt(static_cast<double>(result.residuals));
  const Eigen::Matrix3d sqrt_information =
      (Eigen::Matrix3d::Identity() - along) / options.prior_sigma_translation_m +
      along / forward_sigma_m;
  const Eigen::Quaterniond q_prior(rotation_prior.T_camera_lidar.linear());
  problem.AddResidualBlock(
      CalibrationPriorCost::Create(q_prior, mount_prior.T_camera_lidar.translation(),
                                   mount_prior.time_offset_s,
                                   options.prior_sigma_rotation_deg * M_PI / 180.0,
                                   sqrt_information, options.prior_sigma_time_s),
      nullptr, pose, &delta);
  problem.SetParameterLowerBound(&delta, 0, -options.time_offset_bound_s);
  problem.SetParameterUpperBound(&delta, 0, options.time_offset_bound_s);
  if (!options.estimate_time_offset) problem.SetParameterBlockConstant(&delta);

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  result.iterations = static_cast<int>(summary.iterations.size());
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.usable = summary.IsSolutionUsable();
  if (!result.usable) {
    result.message = "solver: " + summary.message;
    return result;
  }
  const Eigen::Quaterniond q(pose[3], pose[0], pose[1], pose[2]);
  result.state.T_camera_lidar =
      MakeRigid(q.normalized().toRotationMatrix(), Eigen::Vector3d(pose[4], pose[5], pose[6]));
  result.state.time_offset_s = delta;

  // Covariance in the tangent space [rotation (3), translation (3)] + [δ], scaled by the residual
  // variance estimated from the final cost.
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.null_space_rank = -1;
  ceres::Covariance covariance(covariance_options);
  std::vector<const double*> blocks = {pose};
  if (options.estimate_time_offset) blocks.push_back(&delta);
  if (covariance.Compute(blocks, &problem)) {
    // Tangent coordinates → axes (roll, pitch, yaw [deg] about the LiDAR axes, x, y, z [m], δ
    // [s]). Tangent of EigenQuaternionManifold: q ⊕ δ = [cos|δ|, sin|δ|·δ/|δ|] ⊗ q, a rotation
    // of 2δ on the camera side; about the LiDAR axes that is 2·Rᵀ·δ.
    const int translation_size = options.translation == Translation::kFree          ? 3
                                 : options.translation == Translation::kAlongTravel ? 1
                                                                                    : 0;
    const int n = 3 + translation_size + (options.estimate_time_offset ? 1 : 0);
    Eigen::Matrix<double, kNumAxes, Eigen::Dynamic> J =
        Eigen::Matrix<double, kNumAxes, Eigen::Dynamic>::Zero(kNumAxes, n);
    J.block<3, 3>(0, 0) = 2.0 * (180.0 / M_PI) * result.state.T_camera_lidar.linear().transpose();
    if (translation_size == 3) J.block<3, 3>(3, 3).setIdentity();
    if (translation_size == 1) J.block<3, 1>(3, 3) = forward;
    if (options.estimate_time_offset) J(6, n - 1) = 1.0;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> C(n, n);
    if (covariance.GetCovarianceMatrixInTangentSpace(blocks, C.data())) {
      const double dof = std::max(1, result.residuals - n);
      // The residual variance from the fit, but never above the loss scale squared: far from
      // the optimum the fit is poor, and an inflated variance would call every axis
      // unobservable exactly when the estimate most needs to move (a scene that does not
      // constrain an axis shows it in C, whatever the variance).
      const double sigma2 =
          std::min(2.0 * summary.final_cost / dof, options.loss_scale_px * options.loss_scale_px);
      const Eigen::Matrix<double, kNumAxes, kNumAxes> axes = J * (sigma2 * C) * J.transpose();
      for (int k = 0; k < kNumAxes; ++k) result.std_dev[k] = std::sqrt(std::max(0.0, axes(k, k)));
      for (int a = 0; a < kNumAxes; ++a) {
        for (int b = 0; b < kNumAxes; ++b) {
          const double d = result.std_dev[a] * result.std_dev[b];
          result.correlation(a, b) = d > 0 ? axes(a, b) / d : (a == b ? 1.0 : 0.0);
        }
      }
      // The translation along the direction of travel, and δ against it.
      const double var_f = forward.transpose() * axes.block<3, 3>(3, 3) * forward;
      result.forward_std_m = std::sqrt(std::max(0.0, var_f));
      if (options.estimate_time_offset && moving) {
        const double cov_fd = forward.dot(axes.block<3, 1>(3, 6));
        const double d = result.forward_std_m * result.std_dev[6];
        result.time_forward_correlation = d > 0 ? cov_fd / d : 0.0;
      }
      result.covariance_ok = true;
    }
  }
  if (!result.covariance_ok) result.message = "covariance rank-deficient";
  const double thresholds[kNumAxes] = {
      options.observable_rotation_deg,  options.observable_rotation_deg,
      options.observable_rotation_deg,  options.observable_translation_m,
      options.observable_translation_m, options.observable_translation_m,
      options.observable_time_s};
  for (int k = 0; k < kNumAxes; ++k) {
    result.observable[k] = result.covariance_ok && result.std_dev[k] < thresholds[k];
  }
  if (!options.estimate_time_offset) result.observable[6] = false;
  if (options.translation == Translation::kHeld) {
    for (int k = 3; k < 6; ++k) result.observable[k] = false;
  }
  return result;
}

}  // namespace stcalib
