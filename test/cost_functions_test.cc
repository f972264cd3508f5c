// Motion model Tv(δ), the edge-alignment residual and the prior: nominal values computed by hand
// and Jacobians checked against numeric differentiation (ceres::GradientChecker).
#include <ceres/manifold.h>
#include <ceres/manifold_test_utils.h>
#include <ceres/product_manifold.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "core/refine/along_direction_manifold.h"
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
  camera.P_rect << 700, 0, 600, 45, 0, 700, 180, 0.2, 0, 0, 1, 0.003;
  camera.R_rect_00 =
      Eigen::AngleAxisd(0.01, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  camera.width = 1200;
  camera.height = 360;
  return camera;
}

// EdgeAlignmentCost of one frame's points, with the same map for both edge kinds.
EdgeAlignmentCost FrameCost(std::vector<EdgeAlignmentCost::Point> points, const LidarTwist& twist,
                            double e0_s, const CameraModel* camera, const SyntheticMap& map,
                            const ceres::LossFunction* loss = nullptr) {
  return EdgeAlignmentCost(std::move(points), twist, e0_s, camera,
                           {map.interpolator.get(), map.interpolator.get()}, 20.0, loss);
}

TEST(EdgeAlignmentCost, NominalValueByHand) {
  // A linear map D = 0.01·u + 0.02·v + 1 (bicubic interpolation reproduces it exactly).
  const SyntheticMap map(1200, 360, [](double u, double v) { return 0.01 * u + 0.02 * v + 1; });
  CameraModel camera;
  camera.P_rect << 700, 0, 600, 0, 0, 700, 180, 0, 0, 0, 1, 0;
  camera.width = 1200;
  camera.height = 360;
  LidarTwist twist;
  twist.linear_m_s = Eigen::Vector3d(0, 0, 10);  // along the camera axis below (identity pose)
  // Identity extrinsic, p = (1, 0.5, 20), e = e0 + δ = −0.01 + 0.03 = 0.02 s → p' = (1, 0.5, 20.2)
  // u = 600 + 700·1/20.2, v = 180 + 700·0.5/20.2, r = √4 · D(u, v).
  // The second point is behind the camera: the constant cap, weighted (√9 · 20).
  const EdgeAlignmentCost cost =
      FrameCost({{Eigen::Vector3d(1, 0.5, 20), 4.0, 0}, {Eigen::Vector3d(1, 0.5, -20), 9.0, 1}},
                twist, -0.01, &camera, map);
  ASSERT_EQ(cost.num_residuals(), 2);
  const double pose[7] = {0, 0, 0, 1, 0, 0, 0};
  const double delta = 0.03;
  double residuals[2];
  const double* params[2] = {pose, &delta};
  ASSERT_TRUE(cost.Evaluate(params, residuals, nullptr));
  const double u = 600 + 700.0 / 20.2, v = 180 + 350.0 / 20.2;
  const double r0 = 2.0 * (0.01 * u + 0.02 * v + 1);
  EXPECT_NEAR(residuals[0], r0, 1e-5);
  EXPECT_DOUBLE_EQ(residuals[1], 60.0);
  // ... with zero derivatives for the point behind, whichever blocks are asked for.
  double j_pose[14], j_delta[2] = {1.0, 1.0};
  std::fill(j_pose, j_pose + 14, 1.0);
  double* both[2] = {j_pose, j_delta};
  ASSERT_TRUE(cost.Evaluate(params, residuals, both));
  for (int a = 7; a < 14; ++a) EXPECT_EQ(j_pose[a], 0.0);
  EXPECT_EQ(j_delta[1], 0.0);
  // By hand: ∂r/∂δ = √4 · (0.01·∂u/∂z + 0.02·∂v/∂z) · 10 m/s, ∂u/∂z = −700·1/z², ∂v/∂z = −350/z²;
  // ∂r/∂t_x = √4 · 0.01 · 700 / z. (Relative 1e-4: the map's slopes come from float samples.)
  const double z = 20.2;
  const double dr_ddelta = 2.0 * (0.01 * -700.0 / (z * z) + 0.02 * -350.0 / (z * z)) * 10.0;
  const double dr_dtx = 2.0 * 0.01 * 700.0 / z;
  EXPECT_NEAR(j_delta[0], dr_ddelta, 1e-4 * std::abs(dr_ddelta));
  EXPECT_NEAR(j_pose[4], dr_dtx, 1e-4 * dr_dtx);
  // Only the asked-for block is written.
  j_delta[0] = j_delta[1] = 7.0;
  double* pose_only[2] = {j_pose, nullptr};
  ASSERT_TRUE(cost.Evaluate(params, residuals, pose_only));
  EXPECT_EQ(j_delta[0], 7.0);
  EXPECT_NE((Eigen::Map<Eigen::Matrix<double, 7, 1>>(j_pose).norm()), 0.0);

  // The loss per point: Cauchy with scale c, ρ(s) = c²·log(1 + s/c²), ρ'(s) = 1 / (1 + s/c²).
  // Residuals √ρ'(s_i)·r_i and one more, √Σ(ρ(s_i) − ρ'(s_i)·s_i), so that ½Σr̃² = ½Σρ(s_i).
  const ceres::CauchyLoss cauchy(1.5);
  const EdgeAlignmentCost robust =
      FrameCost({{Eigen::Vector3d(1, 0.5, 20), 4.0, 0}, {Eigen::Vector3d(1, 0.5, -20), 9.0, 1}},
                twist, -0.01, &camera, map, &cauchy);
  ASSERT_EQ(robust.num_residuals(), 3);
  auto rho = [](double s) { return 2.25 * std::log(1 + s / 2.25); };
  auto rho_prime = [](double s) { return 1 / (1 + s / 2.25); };
  double robust_residuals[3], j_robust[21], jd_robust[3];
  double* robust_jacobians[2] = {j_robust, jd_robust};
  ASSERT_TRUE(robust.Evaluate(params, robust_residuals, robust_jacobians));
  const double s0 = r0 * r0, s1 = 3600.0;
  EXPECT_NEAR(robust_residuals[0], std::sqrt(rho_prime(s0)) * r0, 1e-6);
  EXPECT_NEAR(robust_residuals[1], std::sqrt(rho_prime(s1)) * 60.0, 1e-9);
  EXPECT_NEAR(robust_residuals[2],
              std::sqrt(rho(s0) - rho_prime(s0) * s0 + rho(s1) - rho_prime(s1) * s1), 1e-6);
  double cost_value = 0;
  for (double r : robust_residuals) cost_value += 0.5 * r * r;
  EXPECT_NEAR(cost_value, 0.5 * (rho(s0) + rho(s1)), 1e-6);
  EXPECT_NEAR(j_robust[4], std::sqrt(rho_prime(s0)) * dr_dtx, 1e-4 * dr_dtx);
  for (int a = 14; a < 21; ++a) EXPECT_EQ(j_robust[a], 0.0);
  EXPECT_EQ(jd_robust[2], 0.0);
}

