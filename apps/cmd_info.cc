// stcalib info: what a drive holds, and whether its stamps and files look sane.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "apps/flags.h"
#include "core/io/image.h"
#include "core/types/transform.h"

namespace stcalib::cli {
namespace {

struct GapStats {
  double rate_hz = 0, min_ms = 0, median_ms = 0, max_ms = 0;
  int long_gaps = 0;  ///< gaps longer than 1.5× the median (dropped frames)
  int non_increasing = 0;
};

GapStats ComputeGaps(const std::vector<StampNs>& stamps) {
  GapStats stats;
  if (stamps.size() < 2) return stats;
  std::vector<double> gaps_ms;
  for (size_t i = 1; i < stamps.size(); ++i) gaps_ms.push_back((stamps[i] - stamps[i - 1]) * 1e-6);
  std::vector<double> sorted = gaps_ms;
  std::sort(sorted.begin(), sorted.end());
  stats.min_ms = sorted.front();
  stats.max_ms = sorted.back();
  stats.median_ms = sorted[sorted.size() / 2];
  stats.rate_hz = (stamps.size() - 1) / (NsToSeconds(stamps.back() - stamps.front()));
  for (double g : gaps_ms) {
    if (g > 1.5 * stats.median_ms) ++stats.long_gaps;
    if (g <= 0) ++stats.non_increasing;
  }
  return stats;
}

void PrintGaps(const char* name, const std::vector<StampNs>& stamps) {
  const GapStats s = ComputeGaps(stamps);
  std::printf("  %-8s %7.3f Hz  gap min %.2f / median %.2f / max %.2f ms", name, s.rate_hz,
              s.min_ms, s.median_ms, s.max_ms);
  if (s.long_gaps > 0) std::printf("  [%d gaps > 1.5x median]", s.long_gaps);
  if (s.non_increasing > 0) std::printf("  [%d non-increasing stamps]", s.non_increasing);
  std::printf("\n");
}

void PrintTransform(const char* name, const Rigid3d& T) {
  std::printf("  %s\n", name);
  for (int r = 0; r < 3; ++r) {
    std::printf("    [% .6f % .6f % .6f | % .6f]\n", T(r, 0), T(r, 1), T(r, 2), T(r, 3));
  }
  const Eigen::Vector3d rv = LogSO3(T.linear()) * 180.0 / M_PI;
  std::printf("    rotation vector (deg) [% .4f % .4f % .4f], |t| = %.4f m\n", rv.x(), rv.y(),
              rv.z(), T.translation().norm());
}

}  // namespace

int RunInfo() {
  Drive drive;
  const Status status = OpenDriveOrBagFromFlags(&drive);
  if (!status.ok()) return ReportError("info", status);

  std::printf("drive        %s\n", drive.drive_dir.c_str());
  std::printf("calibration  %s\n", drive.calib_dir.c_str());
  std::printf("frames       %zu (%s .. %s), %.3f s\n", drive.NumFrames(),
              drive.frame_names.front().c_str(), drive.frame_names.back().c_str(),
              NsToSeconds(drive.camera_stamps_ns.back() - drive.camera_stamps_ns.front()));
  std::printf("sensor rates and stamp gaps\n");
  PrintGaps("camera", drive.camera_stamps_ns);
  PrintGaps("lidar", drive.lidar_stamps_ns);
  if (drive.has_oxts) PrintGaps("oxts", drive.oxts_stamps_ns);

  // Camera stamp minus LiDAR stamp per frame, and the sweep duration.
  double sum_offset_ms = 0, min_offset_ms = 1e18, max_offset_ms = -1e18;
  for (size_t i = 0; i < drive.NumFrames(); ++i) {
    const double d = (drive.camera_stamps_ns[i] - drive.lidar_stamps_ns[i]) * 1e-6;
    sum_offset_ms += d;
    min_offset_ms = std::min(min_offset_ms, d);
    max_offset_ms = std::max(max_offset_ms, d);
  }
  std::printf("camera - lidar stamp  mean %.2f ms (min %.2f, max %.2f)\n",
              sum_offset_ms / drive.NumFrames(), min_offset_ms, max_offset_ms);
  if (!drive.lidar_start_stamps_ns.empty()) {
    double sum_sweep_ms = 0;
    for (size_t i = 0; i < drive.NumFrames(); ++i) {
      sum_sweep_ms += (drive.lidar_end_stamps_ns[i] - drive.lidar_start_stamps_ns[i]) * 1e-6;
    }
    std::printf("lidar sweep duration  mean %.2f ms (timestamps_end - timestamps_start)\n",
                sum_sweep_ms / drive.NumFrames());
  }

  size_t min_points = SIZE_MAX, max_points = 0, total_points = 0;
  for (size_t i = 0; i < drive.NumFrames(); ++i) {
    LidarScan scan;
    const Status s = drive.LoadScan(i, &scan);
    if (!s.ok()) return ReportError("info", s);
    min_points = std::min(min_points, scan.size());
    max_points = std::max(max_points, scan.size());
    total_points += scan.size();
  }
  std::printf("points/frame min %zu / mean %zu / max %zu\n", min_points,
              total_points / drive.NumFrames(), max_points);

  cv::Mat image;
  const Status s = drive.LoadImage(0, &image);
  if (!s.ok()) return ReportError("info", s);
  std::printf("image        %dx%d (S_rect_02 %dx%d)%s\n", image.cols, image.rows,
              drive.camera.image_width, drive.camera.image_height,
              image.cols == drive.camera.image_width && image.rows == drive.camera.image_height
                  ? ""
                  : "  [image size differs from S_rect_02; the image size is used]");
  if (drive.has_oxts) {
    double speed = 0;
    for (const OxtsPacket& p : drive.oxts) speed += std::hypot(p.vf, p.vl);
    std::printf("oxts         mean speed %.2f m/s, first fix lat %.6f lon %.6f\n",
                speed / drive.oxts.size(), drive.oxts.front().lat, drive.oxts.front().lon);
  }
  const bool bag = drive.store != nullptr;
  std::printf("calibration %s\n", bag ? "(the bag's tf)" : "files");
  PrintTransform(bag ? "T_camera_lidar" : "T_camera_lidar (calib_velo_to_cam.txt)",
                 drive.T_camera_lidar);
  if (drive.has_imu_calibration) {
    PrintTransform(
        bag ? "T_lidar_imu (odometry or IMU frame)" : "T_lidar_imu (calib_imu_to_velo.txt)",
        drive.T_lidar_imu);
  }
  const auto& P = drive.camera.P_rect;
  std::printf("  P_rect_02 fx %.3f fy %.3f cx %.3f cy %.3f, tx %.4f\n", P(0, 0), P(1, 1), P(0, 2),
              P(1, 2), P(0, 3));
  return kExitOk;
}

}  // namespace stcalib::cli
