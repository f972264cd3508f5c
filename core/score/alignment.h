#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/features/lidar_edges.h"
#include "core/score/projection.h"

namespace stcalib {

struct AlignmentStats {
  int projected = 0;  ///< edge points projected into the image
  int kept = 0;       ///< after the isolated-point kernel
  int aligned = 0;    ///< kept points within the threshold of an image edge
  double rate = 0;    ///< aligned / kept
  double median_distance_px = 0;
};

// Alignment rate (issue 4): the share of projected LiDAR edge points within `threshold_px` of an
// image edge, after dropping points isolated by more than `isolation_radius_px` (0 = keep all).
// `distance_raw_px` is the exact distance transform of the edge mask.
AlignmentStats MeasureAlignment(const std::vector<ProjectedPoint>& projected,
                                const cv::Mat& distance_raw_px, double threshold_px,
                                double isolation_radius_px);

// Orientation-aware rate: a projected point whose source edge (projected[i].index into `kinds`)
// is vertical reads the distance to near-vertical image edges, a horizontal one the distance to
// near-horizontal image edges (ImageFeatures::distance_{vertical,horizontal}_raw_px). Dense
// texture has edges of every orientation nearby; structure has the right one.
AlignmentStats MeasureOrientedAlignment(const std::vector<ProjectedPoint>& projected,
                                        const std::vector<EdgeKind>& kinds,
                                        const cv::Mat& distance_vertical_raw_px,
                                        const cv::Mat& distance_horizontal_raw_px,
                                        double threshold_px, double isolation_radius_px);

}  // namespace stcalib