// ½Σr̃² of a cost at (pose, δ).
double HalfSquaredNorm(const ceres::CostFunction& cost, const double* pose, const double* delta) {
  std::vector<double> r(cost.num_residuals());
  const double* params[2] = {pose, delta};
  EXPECT_TRUE(cost.Evaluate(params, r.data(), nullptr));
  double sum = 0;
  for (double x : r) sum += 0.5 * x * x;
  return sum;
}

TEST(EdgeAlignmentCost, JacobiansMatchNumericDifferentiation) {
  const SyntheticMap map(1200, 360, [](double u, double v) {
    return 10 + 6 * std::sin(u / 37.0) * std::cos(v / 23.0) + 0.002 * (u - 600) * (v - 100) / 50;
  });
  // The other edge kind reads a different map.
  const SyntheticMap other(1200, 360, [](double u, double v) {
    return 8 + 5 * std::cos(u / 29.0 + v / 41.0) + 0.001 * (u - 300);
  });
  const CameraModel camera = TestCamera();
  const ceres::CauchyLoss cauchy(1.0);
  const ceres::HuberLoss huber(2.0);
  const ceres::TukeyLoss tukey(8.0);  // redescending: some points beyond its support (ρ' = 0)
  const ceres::LossFunction* losses[3] = {&cauchy, &huber, &tukey};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  const Eigen::Matrix3d R0 = NominalRcameraLidar();  // LiDAR x forward → camera z
  int checked = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const LidarTwist twist = RandomTwist(&rng);
    // Points that project within 3 px of the border are left out (the residual is not smooth
    // there); ahead of the camera they land inside.
    std::vector<EdgeAlignmentCost::Point> points;
    for (int k = 0; k < 5; ++k) {
      const Eigen::Vector3d p(8 + 30 * std::abs(unit(rng)), 4 * unit(rng), 1.0 * unit(rng));
      points.push_back({p, 0.2 + std::abs(unit(rng)), k % 2});
    }
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
    const double e0_s = 0.02 * unit(rng);
    const std::array<const DistanceInterpolator*, 2> maps = {map.interpolator.get(),
                                                             other.interpolator.get()};
    const EdgeAlignmentCost plain(points, twist, e0_s, &camera, maps, 20.0, nullptr);
    // Tolerance: the map is stored in float and the bicubic stencil amplifies its rounding in
    // the finite differences (≈1e-6 relative); the Jacobian itself is exact.
    EXPECT_LT(WorstTangentJacobianError(plain, pose, &delta), 1e-4) << "trial " << trial;
    const size_t n = points.size();
    std::vector<double> r_plain(n), j_plain(7 * n), jd_plain(n);
    double* plain_jacobians[2] = {j_plain.data(), jd_plain.data()};
    const double* params[2] = {pose, &delta};
    ASSERT_TRUE(plain.Evaluate(params, r_plain.data(), plain_jacobians));
    const Eigen::Map<const Eigen::Vector4d> q_coeffs(pose);
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Map<const Eigen::Vector4d> j_q(j_plain.data() + 7 * i);
      EXPECT_LT(std::abs(j_q.dot(q_coeffs)), 1e-9 * std::max(1.0, j_q.norm())) << "trial " << trial;
      checked += j_q.norm() > 0;
    }
    // Under a loss: √ρ'(r²) times the plain rows, and J̃ᵀr̃ is the gradient of the cost
    // ½Σρ(r_i²) (central differences in the tangent space).
    const ceres::LossFunction* loss = losses[trial % 3];
    const EdgeAlignmentCost robust(points, twist, e0_s, &camera, maps, 20.0, loss);
    ASSERT_EQ(robust.num_residuals(), static_cast<int>(n + 1));
    std::vector<double> r(n + 1), j_pose(7 * (n + 1)), j_delta(n + 1);
    double* jacobians[2] = {j_pose.data(), j_delta.data()};
    ASSERT_TRUE(robust.Evaluate(params, r.data(), jacobians));
    double expected_cost = 0;
    Eigen::Matrix<double, 8, 1> gradient = Eigen::Matrix<double, 8, 1>::Zero();  // ambient pose, δ
    for (size_t i = 0; i < n; ++i) {
      double rho[3];
      loss->Evaluate(r_plain[i] * r_plain[i], rho);
      expected_cost += 0.5 * rho[0];
      const double w = std::sqrt(rho[1]);
      EXPECT_NEAR(r[i], w * r_plain[i], 1e-12 * r_plain[i]);
      EXPECT_NEAR(j_delta[i], w * jd_plain[i], 1e-12 * std::max(1.0, std::abs(jd_plain[i])));
      for (int a = 0; a < 7; ++a) {
        EXPECT_NEAR(j_pose[7 * i + a], w * j_plain[7 * i + a],
                    1e-12 * std::max(1.0, std::abs(j_plain[7 * i + a])));
      }
    }
    EXPECT_NEAR(HalfSquaredNorm(robust, pose, &delta), expected_cost, 1e-9 * expected_cost);
    for (size_t i = 0; i <= n; ++i) {
      for (int a = 0; a < 7; ++a) gradient[a] += j_pose[7 * i + a] * r[i];
      gradient[7] += j_delta[i] * r[i];
    }
    const ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>
        manifold;
    double plus_jacobian[7 * 6];
    manifold.PlusJacobian(pose, plus_jacobian);
    const double h = 1e-6;
    for (int k = 0; k < 7; ++k) {
      double numeric;
      if (k < 6) {
        double step[6] = {0, 0, 0, 0, 0, 0}, plus[7], minus[7];
        step[k] = h;
        manifold.Plus(pose, step, plus);
        step[k] = -h;
        manifold.Plus(pose, step, minus);
        numeric = (HalfSquaredNorm(robust, plus, &delta) - HalfSquaredNorm(robust, minus, &delta)) /
                  (2 * h);
      } else {
        double up = delta + h, down = delta - h;
        numeric =
            (HalfSquaredNorm(robust, pose, &up) - HalfSquaredNorm(robust, pose, &down)) / (2 * h);
      }
      double analytic = gradient[7];
      if (k < 6) {
        analytic = 0;
        for (int a = 0; a < 7; ++a) analytic += gradient[a] * plus_jacobian[a * 6 + k];
      }
      EXPECT_NEAR(analytic, numeric, 1e-4 * std::max(1.0, std::abs(numeric)))
          << "trial " << trial << " tangent " << k;
    }
  }
  EXPECT_GT(checked, 150);
}

