#pragma once

#include <Eigen/Core>
#include <random>
#include <vector>

namespace stcalib::sim {

// The road centreline of a simulated drive (the middle of the ego lane), parametrised by arc
// length s [m] in the world x/y plane: alternating straights and constant-curvature turns joined
// by smooth curvature ramps.
class SimRoad {
 public:
  // `with_turns` false gives a straight road. The first turn starts 5–25 m after s = 0 so that a
  // short drive already contains one.
  static SimRoad Generate(double s_begin_m, double s_end_m, bool with_turns, std::mt19937_64* rng);

  Eigen::Vector2d Position(double s_m) const;
  double Heading(double s_m) const;    ///< [rad], counter-clockwise from world x
  double Curvature(double s_m) const;  ///< [1/m], positive turning left
  // The point at arc length s and lateral offset (left positive) from the centreline.
  Eigen::Vector2d At(double s_m, double lateral_m) const;
  double s_begin() const { return s_begin_; }
  double s_end() const { return s_begin_ + ds_ * (x_.size() - 1); }

 private:
  double Interpolate(const std::vector<double>& values, double s_m) const;

  double s_begin_ = 0;
  double ds_ = 0.05;  ///< sample spacing [m]
  std::vector<double> x_, y_, heading_, curvature_;
};

}  // namespace stcalib::sim
