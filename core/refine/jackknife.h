#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/refine/refine.h"

namespace stcalib {

// How far a window's own data lets the estimate move (docs/method.md §7): neighbouring edge points
// of one edge are not independent measurements, so the refinement's covariance, which treats them
// as such, is optimistic. A jackknife over the window's frames measures the spread instead: each
// block of frames left out in turn, the estimate is refined again, and the spread of those
// estimates gives each axis its standard deviation.

// The jackknife standard deviation of `leave_one_out` (one estimate per block left out, n ≥ 2):
// sqrt((n − 1) / n · Σ (θ_i − θ̄)²) per component; zero for fewer than 2.
template <int N>
Eigen::Matrix<double, N, 1> JackknifeStd(
    const std::vector<Eigen::Matrix<double, N, 1>>& leave_one_out) {
  const size_t n = leave_one_out.size();
  Eigen::Matrix<double, N, 1> sum = Eigen::Matrix<double, N, 1>::Zero();
  if (n < 2) return sum;
  Eigen::Matrix<double, N, 1> mean = Eigen::Matrix<double, N, 1>::Zero();
  for (const auto& v : leave_one_out) mean += v;
  mean /= static_cast<double>(n);
  for (const auto& v : leave_one_out) sum += (v - mean).cwiseAbs2();
  return (sum * (static_cast<double>(n - 1) / static_cast<double>(n))).cwiseSqrt();
}

struct RefineJackknife {
  int frames = 0;  ///< frames in the window (0: too few to leave one out, nothing measured)
  int blocks = 0;  ///< blocks of contiguous frames left out in turn
  // Per axis, in result order and units (kAxisNames: deg, m, s); zero on the axes `options`
  // holds.
  Eigen::Matrix<double, kNumAxes, 1> std = Eigen::Matrix<double, kNumAxes, 1>::Zero();
  // Leave-one-out refinements that failed (they are left out of the spread).
  int failed = 0;
};

// The delete-a-block jackknife of Refine over `frames` (at least `min_frames` and two blocks, else
// nothing is measured): the frames are cut into n / block_frames contiguous blocks, each left out
// in turn (frames share sweeps through their local maps and scenery over seconds, so single frames
// are not independent); each refinement starts at `estimate` with the rotation prior there and
// `mount_prior` for the translation and δ, and frees the axes `options` frees.
RefineJackknife JackknifeRefine(const std::vector<const CalibrationFrame*>& frames,
                                const CalibrationState& estimate,
                                const CalibrationState& mount_prior, const RefineOptions& options,
                                int block_frames, int min_frames = 4);

// The rotation's jackknife: JackknifeRefine with the translation and δ held.
RefineJackknife JackknifeRotation(const std::vector<const CalibrationFrame*>& frames,
                                  const CalibrationState& estimate,
                                  const CalibrationState& mount_prior, RefineOptions options,
                                  int block_frames, int min_frames = 4);

}  // namespace stcalib