// The translation that moves only along the direction of travel (the polish, RefineOptions::
// Translation::kAlongTravel): Ceres' manifold invariants (Plus/Minus inverse on the line,
// Jacobians against numeric differentiation), and Plus moves along d only.
TEST(AlongDirectionManifold, InvariantsHoldAndPlusMovesAlongTheDirection) {
  using namespace ceres;  // the invariant macro names its matchers unqualified
  const Eigen::Vector3d d = Eigen::Vector3d(0.1, -0.05, 2.0);  // not unit: normalised inside
  const AlongDirectionManifold manifold(d);
  EXPECT_EQ(manifold.AmbientSize(), 3);
  EXPECT_EQ(manifold.TangentSize(), 1);
  EXPECT_NEAR(manifold.direction().norm(), 1.0, 1e-15);
  Vector x(3), delta(1), y(3);
  x << 0.06, -0.08, -0.27;
  delta << 0.043;
  y = x + 0.021 * d.normalized();
  EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, 1e-9);
  Eigen::Vector3d moved;
  ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), moved.data()));
  EXPECT_LT((moved - x).cross(d).norm(), 1e-15);
  EXPECT_NEAR((moved - x).norm(), 0.043, 1e-15);
  // Minus of a point off the line: the component along d.
  const Eigen::Vector3d off = x + Eigen::Vector3d(0.3, 0.2, 0.1);
  double along = 0;
  ASSERT_TRUE(manifold.Minus(off.data(), x.data(), &along));
  EXPECT_NEAR(along, d.normalized().dot(Eigen::Vector3d(0.3, 0.2, 0.1)), 1e-15);
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
