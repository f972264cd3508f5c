// Axis ticks of the CLI's plots (apps/plot.h): round steps, and a panel drawn for any data.
#include "apps/plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace stcalib::cli {
namespace {

TEST(Plot, TickStepsAreRoundAndFitTheRange) {
  // The rotation panel of a KITTI run: −2.34..5.05° (it used to print 3.21, 1.36, −0.489 …).
  EXPECT_DOUBLE_EQ(NiceTickStep(-2.34, 5.05, 5), 2.0);
  EXPECT_DOUBLE_EQ(NiceTickStep(0, 6.46, 5), 2.0);
  EXPECT_DOUBLE_EQ(NiceTickStep(0, 0.31, 5), 0.1);
  EXPECT_DOUBLE_EQ(NiceTickStep(0, 30, 8), 5.0);
  EXPECT_DOUBLE_EQ(NiceTickStep(0, 10, 5), 2.0);  // exactly five intervals
  for (double span : {0.0137, 0.9, 3.3, 47.0, 1234.0}) {
    const double step = NiceTickStep(-span / 3, span, 5);
    const double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
    EXPECT_TRUE(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 ||
                std::abs(mantissa - 5) < 1e-9)
        << span << ": " << step;
    EXPECT_LE(std::ceil(span / step + 1e-9) + std::ceil(span / 3 / step + 1e-9), 6) << span;
  }
  EXPECT_DOUBLE_EQ(NiceTickStep(1, 1, 5), 1.0);
  EXPECT_DOUBLE_EQ(NiceTickStep(0, std::numeric_limits<double>::quiet_NaN(), 5), 1.0);
}

TEST(Plot, PanelDrawsAnyData) {
  const std::vector<double> x = {0, 1, 2};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const std::vector<double>& values :
       {std::vector<double>{0.2, -1.5, 3.0}, std::vector<double>{0, 0, 0},
        std::vector<double>{nan, nan, nan}, std::vector<double>{1e-4, 2e-4, 3e-4}}) {
    const cv::Mat panel = PlotPanel("t", x, {{"s", values, cv::Scalar(0, 0, 255)}}, 300, 120);
    EXPECT_EQ(panel.rows, 120);
    EXPECT_EQ(panel.cols, 300);
  }
}

}  // namespace
}  // namespace stcalib::cli
