// MemoizedCostFunction: repeated evaluations come from memory, changed ones are evaluated, and a
// bounded Ceres solve is the same bit for bit with fewer evaluations of the wrapped cost.
#include "cost_functions/memoized_cost.h"

#include <ceres/problem.h>
#include <ceres/sized_cost_function.h>
#include <ceres/solver.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

namespace stcalib {
namespace {
// r_i = exp(m·x_i + c) − y_i over parameter blocks m (1) and c (1), counting its evaluations.
class CountingExponentialCost final : public ceres::SizedCostFunction<8, 1, 1> {
 public:
  explicit CountingExponentialCost(int* count) : count_(count) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    ++*count_;
    for (int i = 0; i < 8; ++i) {
      const double x = 0.25 * i, y = std::exp(0.7 * x - 0.4) + 0.01 * std::sin(7.0 * i);
      const double e = std::exp(parameters[0][0] * x + parameters[1][0]);
      residuals[i] = e - y;
      if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][i] = x * e;
      if (jacobians != nullptr && jacobians[1] != nullptr) jacobians[1][i] = e;
    }
    return true;
  }

 private:
  int* count_;
};

TEST(MemoizedCostFunction, RepeatsComeFromMemoryAndChangesAreEvaluated) {
  int count = 0;
  MemoizedCostFunction memo(std::make_unique<CountingExponentialCost>(&count));
  ASSERT_EQ(memo.num_residuals(), 8);
  ASSERT_EQ(memo.parameter_block_sizes(), std::vector<int32_t>({1, 1}));
  CountingExponentialCost plain(&count);
  double m = 0.3, c = 0.1;
  const double* params[2] = {&m, &c};
  double r[8], r_plain[8], jm[8], jc[8], jm_plain[8], jc_plain[8];
  double* jac[2] = {jm, jc};
  double* jac_plain[2] = {jm_plain, jc_plain};

  ASSERT_TRUE(memo.Evaluate(params, r, nullptr));  // residuals only: evaluated
  EXPECT_EQ(memo.evaluations(), 1);
  ASSERT_TRUE(memo.Evaluate(params, r, jac));  // Jacobians not remembered: evaluated again
  EXPECT_EQ(memo.evaluations(), 2);
  ASSERT_TRUE(memo.Evaluate(params, r, nullptr));  // both remembered now
  double* only_c[2] = {nullptr, jc};
  ASSERT_TRUE(memo.Evaluate(params, r, only_c));
  ASSERT_TRUE(memo.Evaluate(params, r, jac));
  EXPECT_EQ(memo.evaluations(), 2);
  EXPECT_EQ(memo.calls(), 5);
  ASSERT_TRUE(plain.Evaluate(params, r_plain, jac_plain));
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(r[i], r_plain[i]);
    EXPECT_EQ(jm[i], jm_plain[i]);
    EXPECT_EQ(jc[i], jc_plain[i]);
  }
  c = std::nextafter(c, 1.0);  // the smallest change is a new point
  ASSERT_TRUE(memo.Evaluate(params, r, jac));
  EXPECT_EQ(memo.evaluations(), 3);
  ASSERT_TRUE(plain.Evaluate(params, r_plain, jac_plain));
  for (int i = 0; i < 8; ++i) EXPECT_EQ(r[i], r_plain[i]);
  double* only_m[2] = {jm, nullptr};  // evaluated with block m's Jacobian only ...
  m = 0.31;
  ASSERT_TRUE(memo.Evaluate(params, r, only_m));
  EXPECT_EQ(memo.evaluations(), 4);
  ASSERT_TRUE(memo.Evaluate(params, r, jac));  // ... so block c's is computed anew
  EXPECT_EQ(memo.evaluations(), 5);
}

// A bounded fit (the bound makes Ceres add its projected line search after each step): the
// memoized cost gives the same solution bit for bit with fewer evaluations of the wrapped one.
TEST(MemoizedCostFunction, BoundedSolveIsUnchangedWithFewerEvaluations) {
  auto solve = [](bool memoize, double* m, double* c, int* evaluations) {
    *m = 0.0;
    *c = 0.0;
    *evaluations = 0;
    ceres::Problem problem;
    std::unique_ptr<ceres::CostFunction> cost =
        std::make_unique<CountingExponentialCost>(evaluations);
    problem.AddResidualBlock(memoize ? new MemoizedCostFunction(std::move(cost)) : cost.release(),
                             nullptr, m, c);
    problem.SetParameterLowerBound(c, 0, -1.0);
    problem.SetParameterUpperBound(c, 0, 1.0);
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    EXPECT_TRUE(summary.IsSolutionUsable());
    return summary.final_cost;
  };
  double m_plain, c_plain, m_memo, c_memo;
  int plain = 0, memo = 0;
  const double cost_plain = solve(false, &m_plain, &c_plain, &plain);
  const double cost_memo = solve(true, &m_memo, &c_memo, &memo);
  EXPECT_EQ(m_memo, m_plain);
  EXPECT_EQ(c_memo, c_plain);
  EXPECT_EQ(cost_memo, cost_plain);
  EXPECT_NEAR(m_plain, 0.7, 0.05);  // the data's slope: a real fit, not the start
  EXPECT_LT(memo, plain);
  std::printf("wrapped cost evaluated %d times with memory, %d without\n", memo, plain);
}

}  // namespace
}  // namespace stcalib
