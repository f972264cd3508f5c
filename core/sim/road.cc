#include "core/sim/road.h"

#include <algorithm>
#include <cmath>

namespace stcalib::sim {

SimRoad SimRoad::Generate(double s_begin_m, double s_end_m, bool with_turns, std::mt19937_64* rng) {
  SimRoad road;
  road.s_begin_ = s_begin_m;
  const int n = static_cast<int>(std::ceil((s_end_m - s_begin_m) / road.ds_)) + 1;

  // Turns as (start, length, curvature); ramps of 8 m blend curvature in and out (cosine).
  struct Turn {
    double start, length, curvature;
  };
  std::vector<Turn> turns;
  if (with_turns) {
    std::uniform_real_distribution<double> first(5.0, 25.0), straight(20.0, 60.0),
        turn_length(15.0, 35.0), radius(35.0, 80.0), sign(-1.0, 1.0);
    double s = first(*rng);
    while (s < s_end_m) {
      const double length = turn_length(*rng);
      const double k = (sign(*rng) < 0 ? -1.0 : 1.0) / radius(*rng);
      turns.push_back({s, length, k});
      s += length + straight(*rng);
    }
  }
  constexpr double kRamp = 8.0;
  auto curvature_at = [&](double s) {
    double k = 0;
    for (const Turn& t : turns) {
      const double a = s - t.start, b = t.start + t.length - s;
      if (a <= 0 || b <= 0) continue;
      const double w = std::min({1.0, a / kRamp, b / kRamp});
      k += t.curvature * 0.5 * (1 - std::cos(M_PI * w));
    }
    return k;
  };

  road.x_.resize(n);
  road.y_.resize(n);
  road.heading_.resize(n);
  road.curvature_.resize(n);
  // Integrate from s = 0 (origin, heading 0) both ways so that the drive starts at the origin.
  const int zero = std::clamp(static_cast<int>(std::lround(-s_begin_m / road.ds_)), 0, n - 1);
  for (int i = 0; i < n; ++i) road.curvature_[i] = curvature_at(s_begin_m + i * road.ds_);
  road.x_[zero] = road.y_[zero] = road.heading_[zero] = 0.0;
  for (int i = zero + 1; i < n; ++i) {
    const double h0 = road.heading_[i - 1];
    const double h1 = h0 + 0.5 * (road.curvature_[i - 1] + road.curvature_[i]) * road.ds_;
    const double hm = 0.5 * (h0 + h1);
    road.heading_[i] = h1;
    road.x_[i] = road.x_[i - 1] + road.ds_ * std::cos(hm);
    road.y_[i] = road.y_[i - 1] + road.ds_ * std::sin(hm);
  }
  for (int i = zero - 1; i >= 0; --i) {
    const double h1 = road.heading_[i + 1];
    const double h0 = h1 - 0.5 * (road.curvature_[i] + road.curvature_[i + 1]) * road.ds_;
    const double hm = 0.5 * (h0 + h1);
    road.heading_[i] = h0;
    road.x_[i] = road.x_[i + 1] - road.ds_ * std::cos(hm);
    road.y_[i] = road.y_[i + 1] - road.ds_ * std::sin(hm);
  }
  return road;
}

double SimRoad::Interpolate(const std::vector<double>& values, double s_m) const {
  const double f = std::clamp((s_m - s_begin_) / ds_, 0.0, static_cast<double>(values.size() - 1));
  const size_t i = std::min(static_cast<size_t>(f), values.size() - 2);
  const double w = f - i;
  return (1 - w) * values[i] + w * values[i + 1];
}

Eigen::Vector2d SimRoad::Position(double s_m) const {
  const double end = s_end();
  if (s_m > end) {  // extend straight beyond the generated range
    return Eigen::Vector2d(x_.back(), y_.back()) +
           (s_m - end) * Eigen::Vector2d(std::cos(heading_.back()), std::sin(heading_.back()));
  }
  if (s_m < s_begin_) {
    return Eigen::Vector2d(x_.front(), y_.front()) -
           (s_begin_ - s_m) *
               Eigen::Vector2d(std::cos(heading_.front()), std::sin(heading_.front()));
  }
  // Between samples the arc is nearly straight: interpolate along the local heading.
  const double f = (s_m - s_begin_) / ds_;
  const size_t i = std::min(static_cast<size_t>(f), x_.size() - 2);
  const double offset = s_m - (s_begin_ + i * ds_);
  const double h = heading_[i] + 0.5 * curvature_[i] * offset;
  return Eigen::Vector2d(x_[i] + offset * std::cos(h), y_[i] + offset * std::sin(h));
}

double SimRoad::Heading(double s_m) const { return Interpolate(heading_, s_m); }

double SimRoad::Curvature(double s_m) const {
  if (s_m < s_begin_ || s_m > s_end()) return 0.0;
  return Interpolate(curvature_, s_m);
}

Eigen::Vector2d SimRoad::At(double s_m, double lateral_m) const {
  const double h = Heading(s_m);
  return Position(s_m) + lateral_m * Eigen::Vector2d(-std::sin(h), std::cos(h));
}

}  // namespace stcalib::sim
