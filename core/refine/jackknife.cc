#include "core/refine/jackknife.h"

#include <cmath>

#include "core/types/calibration.h"
#include "core/types/transform.h"

namespace stcalib {

Eigen::Vector3d JackknifeStd(const std::vector<Eigen::Vector3d>& leave_one_out) {
  const size_t n = leave_one_out.size();
  if (n < 2) return Eigen::Vector3d::Zero();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : leave_one_out) mean += v;
  mean /= static_cast<double>(n);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : leave_one_out) sum += (v - mean).cwiseAbs2();
  return (sum * (static_cast<double>(n - 1) / static_cast<double>(n))).cwiseSqrt();
}

RotationJackknife JackknifeRotation(const std::vector<const CalibrationFrame*>& frames,
                                    const CalibrationState& estimate,
                                    const CalibrationState& mount_prior, RefineOptions options,
                                    int block_frames, int min_frames) {
  RotationJackknife result;
  const int n = static_cast<int>(frames.size());
  const int blocks = n / std::max(block_frames, 1);
  if (n < min_frames || blocks < 2) return result;
  result.frames = n;
  result.blocks = blocks;
  options.translation = RefineOptions::Translation::kHeld;
  options.estimate_time_offset = false;
  std::vector<Eigen::Vector3d> rotations;
  for (int out = 0; out < blocks; ++out) {
    // Block `out` is frames [n·out/blocks, n·(out+1)/blocks): contiguous, as even as n allows.
    const int first = n * out / blocks, end = n * (out + 1) / blocks;
    std::vector<const CalibrationFrame*> kept;
    for (int k = 0; k < n; ++k) {
      if (k < first || k >= end) kept.push_back(frames[k]);
    }
    const RefineResult refined = Refine(kept, estimate, estimate, mount_prior, options);
    if (!refined.usable) {
      ++result.failed;
      continue;
    }
    rotations.push_back(LogSO3(estimate.T_camera_lidar.linear().transpose() *
                               refined.state.T_camera_lidar.linear()));
  }
  result.std_deg = JackknifeStd(rotations) * (180.0 / M_PI);
  return result;
}

}  // namespace stcalib
