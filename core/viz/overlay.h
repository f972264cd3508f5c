#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/score/projection.h"

namespace stcalib {

struct OverlayOptions {
  double min_depth_m = 3.0;   ///< depth mapped to the first colour (red) [m]
  double max_depth_m = 50.0;  ///< depth mapped to the last colour (blue) [m]
  int radius_px = 1;          ///< dot radius [px]
  double image_dim = 0.6;     ///< image brightness under the dots, 0..1
};

// The image (dimmed) with projected points drawn as dots coloured by depth, near = red,
// far = blue (log-depth scale, so both the near and the far field keep contrast).
cv::Mat RenderDepthOverlay(const cv::Mat& image_bgr, const std::vector<ProjectedPoint>& points,
                           const OverlayOptions& options = OverlayOptions());

}  // namespace stcalib
