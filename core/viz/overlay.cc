#include "core/viz/overlay.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace stcalib {

cv::Mat RenderDepthOverlay(const cv::Mat& image_bgr, const std::vector<ProjectedPoint>& points,
                           const OverlayOptions& options) {
  cv::Mat canvas;
  if (image_bgr.channels() == 1) {
    cv::cvtColor(image_bgr, canvas, cv::COLOR_GRAY2BGR);
  } else {
    canvas = image_bgr.clone();
  }
  canvas.convertTo(canvas, CV_8UC3, options.image_dim);

  // Jet colour map looked up once: index 0 = blue (far) .. 255 = red (near).
  cv::Mat ramp(1, 256, CV_8UC1);
  for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(0, i) = static_cast<uint8_t>(i);
  cv::Mat colours;
  cv::applyColorMap(ramp, colours, cv::COLORMAP_JET);

  const double log_range = std::log(options.max_depth_m / options.min_depth_m);
  // Far points first so near ones stay on top.
  std::vector<const ProjectedPoint*> order;
  order.reserve(points.size());
  for (const ProjectedPoint& p : points) order.push_back(&p);
  std::sort(order.begin(), order.end(), [](const ProjectedPoint* a, const ProjectedPoint* b) {
    return a->depth_m > b->depth_m;
  });
  for (const ProjectedPoint* p : order) {
    const double s = std::clamp(
        std::log(options.max_depth_m / std::max(p->depth_m, 1e-3)) / log_range, 0.0, 1.0);
    const cv::Vec3b c = colours.at<cv::Vec3b>(0, static_cast<int>(std::lround(s * 255.0)));
    cv::circle(canvas,
               cv::Point(static_cast<int>(std::lround(p->pixel.x())),
                         static_cast<int>(std::lround(p->pixel.y()))),
               options.radius_px, cv::Scalar(c[0], c[1], c[2]), cv::FILLED, cv::LINE_8);
  }
  return canvas;
}

}  // namespace stcalib
