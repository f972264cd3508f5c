#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "core/score/projection.h"

namespace stcalib {

struct AlignmentStats {
  int projected = 0;         ///< edge points projected into the image
  int kept = 0;              ///< after the isolated-point kernel
  int aligned = 0;           ///< kept points within the threshold of an image edge
  double rate = 0;           ///< aligned / kept
  double median_distance_px = 0;
};

// Alignment rate (issue 4): the share of projected LiDAR edge points within `threshold_px` of an
// image edge, after dropping points isolated by more than `isolation_radius_px` (0 = keep all).
// `distance_raw_px` is the exact distance transform of the edge mask.
AlignmentStats MeasureAlignment(const std::vector<ProjectedPoint>& projected,
                                const cv::Mat& distance_raw_px, double threshold_px,
                                double isolation_radius_px);

}  // namespace stcalib
