#include "core/features/ground.h"

#include <glog/logging.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

namespace stcalib {

Status GroundOptions::Validate() const {
  if (!(max_fit_range_m > 0) || !(inlier_threshold_m > 0) || !(band_m > 0) || iterations < 1 ||
      sample_points < 3 || !(max_tilt_deg > 0 && max_tilt_deg < 90)) {
    return Status::Error("ground: options must be positive (tilt below 90 deg)");
  }
  return Status::Ok();
}

GroundPlane FitGroundPlane(const std::vector<Eigen::Vector3d>& points,
                           const GroundOptions& options) {
  CHECK(options.Validate().ok()) << options.Validate().message();
  GroundPlane best;
  std::vector<int> candidates;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const Eigen::Vector3d& p = points[i];
    // Low returns only: below the sensor, within the fit range.
    if (p.z() < -0.3 &&
        p.head<2>().squaredNorm() < options.max_fit_range_m * options.max_fit_range_m) {
      candidates.push_back(i);
    }
  }
  if (candidates.size() < 50) {
    LOG(WARNING) << "ground: too few low returns (" << candidates.size() << ") to fit a plane";
    return best;
  }
  std::mt19937_64 rng(options.seed);
  std::vector<Eigen::Vector3d> sample;
  std::uniform_int_distribution<size_t> pick(0, candidates.size() - 1);
  const int sample_count = std::min<int>(options.sample_points, candidates.size());
  for (int k = 0; k < sample_count; ++k) sample.push_back(points[candidates[pick(rng)]]);

  const double cos_tilt = std::cos(options.max_tilt_deg * M_PI / 180.0);
  std::uniform_int_distribution<int> pick_sample(0, sample_count - 1);
  for (int it = 0; it < options.iterations; ++it) {
    const Eigen::Vector3d& a = sample[pick_sample(rng)];
    const Eigen::Vector3d& b = sample[pick_sample(rng)];
    const Eigen::Vector3d& c = sample[pick_sample(rng)];
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-6) continue;
    n.normalize();
    if (n.z() < 0) n = -n;
    if (n.z() < cos_tilt) continue;
    const double d = -n.dot(a);
    int inliers = 0;
    for (const Eigen::Vector3d& p : sample)
      inliers += std::abs(n.dot(p) + d) < options.inlier_threshold_m;
    if (inliers > best.inliers) {
      best.normal = n;
      best.offset = d;
      best.inliers = inliers;
      best.valid = true;
    }
  }
  if (!best.valid) {
    LOG(WARNING) << "ground: no level plane found";
    return best;
  }
  // Least-squares refinement on the inliers (smallest principal axis).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> inliers;
  for (const Eigen::Vector3d& p : sample) {
    if (std::abs(best.Height(p)) < options.inlier_threshold_m) inliers.push_back(p);
  }
  for (const auto& p : inliers) mean += p;
  mean /= inliers.size();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : inliers) cov += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  Eigen::Vector3d n = solver.eigenvectors().col(0);
  if (n.z() < 0) n = -n;
  if (n.z() >= cos_tilt) {
    best.normal = n;
    best.offset = -n.dot(mean);
  }
  return best;
}

std::vector<uint8_t> GroundMask(const std::vector<Eigen::Vector3d>& points,
                                const GroundPlane& plane, double band_m) {
  std::vector<uint8_t> mask(points.size(), 0);
  if (!plane.valid) return mask;
  for (size_t i = 0; i < points.size(); ++i) mask[i] = plane.Height(points[i]) < band_m;
  return mask;
}

}  // namespace stcalib
