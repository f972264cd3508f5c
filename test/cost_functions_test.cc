// Motion model Tv(δ), the edge-alignment residual and the prior: nominal values computed by hand
// and Jacobians checked against numeric differentiation (ceres::GradientChecker).
#include <ceres/manifold.h>
#include <ceres/product_manifold.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/types/calibration.h"
#include "cost_functions/calibration_prior_cost.h"
#include "cost_functions/edge_alignment_cost.h"

namespace stcalib {
namespace {

template <typename Rng>
LidarTwist RandomTwist(Rng* rng) {
  std::uniform_real_distribution<double> w(-0.6, 0.6), v(-15, 15);
  LidarTwist twist;
  twist.angular_rad_s = Eigen::Vector3d(w(*rng), w(*rng), w(*rng));
  twist.linear_m_s = Eigen::Vector3d(v(*rng), v(*rng) * 0.2, v(*rng) * 0.05);
  return twist;
}

TEST(MotionModel, PureTranslationAndPureRotation) {
  LidarTwist twist;
  twist.linear_m_s = Eigen::Vector3d(12, -0.5, 0.1);
  const Eigen::Vector3d p(10, 2, -1);
  EXPECT_LT((ApplyLidarMotion<double>(twist, 0.03, p) - (p + 0.03 * twist.linear_m_s)).norm(),
            1e-12);
  twist = LidarTwist();
  twist.angular_rad_s = Eigen::Vector3d(0, 0, 0.4);
  const Eigen::Vector3d expected = Eigen::AngleAxisd(0.4 * 0.05, Eigen::Vector3d::UnitZ()) * p;
  EXPECT_LT((ApplyLidarMotion<double>(twist, 0.05, p) - expected).norm(), 1e-12);
}

TEST(MotionModel, GroupPropertyAndLogRoundTrip) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> e(-0.12, 0.12);
  for (int trial = 0; trial < 100; ++trial) {
    const LidarTwist twist = RandomTwist(&rng);
    const double e1 = e(rng), e2 = e(rng);
    const Eigen::Vector3d p(20 * e(rng), 30 * e(rng), 5 * e(rng));
    // Exp((e1 + e2)ξ) = Exp(e1 ξ) · Exp(e2 ξ) for a constant twist.
    const Eigen::Vector3d composed =
        ApplyLidarMotion<double>(twist, e1, ApplyLidarMotion<double>(twist, e2, p));
    EXPECT_LT((ApplyLidarMotion<double>(twist, e1 + e2, p) - composed).norm(), 1e-10);
    // Log(Exp(dt ξ)) / dt = ξ.
    const LidarTwist back = ConstantVelocityTwist(LidarMotion(twist, 0.1), 0.1);
    EXPECT_LT((back.angular_rad_s - twist.angular_rad_s).norm(), 1e-9);
    EXPECT_LT((back.linear_m_s - twist.linear_m_s).norm(), 1e-9);
    // A pose function moving with this body twist gives it back.
    const LidarPoseFunction pose = [&](double t) { return LidarMotion(twist, t); };
    const LidarTwist measured = TwistFromPoses(pose, 0.3);
    EXPECT_LT((measured.linear_m_s - twist.linear_m_s).norm(), 1e-6);
  }
}

// Tangent-space Jacobian check: the analytic (or autodiff) Jacobian times the manifold's
// PlusJacobian against central differences of f(Plus(x, ±h·e_k)) — exactly the derivative the
// solver uses. Returns the worst relative error over all tangent directions.
// (ceres::GradientChecker is not used: it first requires the residuals evaluated with and
// without Jacobians to be bit-identical, and Eigen's quaternion products round the last bit
// differently for double and for Jet — a 1e-15 difference that makes it reject both functors
// and print meaningless numeric Jacobians.)
double WorstTangentJacobianError(const ceres::CostFunction& cost, double* pose, double* delta) {
  const ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>
      manifold;
  const int n = cost.num_residuals();
  std::vector<double> residual(n), j_pose(n * 7), j_delta(n);
  double* jacobians[2] = {j_pose.data(), j_delta.data()};
  const double* params[2] = {pose, delta};
  EXPECT_TRUE(cost.Evaluate(params, residual.data(), jacobians));
  double plus_jacobian[7 * 6];
  manifold.PlusJacobian(pose, plus_jacobian);
  double worst = 0;
  auto compare = [&](double analytic, double numeric) {
    worst = std::max(worst, std::abs(analytic - numeric) / std::max(1.0, std::abs(numeric)));
  };
  const double h = 1e-6;
  std::vector<double> plus(n), minus(n);
  for (int k = 0; k < 6; ++k) {
    double step[6] = {0, 0, 0, 0, 0, 0}, moved[7];
    const double* moved_params[2] = {moved, delta};
    step[k] = h;
    manifold.Plus(pose, step, moved);
    cost.Evaluate(moved_params, plus.data(), nullptr);
    step[k] = -h;
    manifold.Plus(pose, step, moved);
    cost.Evaluate(moved_params, minus.data(), nullptr);
    for (int r = 0; r < n; ++r) {
      double analytic = 0;
      for (int a = 0; a < 7; ++a) analytic += j_pose[r * 7 + a] * plus_jacobian[a * 6 + k];
      compare(analytic, (plus[r] - minus[r]) / (2 * h));
    }
  }
  const double saved = *delta;
  *delta = saved + h;
  cost.Evaluate(params, plus.data(), nullptr);
  *delta = saved - h;
  cost.Evaluate(params, minus.data(), nullptr);
  *delta = saved;
  for (int r = 0; r < n; ++r) compare(j_delta[r], (plus[r] - minus[r]) / (2 * h));
  return worst;
}

// A distance map that is a known function of the pixel, stored row-major.
struct SyntheticMap {
  SyntheticMap(int width, int height, double (*f)(double u, double v))
      : width(width), height(height), data(width * height) {
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) data[v * width + u] = static_cast<float>(f(u, v));
    }
    grid = std::make_unique<DistanceGrid>(data.data(), 0, height, 0, width);
    interpolator = std::make_unique<DistanceInterpolator>(*grid);
  }
  int width, height;
  std::vector<float> data;
  std::unique_ptr<DistanceGrid> grid;
  std::unique_ptr<DistanceInterpolator> interpolator;
};

