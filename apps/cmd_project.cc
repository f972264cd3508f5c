// stcalib project: one frame's LiDAR points on its image, coloured by depth.
#include <cstdio>

#include "apps/commands.h"
#include "apps/flags.h"
#include "core/io/image.h"
#include "core/score/projection.h"
#include "core/viz/overlay.h"

namespace stcalib::cli {

int RunProject() {
  if (FLAGS_out.empty()) return UsageError("project", "--out=FILE.png is required");
  if (FLAGS_frame < 0) return UsageError("project", "--frame must be >= 0");
  Drive drive;
  Status status = OpenDriveOrBagFromFlags(&drive);
  if (!status.ok()) return ReportError("project", status);
  const size_t frame = static_cast<size_t>(FLAGS_frame);
  status = drive.CheckFrame(frame);
  if (!status.ok()) return ReportError("project", status);

  cv::Mat image;
  LidarScan scan;
  status = drive.LoadImage(frame, &image);
  if (status.ok()) status = drive.LoadScan(frame, &scan);
  if (!status.ok()) return ReportError("project", status);

  const CameraModel camera = MakeCameraModel(drive.camera, image.cols, image.rows);
  const std::vector<ProjectedPoint> projected =
      ProjectPoints(camera, drive.T_camera_lidar, scan.points_lidar);
  status = WriteImage(FLAGS_out, RenderDepthOverlay(image, projected));
  if (!status.ok()) return ReportError("project", status);
  std::printf("frame %d: %zu of %zu points project into the %dx%d image; wrote %s\n", FLAGS_frame,
              projected.size(), scan.size(), image.cols, image.rows, FLAGS_out.c_str());
  return kExitOk;
}

}  // namespace stcalib::cli
