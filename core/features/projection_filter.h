#pragma once

#include <Eigen/Core>
#include <vector>

namespace stcalib {

// The outlier kernel of docs/method.md §4: a projected point with no other projected point within
// `radius_px` (8 px in the paper) is dropped. Returns one flag per pixel, true = keep.
std::vector<bool> KeepNonIsolated(const std::vector<Eigen::Vector2d>& pixels, double radius_px);

}  // namespace stcalib