CameraModel TestCamera() {
  CameraModel camera;
  camera.P_rect_02 << 700, 0, 600, 45, 0, 700, 180, 0.2, 0, 0, 1, 0.003;
  camera.R_rect_00 =
      Eigen::AngleAxisd(0.01, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  camera.width = 1200;
  camera.height = 360;
  return camera;
}

TEST(EdgeAlignmentCost, NominalValueByHand) {
  // A linear map D = 0.01·u + 0.02·v + 1 (bicubic interpolation reproduces it exactly).
  const SyntheticMap map(1200, 360, [](double u, double v) { return 0.01 * u + 0.02 * v + 1; });
  CameraModel camera;
  camera.P_rect_02 << 700, 0, 600, 0, 0, 700, 180, 0, 0, 0, 1, 0;
  camera.width = 1200;
  camera.height = 360;
  LidarTwist twist;
  twist.linear_m_s = Eigen::Vector3d(0, 0, 10);  // along the camera axis below (identity pose)
  // Identity extrinsic, p = (1, 0.5, 20), e = e0 + δ = −0.01 + 0.03 = 0.02 s → p' = (1, 0.5, 20.2)
  // u = 600 + 700·1/20.2, v = 180 + 700·0.5/20.2, r = √4 · D(u, v).
  const EdgeAlignmentCost cost(Eigen::Vector3d(1, 0.5, 20), 4.0, twist, -0.01, &camera,
                               map.interpolator.get(), 20.0);
  const double pose[7] = {0, 0, 0, 1, 0, 0, 0};
  const double delta = 0.03;
  double residual = 0;
  const double* params[2] = {pose, &delta};
  ASSERT_TRUE(cost.Evaluate(params, &residual, nullptr));
  const double u = 600 + 700.0 / 20.2, v = 180 + 350.0 / 20.2;
  EXPECT_NEAR(residual, 2.0 * (0.01 * u + 0.02 * v + 1), 1e-5);
  // Behind the camera: the constant cap, weighted.
  const EdgeAlignmentCost behind(Eigen::Vector3d(1, 0.5, -20), 4.0, twist, -0.01, &camera,
                                 map.interpolator.get(), 20.0);
  ASSERT_TRUE(behind.Evaluate(params, &residual, nullptr));
  EXPECT_DOUBLE_EQ(residual, 40.0);
  // ... with zero derivatives, whichever blocks are asked for.
  double j_pose[7], j_delta = 1.0;
  std::fill(j_pose, j_pose + 7, 1.0);
  double* both[2] = {j_pose, &j_delta};
  ASSERT_TRUE(behind.Evaluate(params, &residual, both));
  for (double j : j_pose) EXPECT_EQ(j, 0.0);
  EXPECT_EQ(j_delta, 0.0);
  j_delta = 1.0;
  double* delta_only[2] = {nullptr, &j_delta};
  ASSERT_TRUE(behind.Evaluate(params, &residual, delta_only));
  EXPECT_EQ(j_delta, 0.0);
  // Inside the image, only the asked-for block is written.
  std::fill(j_pose, j_pose + 7, 0.0);
  double* pose_only[2] = {j_pose, nullptr};
  ASSERT_TRUE(cost.Evaluate(params, &residual, pose_only));
  EXPECT_NE((Eigen::Map<Eigen::Matrix<double, 7, 1>>(j_pose).norm()), 0.0);
}

TEST(EdgeAlignmentCost, JacobiansMatchNumericDifferentiation) {
  const SyntheticMap map(1200, 360, [](double u, double v) {
    return 10 + 6 * std::sin(u / 37.0) * std::cos(v / 23.0) + 0.002 * (u - 600) * (v - 100) / 50;
  });
  const CameraModel camera = TestCamera();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  Eigen::Matrix3d R0;
  R0 << 0, -1, 0, 0, 0, -1, 1, 0, 0;  // LiDAR x forward → camera z
  int checked = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const LidarTwist twist = RandomTwist(&rng);
    const Eigen::Vector3d p(8 + 30 * std::abs(unit(rng)), 8 * unit(rng), 1.5 * unit(rng));
    const Rigid3d T = PerturbTcameraLidar(MakeRigid(R0, Eigen::Vector3d(0.05, -0.08, -0.27)),
                                          Eigen::Vector3d(unit(rng), unit(rng), unit(rng)),
                                          0.05 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
    // A quaternion of norm 0.75–1.25: the residual depends on the rotation only, so the ambient
    // Jacobian has no component along q (checked below) and scales with 1/|q|.
    const Eigen::Quaterniond q(T.linear());
    const double s = 1.0 + 0.25 * unit(rng);
    double pose[7] = {s * q.x(),           s * q.y(),           s * q.z(),          s * q.w(),
                      T.translation().x(), T.translation().y(), T.translation().z()};
    double delta = 0.05 * unit(rng);
    std::unique_ptr<ceres::CostFunction> cost(EdgeAlignmentCost::Create(
        p, 0.7, twist, 0.02 * unit(rng), &camera, map.interpolator.get(), 20.0));
    // Skip points that project within 3 px of the border (the residual is not smooth there).
    double residual;
    const double* params[2] = {pose, &delta};
    ASSERT_TRUE(cost->Evaluate(params, &residual, nullptr));
    if (residual == std::sqrt(0.7) * 20.0) continue;
    // Tolerance: the map is stored in float and the bicubic stencil amplifies its rounding in
    // the finite differences (≈1e-6 relative); the Jacobian itself is exact.
    EXPECT_LT(WorstTangentJacobianError(*cost, pose, &delta), 1e-4) << "trial " << trial;
    double j_pose[7], j_delta;
    double* jacobians[2] = {j_pose, &j_delta};
    ASSERT_TRUE(cost->Evaluate(params, &residual, jacobians));
    const Eigen::Map<const Eigen::Vector4d> j_q(j_pose), q_coeffs(pose);
    EXPECT_LT(std::abs(j_q.dot(q_coeffs)), 1e-9 * std::max(1.0, j_q.norm())) << "trial " << trial;
    ++checked;
  }
  EXPECT_GT(checked, 30);
}

TEST(CalibrationPriorCost, NominalValuesAndJacobians) {
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, -1, 0.4).normalized()));
  const Eigen::Vector3d t0(0.1, -0.2, 0.3);
  const double sigma_r = 0.01, sigma_t = 0.05, sigma_d = 0.002;
  std::unique_ptr<ceres::CostFunction> cost(
      CalibrationPriorCost::Create(q0, t0, 0.01, sigma_r, sigma_t, sigma_d));
  // The reference rotated by 0.02 rad about the LiDAR-side z axis, t moved by (0.05, 0, 0),
  // δ = 0.013: residuals (0, 0, 2 sin(0.01)/σ_r, 1, 0, 0, 1.5).
  const Eigen::Quaterniond q =
      q0 * Eigen::Quaterniond(Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitZ()));
  double pose[7] = {q.x(), q.y(), q.z(), q.w(), t0.x() + 0.05, t0.y(), t0.z()};
  double delta = 0.013;
  const double* params[2] = {pose, &delta};
  double r[7];
  ASSERT_TRUE(cost->Evaluate(params, r, nullptr));
  const double expected[7] = {0, 0, 2 * std::sin(0.01) / sigma_r, 1, 0, 0, 1.5};
  for (int k = 0; k < 7; ++k) EXPECT_NEAR(r[k], expected[k], 1e-9) << k;

  EXPECT_LT(WorstTangentJacobianError(*cost, pose, &delta), 1e-6);
}

}  // namespace
}  // namespace stcalib
