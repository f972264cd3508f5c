#pragma once

#include <ceres/cost_function.h>
#include <glog/logging.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

namespace stcalib {

// A cost function that remembers its last evaluation and answers a repeated one from memory.
//
// Why: with a bounded parameter (δ), Ceres' trust-region minimizer follows every step by a
// projected Armijo line search, and an accepted step of length one is then evaluated three times
// at the same point: by the line search (residuals and Jacobians), as the candidate (residuals)
// and, once accepted, for the next iteration (residuals and Jacobians); the covariance evaluates
// the final point once more. The wrapped function is pure, so the repeats return exactly what it
// would return: the solve is the same bit for bit, at a fraction of the evaluations.
//
// A call is answered from memory when every parameter has the remembered one's bits and every
// Jacobian it asks for was computed then. Otherwise the wrapped function is evaluated (with the
// Jacobians asked for) and remembered, when it succeeds. Not for concurrent use: Refine solves with
// one thread.
class MemoizedCostFunction final : public ceres::CostFunction {
 public:
  explicit MemoizedCostFunction(std::unique_ptr<ceres::CostFunction> cost)
      : cost_(std::move(cost)) {
    CHECK(cost_ != nullptr);
    set_num_residuals(cost_->num_residuals());
    *mutable_parameter_block_sizes() = cost_->parameter_block_sizes();
    size_t total = 0;
    for (int32_t size : parameter_block_sizes()) total += static_cast<size_t>(size);
    parameters_.resize(total);
    residuals_.resize(static_cast<size_t>(num_residuals()));
    jacobians_.resize(parameter_block_sizes().size());
    have_jacobian_.assign(parameter_block_sizes().size(), 0);
    into_.assign(parameter_block_sizes().size(), nullptr);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    const size_t rows = static_cast<size_t>(num_residuals());
    bool hit = valid_;
    for (size_t b = 0, offset = 0; hit && b < sizes.size(); offset += sizes[b], ++b) {
      hit = std::memcmp(parameters[b], parameters_.data() + offset, sizes[b] * sizeof(double)) == 0;
    }
    for (size_t b = 0; hit && jacobians != nullptr && b < sizes.size(); ++b) {
      hit = jacobians[b] == nullptr || have_jacobian_[b];
    }
    ++calls_;
    if (!hit) {
      ++evaluations_;
      std::fill(into_.begin(), into_.end(), nullptr);
      for (size_t b = 0; jacobians != nullptr && b < sizes.size(); ++b) {
        if (jacobians[b] == nullptr) continue;
        jacobians_[b].resize(rows * static_cast<size_t>(sizes[b]));
        into_[b] = jacobians_[b].data();
      }
      valid_ = cost_->Evaluate(parameters, residuals_.data(),
                               jacobians != nullptr ? into_.data() : nullptr);
      if (!valid_) return false;
      for (size_t b = 0, offset = 0; b < sizes.size(); offset += sizes[b], ++b) {
        std::copy(parameters[b], parameters[b] + sizes[b], parameters_.begin() + offset);
        have_jacobian_[b] = into_[b] != nullptr;
      }
    }
    std::copy(residuals_.begin(), residuals_.end(), residuals);
    for (size_t b = 0; jacobians != nullptr && b < sizes.size(); ++b) {
      if (jacobians[b] != nullptr) {
        std::copy(jacobians_[b].begin(), jacobians_[b].end(), jacobians[b]);
      }
    }
    return true;
  }

  int calls() const { return calls_; }              ///< Evaluate calls so far
  int evaluations() const { return evaluations_; }  ///< of them, evaluations of the wrapped cost

 private:
  const std::unique_ptr<ceres::CostFunction> cost_;
  // The remembered evaluation.
  mutable bool valid_ = false;
  mutable std::vector<double> parameters_;  // all blocks, concatenated
  mutable std::vector<double> residuals_;
  mutable std::vector<std::vector<double>> jacobians_;  // row-major, per block
  mutable std::vector<uint8_t> have_jacobian_;
  mutable std::vector<double*> into_;  // where a miss writes its Jacobians (no allocation per call)
  mutable int calls_ = 0, evaluations_ = 0;
};

}  // namespace stcalib
