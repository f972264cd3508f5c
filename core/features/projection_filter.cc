#include "core/features/projection_filter.h"

#include <cmath>
#include <unordered_map>

namespace stcalib {

std::vector<bool> KeepNonIsolated(const std::vector<Eigen::Vector2d>& pixels, double radius_px) {
  std::vector<bool> keep(pixels.size(), false);
  if (pixels.size() < 2 || !(radius_px > 0)) return keep;
  // Hash grid with cells of the radius: neighbours lie in the 3×3 cells around.
  auto key = [](int cx, int cy) {
    return (static_cast<int64_t>(cx) << 32) ^ static_cast<uint32_t>(cy);
  };
  std::unordered_map<int64_t, std::vector<int>> grid;
  grid.reserve(pixels.size());
  std::vector<std::pair<int, int>> cells(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) {
    const int cx = static_cast<int>(std::floor(pixels[i].x() / radius_px));
    const int cy = static_cast<int>(std::floor(pixels[i].y() / radius_px));
    cells[i] = {cx, cy};
    grid[key(cx, cy)].push_back(static_cast<int>(i));
  }
  const double r2 = radius_px * radius_px;
  for (size_t i = 0; i < pixels.size(); ++i) {
    for (int dx = -1; dx <= 1 && !keep[i]; ++dx) {
      for (int dy = -1; dy <= 1 && !keep[i]; ++dy) {
        const auto it = grid.find(key(cells[i].first + dx, cells[i].second + dy));
        if (it == grid.end()) continue;
        for (int j : it->second) {
          if (j != static_cast<int>(i) && (pixels[j] - pixels[i]).squaredNorm() <= r2) {
            keep[i] = true;
            break;
          }
        }
      }
    }
  }
  return keep;
}

}  // namespace stcalib
