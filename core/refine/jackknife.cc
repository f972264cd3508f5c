#include "core/refine/jackknife.h"

#include <algorithm>

namespace stcalib {

RefineJackknife JackknifeRefine(const std::vector<const CalibrationFrame*>& frames,
                                const CalibrationState& estimate,
                                const CalibrationState& mount_prior, const RefineOptions& options,
                                int block_frames, int min_frames) {
  RefineJackknife result;
  const int n = static_cast<int>(frames.size());
  const int blocks = n / std::max(block_frames, 1);
  if (n < min_frames || blocks < 2) return result;
  result.frames = n;
  result.blocks = blocks;
  std::vector<Eigen::Matrix<double, kNumAxes, 1>> estimates;
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
    estimates.push_back(AxisOffsets(refined.state, estimate));
  }
  result.std = JackknifeStd<kNumAxes>(estimates);
  return result;
}

RefineJackknife JackknifeRotation(const std::vector<const CalibrationFrame*>& frames,
                                  const CalibrationState& estimate,
                                  const CalibrationState& mount_prior, RefineOptions options,
                                  int block_frames, int min_frames) {
  options.translation = RefineOptions::Translation::kHeld;
  options.estimate_time_offset = false;
  return JackknifeRefine(frames, estimate, mount_prior, options, block_frames, min_frames);
}

}  // namespace stcalib
