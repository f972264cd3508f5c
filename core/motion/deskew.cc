#include "core/motion/deskew.h"

#include <algorithm>
#include <cmath>

namespace stcalib {

std::vector<Eigen::Vector3d> DeskewToStamp(const std::vector<Eigen::Vector3d>& points,
                                           const std::vector<double>& time_s, double stamp_s,
                                           const LidarPoseFunction& T_world_lidar, int bins) {
  std::vector<Eigen::Vector3d> out(points.size());
  if (points.empty()) return out;
  const auto [lo_it, hi_it] = std::minmax_element(time_s.begin(), time_s.end());
  const double lo = *lo_it, hi = *hi_it;
  const Rigid3d T_stamp_inv = T_world_lidar(stamp_s).inverse();
  bins = std::max(bins, 2);
  std::vector<Rigid3d> table(bins);
  const double width = hi > lo ? (hi - lo) / (bins - 1) : 1.0;
  for (int k = 0; k < bins; ++k) table[k] = T_stamp_inv * T_world_lidar(stamp_s + lo + k * width);
  for (size_t i = 0; i < points.size(); ++i) {
    // Linear interpolation between the two tabulated poses around t_i.
    const double f = std::clamp((time_s[i] - lo) / width, 0.0, static_cast<double>(bins - 1));
    const int k = std::min(static_cast<int>(f), bins - 2);
    const double w = f - k;
    out[i] = (1 - w) * (table[k] * points[i]) + w * (table[k + 1] * points[i]);
  }
  return out;
}

Rigid3d RelativeLidarPose(const LidarPoseFunction& T_world_lidar, double t_to_s, double t_from_s) {
  return T_world_lidar(t_to_s).inverse() * T_world_lidar(t_from_s);
}

Eigen::Matrix<double, 3, 4> RelativeLidarPoseRate(const LidarPoseFunction& T_world_lidar,
                                                  double t_to_s, double t_from_s) {
  constexpr double kStepS = 0.005;
  const Rigid3d later = RelativeLidarPose(T_world_lidar, t_to_s + kStepS, t_from_s + kStepS);
  const Rigid3d earlier = RelativeLidarPose(T_world_lidar, t_to_s - kStepS, t_from_s - kStepS);
  return (later.matrix() - earlier.matrix()).topRows<3>() / (2 * kStepS);
}

}  // namespace stcalib
