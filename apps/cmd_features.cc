// stcalib features: the line features of one frame, as pictures and numbers.
#include <cstdio>
#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "apps/commands.h"
#include "apps/flags.h"
#include "core/features/image_features.h"
#include "core/features/lidar_frame.h"
#include "core/io/image.h"
#include "core/motion/drive_motion.h"
#include "core/score/alignment.h"
#include "core/score/projection.h"

namespace stcalib::cli {
namespace {

cv::Mat Colourise(const cv::Mat& map_0_255) {
  cv::Mat u8, colour;
  map_0_255.convertTo(u8, CV_8U);
  cv::applyColorMap(u8, colour, cv::COLORMAP_INFERNO);
  return colour;
}

void Draw(cv::Mat* canvas, const std::vector<ProjectedPoint>& points, const cv::Scalar& colour) {
  for (const ProjectedPoint& p : points) {
    cv::circle(*canvas,
               cv::Point(static_cast<int>(std::lround(p.pixel.x())),
                         static_cast<int>(std::lround(p.pixel.y()))),
               2, colour, cv::FILLED);
  }
}

}  // namespace

int RunFeatures() {
  if (FLAGS_out.empty()) return UsageError("features", "--out=DIR is required");
  if (FLAGS_frame < 0) return UsageError("features", "--frame must be >= 0");
  Drive drive;
  Status status = OpenDriveOrBagFromFlags(&drive);
  if (status.ok()) status = drive.CheckFrame(FLAGS_frame);
  if (!status.ok()) return ReportError("features", status);
  DriveMotion motion;
  status = DriveMotion::CreateForDrive(drive, &motion);
  if (!status.ok()) return ReportError("features", status);
  std::error_code ec;
  std::filesystem::create_directories(FLAGS_out, ec);

  const size_t frame = static_cast<size_t>(FLAGS_frame);
  cv::Mat image;
  status = drive.LoadImage(frame, &image);
  if (!status.ok()) return ReportError("features", status);
  ImageFeatureOptions image_options;
  const Status flags_status = ImageOptionsFromFlags(&image_options);
  if (!flags_status.ok()) return UsageError("features", flags_status.message());
  image_options.split_orientation = true;
  image_options.precise_distance = true;
  const ImageFeatures image_features = ExtractImageFeatures(image, image_options);
  LidarFrameFeatures lidar;
  status = LoadLidarFrameFeatures(drive, motion, frame, LidarFeatureOptions(), &lidar);
  if (!status.ok()) return ReportError("features", status);

  // Carry the de-skewed points from the LiDAR stamp to the image stamp (stamps taken as is).
  const double camera_s = motion.Seconds(drive.camera_stamps_ns[frame]);
  const Rigid3d T_camera_lidar =
      drive.T_camera_lidar * RelativeLidarPose(motion.PoseFunction(), camera_s, lidar.stamp_s);
  const CameraModel camera = MakeCameraModel(drive.camera, image.cols, image.rows);
  const AlignmentStats oriented = MeasureOrientedAlignment(
      ProjectPoints(camera, T_camera_lidar, lidar.edges.points_lidar), lidar.edges.kind,
      image_features.distance_vertical_raw_px, image_features.distance_horizontal_raw_px, 3.0, 8.0);
  std::vector<Eigen::Vector3d> vertical, horizontal, dynamic;
  for (size_t i = 0; i < lidar.edges.size(); ++i) {
    (lidar.edges.kind[i] == EdgeKind::kVertical ? vertical : horizontal)
        .push_back(lidar.edges.points_lidar[i]);
  }
  for (size_t i = 0; i < lidar.deskewed.size(); ++i) {
    if (!lidar.dynamic.dynamic.empty() && lidar.dynamic.dynamic[i])
      dynamic.push_back(lidar.deskewed[i]);
  }
  const auto projected_v = ProjectPoints(camera, T_camera_lidar, vertical);
  const auto projected_h = ProjectPoints(camera, T_camera_lidar, horizontal);
  const auto projected_d = ProjectPoints(camera, T_camera_lidar, dynamic);
  std::vector<ProjectedPoint> all = projected_v;
  all.insert(all.end(), projected_h.begin(), projected_h.end());
  const AlignmentStats alignment = MeasureAlignment(all, image_features.distance_raw_px, 3.0, 8.0);

  cv::Mat overlay;
  image.convertTo(overlay, CV_8UC3, 0.5);
  Draw(&overlay, projected_d, cv::Scalar(255, 0, 255));  // removed dynamic points: magenta
  Draw(&overlay, projected_v, cv::Scalar(80, 255, 80));  // vertical edges: green
  Draw(&overlay, projected_h, cv::Scalar(0, 170, 255));  // horizontal edges: orange
  // Edge mask with the projected LiDAR edges: green within 3 px of an edge, red beyond.
  cv::Mat check;
  cv::cvtColor(image_features.edge_mask / 2, check, cv::COLOR_GRAY2BGR);
  for (const ProjectedPoint& p : all) {
    const int u = static_cast<int>(std::lround(p.pixel.x())),
              v = static_cast<int>(std::lround(p.pixel.y()));
    const bool near = image_features.distance_raw_px.at<float>(v, u) <= 3.0f;
    cv::circle(check, cv::Point(u, v), 2, near ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 0, 255),
               cv::FILLED);
  }
  const std::string out = FLAGS_out;
  for (const auto& [name, picture] : std::vector<std::pair<std::string, cv::Mat>>{
           {"edge_mask.png", image_features.edge_mask},
           {"idt.png", Colourise(image_features.idt)},
           {"idt_suppressed.png", Colourise(image_features.idt_suppressed * 2.0)},
           {"lidar_edges.png", overlay},
           {"alignment.png", check}}) {
    status = WriteImage(out + "/" + name, picture);
    if (!status.ok()) return ReportError("features", status);
  }
  std::printf("frame %d (%s)\n", FLAGS_frame, drive.frame_names[frame].c_str());
  std::printf("  image      %dx%d, %d edge pixels\n", image.cols, image.rows,
              image_features.edge_pixels);
  int ground = 0;
  for (uint8_t g : lidar.ground) ground += g;
  std::printf("  lidar      %zu points, %d rings, %d ground, %d dynamic removed (%d clusters)\n",
              lidar.deskewed.size(), lidar.rings.num_rings(), ground, lidar.dynamic.removed_points,
              lidar.dynamic.dynamic_clusters);
  std::printf("  edges      %zu vertical, %zu horizontal; %zu + %zu in the image\n",
              vertical.size(), horizontal.size(), projected_v.size(), projected_h.size());
  std::printf(
      "  alignment  %.1f%% of %d projected edge points within 3 px of an image edge "
      "(median %.2f px)\n",
      100 * alignment.rate, alignment.kept, alignment.median_distance_px);
  std::printf("  oriented   %.1f%% within 3 px of an image edge of the same orientation\n",
              100 * oriented.rate);
  std::printf("  wrote      %s/{edge_mask,idt,idt_suppressed,lidar_edges,alignment}.png\n",
              out.c_str());
  return kExitOk;
}

}  // namespace stcalib::cli
