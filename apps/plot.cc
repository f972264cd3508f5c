#include "apps/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace stcalib::cli {

double NiceTickStep(double lo, double hi, int max_intervals) {
  const double span = hi - lo;
  if (!(span > 0) || !std::isfinite(span) || max_intervals < 1) return 1.0;
  const double raw = span / max_intervals;
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * decade >= raw * (1 - 1e-9)) return m * decade;
  }
  return 10.0 * decade;
}

namespace {

// Decimals that print every multiple of `step` exactly (step 0.25 → 2, 5 → 0).
int TickDecimals(double step) {
  for (int d = 0; d < 6; ++d) {
    const double scaled = step * std::pow(10.0, d);
    if (std::abs(scaled - std::round(scaled)) < 1e-6 * std::max(1.0, scaled)) return d;
  }
  return 6;
}

}  // namespace

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
  // Round ticks, the range (with a little room, so no line runs along the frame; none below a
  // series that never goes negative) widened to whole steps.
  const double pad = 0.02 * (y_max - y_min);
  if (y_min < 0) y_min -= pad;
  if (y_max > 0) y_max += pad;
  const double y_step = NiceTickStep(y_min, y_max, 6);
  y_min = std::floor(y_min / y_step) * y_step;
  y_max = std::ceil(y_max / y_step) * y_step;
  const double x_min = x.empty() ? 0 : x.front(),
               x_max = x.empty() ? 1 : std::max(x.back(), x_min + 1);
  const double x_step = std::max(1.0, NiceTickStep(x_min, x_max, 8));
  auto px = [&](double xv, double yv) {
    return cv::Point(
        left + static_cast<int>((xv - x_min) / (x_max - x_min) * (width - left - right)),
        top + static_cast<int>((y_max - yv) / (y_max - y_min) * (height - top - bottom)));
  };
  cv::rectangle(canvas, cv::Point(left, top), cv::Point(width - right, height - bottom),
                cv::Scalar(0, 0, 0), 1);
  char label[64];
  const int y_decimals = TickDecimals(y_step);
  const int y_ticks = static_cast<int>(std::lround((y_max - y_min) / y_step));
  for (int k = 0; k <= y_ticks; ++k) {
    const double yv = y_min + k * y_step;
    if (k > 0 && k < y_ticks) {
      cv::line(canvas, px(x_min, yv), px(x_max, yv), cv::Scalar(225, 225, 225), 1);
    }
    std::snprintf(label, sizeof(label), "%.*f", y_decimals, std::abs(yv) < 1e-12 ? 0.0 : yv);
    cv::putText(canvas, label, cv::Point(5, px(x_min, yv).y + 4), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  cv::line(canvas, px(x_min, 0), px(x_max, 0), cv::Scalar(160, 160, 160), 1);
  for (double xv = std::ceil(x_min / x_step) * x_step; xv <= x_max + 1e-9; xv += x_step) {
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
