#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace stcalib::cli {

struct Series {
  std::string name;
  std::vector<double> values;
  cv::Scalar colour;
};

// Spacing of round axis ticks: 1, 2 or 5 × 10^k, the smallest that divides [lo, hi] into at most
// `max_intervals` intervals (1 for an empty or invalid range).
double NiceTickStep(double lo, double hi, int max_intervals);

// One panel: lines over frame numbers with axes, ticks, a zero line and a legend.
cv::Mat PlotPanel(const std::string& title, const std::vector<double>& x,
                  const std::vector<Series>& series, int width = 900, int height = 260);

}  // namespace stcalib::cli
