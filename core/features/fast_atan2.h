#pragma once

#include <algorithm>
#include <cmath>

namespace stcalib {

// atan2(y, x) in [−π, π] to within 2e-11 rad (tested against std::atan2) for finite y and x (NaN
// and infinities give meaningless angles: callers pass finite points), branch-light and
// inlined: several times cheaper than libm's correctly rounded atan2, for the dynamic filter's
// range image, which bins two angles per point into 0.25° cells (a cell changes only for a point
// within 2e-11 rad of a border), and for ring splitting, which keeps azimuths as float.
//
// The octant reduction leaves t = min/max of |x|, |y| in [0, 1]; above tan(π/8), atan t =
// π/4 + atan((t − 1)/(t + 1)), so the series runs on |u| ≤ tan(π/8) = 0.4142, where its terms
// fall by u² ≤ 0.1716 each: 12 terms (to u²³) leave |u|²⁵/25 < 1.1e-11.
inline double FastAtan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double hi = std::max(ax, ay), lo = std::min(ax, ay);
  if (hi == 0) return std::signbit(x) ? std::copysign(M_PI, y) : y;  // ±0, ±0 as std::atan2
  double t = lo / hi;
  constexpr double kTanPiOver8 = 0.41421356237309504880;
  double base = 0;
  if (t > kTanPiOver8) {
    t = (t - 1) / (t + 1);
    base = M_PI / 4;
  }
  const double u2 = t * t;
  // atan u = u·Σ (−1)^k u^(2k)/(2k + 1), k = 0..11, by Horner in u².
  double s = -1.0 / 23;
  s = s * u2 + 1.0 / 21;
  s = s * u2 - 1.0 / 19;
  s = s * u2 + 1.0 / 17;
  s = s * u2 - 1.0 / 15;
  s = s * u2 + 1.0 / 13;
  s = s * u2 - 1.0 / 11;
  s = s * u2 + 1.0 / 9;
  s = s * u2 - 1.0 / 7;
  s = s * u2 + 1.0 / 5;
  s = s * u2 - 1.0 / 3;
  s = s * u2 + 1.0;
  double a = base + t * s;
  if (ay > ax) a = M_PI / 2 - a;
  if (x < 0) a = M_PI - a;
  return std::signbit(y) ? -a : a;
}

}  // namespace stcalib
