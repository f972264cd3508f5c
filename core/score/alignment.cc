#include "core/score/alignment.h"

#include <algorithm>
#include <cmath>

#include "core/features/projection_filter.h"

namespace stcalib {

namespace {

// `map_of(i)` gives the distance map point i reads.
template <typename MapOf>
AlignmentStats Measure(const std::vector<ProjectedPoint>& projected, const MapOf& map_of,
                       double threshold_px, double isolation_radius_px) {
  AlignmentStats stats;
  stats.projected = static_cast<int>(projected.size());
  if (projected.empty()) return stats;
  std::vector<Eigen::Vector2d> pixels;
  pixels.reserve(projected.size());
  for (const ProjectedPoint& p : projected) pixels.push_back(p.pixel);
  const std::vector<bool> keep = isolation_radius_px > 0
                                     ? KeepNonIsolated(pixels, isolation_radius_px)
                                     : std::vector<bool>(pixels.size(), true);
  std::vector<float> distances;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const cv::Mat& map = map_of(i);
    if (!keep[i] || map.empty()) continue;
    const int u = std::clamp(static_cast<int>(std::lround(pixels[i].x())), 0, map.cols - 1);
    const int v = std::clamp(static_cast<int>(std::lround(pixels[i].y())), 0, map.rows - 1);
    distances.push_back(map.at<float>(v, u));
  }
  stats.kept = static_cast<int>(distances.size());
  if (distances.empty()) return stats;
  stats.aligned = static_cast<int>(std::count_if(distances.begin(), distances.end(),
                                                 [&](float d) { return d <= threshold_px; }));
  stats.rate = static_cast<double>(stats.aligned) / stats.kept;
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  stats.median_distance_px = distances[distances.size() / 2];
  return stats;
}

}  // namespace

AlignmentStats MeasureAlignment(const std::vector<ProjectedPoint>& projected,
                                const cv::Mat& distance_raw_px, double threshold_px,
                                double isolation_radius_px) {
  return Measure(
      projected, [&](size_t) -> const cv::Mat& { return distance_raw_px; }, threshold_px,
      isolation_radius_px);
}

AlignmentStats MeasureOrientedAlignment(const std::vector<ProjectedPoint>& projected,
                                        const std::vector<EdgeKind>& kinds,
                                        const cv::Mat& distance_vertical_raw_px,
                                        const cv::Mat& distance_horizontal_raw_px,
                                        double threshold_px, double isolation_radius_px) {
  return Measure(
      projected,
      [&](size_t i) -> const cv::Mat& {
        return kinds[projected[i].index] == EdgeKind::kVertical ? distance_vertical_raw_px
                                                                : distance_horizontal_raw_px;
      },
      threshold_px, isolation_radius_px);
}

}  // namespace stcalib
