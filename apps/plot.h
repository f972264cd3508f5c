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

// One panel: lines over frame numbers with axes, ticks, a zero line and a legend.
cv::Mat PlotPanel(const std::string& title, const std::vector<double>& x,
                  const std::vector<Series>& series, int width = 900, int height = 260);

}  // namespace stcalib::cli
