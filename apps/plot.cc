#include "apps/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace stcalib::cli {

cv::Mat PlotPanel(const std::string& title, const std::vector<double>& x,
                  const std::vector<Series>& series, int width, int height) {
  cv::Mat canvas(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 70, right = 20, top = 30, bottom = 35;
  double y_min = 0, y_max = 0;
  for (const Series& s : series) {
    for (double v : s.values) {
      if (!std::isfinite(v)) continue;
      y_min = std::min(y_min, v);
      y_max = std::max(y_max, v);
    }
  }
  if (y_max - y_min < 1e-9) y_max = y_min + 1;
  const double pad = 0.05 * (y_max - y_min);
  y_min -= pad;
  y_max += pad;
  const double x_min = x.empty() ? 0 : x.front(),
               x_max = x.empty() ? 1 : std::max(x.back(), x_min + 1);
  auto px = [&](double xv, double yv) {
    return cv::Point(
        left + static_cast<int>((xv - x_min) / (x_max - x_min) * (width - left - right)),
        top + static_cast<int>((y_max - yv) / (y_max - y_min) * (height - top - bottom)));
  };
  cv::rectangle(canvas, cv::Point(left, top), cv::Point(width - right, height - bottom),
                cv::Scalar(0, 0, 0), 1);
  cv::line(canvas, px(x_min, 0), px(x_max, 0), cv::Scalar(160, 160, 160), 1);
  char label[64];
  for (int k = 0; k <= 4; ++k) {
    const double yv = y_min + (y_max - y_min) * k / 4;
    std::snprintf(label, sizeof(label), "%.3g", yv);
    cv::putText(canvas, label, cv::Point(5, px(x_min, yv).y + 4), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  for (int k = 0; k <= 5; ++k) {
    const double xv = x_min + (x_max - x_min) * k / 5;
    std::snprintf(label, sizeof(label), "%.0f", xv);
    cv::putText(canvas, label, cv::Point(px(xv, y_min).x - 8, height - bottom + 16),
                cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  cv::putText(canvas, title, cv::Point(left, 20), cv::FONT_HERSHEY_SIMPLEX, 0.55,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(canvas, "frame", cv::Point(width / 2, height - 4), cv::FONT_HERSHEY_SIMPLEX, 0.4,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  int legend_x = width - right - 10;
  for (auto it = series.rbegin(); it != series.rend(); ++it) {
    const Series& s = *it;
    for (size_t i = 1; i < s.values.size() && i < x.size(); ++i) {
      if (!std::isfinite(s.values[i - 1]) || !std::isfinite(s.values[i])) continue;
      cv::line(canvas, px(x[i - 1], s.values[i - 1]), px(x[i], s.values[i]), s.colour, 2,
               cv::LINE_AA);
    }
    int baseline = 0;
    const cv::Size size = cv::getTextSize(s.name, cv::FONT_HERSHEY_SIMPLEX, 0.45, 1, &baseline);
    legend_x -= size.width + 30;
    cv::line(canvas, cv::Point(legend_x, 16), cv::Point(legend_x + 20, 16), s.colour, 2);
    cv::putText(canvas, s.name, cv::Point(legend_x + 24, 20), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                s.colour, 1, cv::LINE_AA);
  }
  return canvas;
}

}  // namespace stcalib::cli
