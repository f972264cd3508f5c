#include "core/online/frame_source.h"

#include <glog/logging.h>

#include <cmath>

#include "core/score/projection.h"

namespace stcalib {

namespace {

// The acquisition's coarse maps (CoarseScoreMap): a basin wide enough that a hypothesis half a
// lattice step from the truth still reads its peak, at a quarter of the image size (a map of
// ~120 KB on KITTI stays in the cache while the lattice reads it).
// Measured: docs/tuning.md#lattice-steps
constexpr double kCoarseBasinPx = 20;
constexpr int kCoarseMapScale = 4;

// A frame stays in the calibrator's window for up to refine_frames frames, and every full-size
// float map costs width × height × 4 bytes (1.9 MB on KITTI). Of its image features the frame's
// readers need only what it does not hold itself: the edge count (ImageFeatures::empty); the
// overlays read the frame's own distance maps. A frame scoring on the band-pass IDTs also
// drops the texture-suppressed and plain IDTs, which TextureSuppressedMap and PlainIdt make again
// from its score and distance maps where they are read (the health check, the gray rate).
void ReleaseMapsNotRead(double basin_px, CalibrationFrame* frame) {
  ImageFeatures& features = frame->image;
  features.distance_raw_px.release();
  features.distance_vertical_raw_px.release();
  features.distance_horizontal_raw_px.release();
  features.segments.clear();
  features.edge_mask.release();
  features.segments.shrink_to_fit();
  if (!frame->score_maps_bandpass) return;
  features.idt_suppressed.release();
  features.idt.release();
  for (OrientedMaps& m : features.oriented) {
    m.idt_suppressed.release();
    m.idt.release();
  }
  for (cv::Mat& map : frame->gray_map) map.release();
  frame->gray_basin_px = basin_px;
}

}  // namespace

Status FrameSourceOptions::Validate() const {
  STCALIB_RETURN_IF_ERROR(image.Validate());
  return lidar.Validate();
}

ImageFeatureOptions FrameSourceOptions::ImageOptions() const {
  ImageFeatureOptions options = image;
  options.split_orientation = oriented_maps;
  options.unsplit_maps = !oriented_maps;  // Load reads the oriented maps only
  return options;
}

Eigen::Vector2d CameraAzimuthWindowDeg(const CameraCalibration& camera, int image_width,
                                       int image_height, const Rigid3d& T_camera_lidar,
                                       double margin_deg) {
  const double fx = camera.P_rect_02(0, 0), fy = camera.P_rect_02(1, 1);
  const double cx = camera.P_rect_02(0, 2), cy = camera.P_rect_02(1, 2);
  // Rectified camera ray -> LiDAR direction.
  const Eigen::Matrix3d R_lidar_rect =
      T_camera_lidar.linear().transpose() * camera.R_rect_00.transpose();
  auto direction = [&](double u, double v) {
    return (R_lidar_rect * Eigen::Vector3d((u - cx) / fx, (v - cy) / fy, 1.0)).normalized();
  };
  const Eigen::Vector3d axis = direction(cx, cy);
  if (std::abs(axis.z()) > 0.9) return Eigen::Vector2d::Zero();
  const double center = std::atan2(axis.y(), axis.x());
  double half = 0;
  for (double u : {0.0, 0.5 * image_width, static_cast<double>(image_width)}) {
    for (double v : {0.0, 0.5 * image_height, static_cast<double>(image_height)}) {
      const Eigen::Vector3d d = direction(u, v);
      half = std::max(half, std::abs(std::remainder(std::atan2(d.y(), d.x()) - center, 2 * M_PI)));
    }
  }
  const double half_deg = half * 180.0 / M_PI + margin_deg;
  if (half_deg >= 180) return Eigen::Vector2d::Zero();
  return Eigen::Vector2d(center * 180.0 / M_PI, half_deg);
}

Status DriveFrameSource::Create(const Drive* drive, const FrameSourceOptions& options,
                                std::unique_ptr<DriveFrameSource>* source) {
  STCALIB_RETURN_IF_ERROR(options.Validate());
  std::unique_ptr<DriveFrameSource> s(new DriveFrameSource(drive, options));
  if (options.view_margin_deg >= 0 && drive->camera.image_width > 0 &&
      drive->camera.image_height > 0 && drive->camera.P_rect_02(0, 0) > 0 &&
      drive->camera.P_rect_02(1, 1) > 0) {
    const Eigen::Vector2d window = CameraAzimuthWindowDeg(
        drive->camera, drive->camera.image_width, drive->camera.image_height,
        options.view_T_camera_lidar.value_or(drive->T_camera_lidar), options.view_margin_deg);
    s->options_.lidar.dynamic.roi_center_azimuth_deg = window.x();
    s->options_.lidar.dynamic.roi_half_angle_deg = window.y();
  }
  STCALIB_RETURN_IF_ERROR(DriveMotion::CreateForDrive(*drive, &s->motion_));
  // A sequential pass needs the local map's sweeps and the dynamic filter's long-baseline
  // reference, which the cache's least capacity holds: no more (each sweep kept costs ~4 MB).
  s->cache_ = std::make_unique<SweepCache>(*drive, s->motion_, s->options_.lidar, /*capacity=*/0);
  s->cache_->ReleaseCaptureFieldsOnceFinished();  // Load reads local maps only
  *source = std::move(s);
  return Status::Ok();
}

Status DriveFrameSource::Load(size_t frame, CalibrationFrame* out) {
  STCALIB_RETURN_IF_ERROR(drive_->CheckFrame(frame));
  *out = CalibrationFrame();
  const double camera_s = motion_.Seconds(drive_->camera_stamps_ns[frame]);
  const double oxts_gap_s = motion_.GapAround(camera_s);
  if (oxts_gap_s > options_.max_oxts_gap_s) {
    const bool oxts = motion_.source() == DriveMotion::Source::kOxts;
    const bool odometry = motion_.source() == DriveMotion::Source::kOdometry;
    return Status::Error(drive_->drive_dir +
                         (oxts       ? "/oxts"
                          : odometry ? " (odometry)"
                                     : "/velodyne_points") +
                         ": frame " + std::to_string(frame) + " falls in a gap of " +
                         std::to_string(oxts_gap_s) + " s between motion measurements (more than " +
                         std::to_string(options_.max_oxts_gap_s) + " s): no motion model");
  }
  out->index = static_cast<int>(frame);
  cv::Mat image;
  STCALIB_RETURN_IF_ERROR(drive_->LoadImage(frame, &image));
  out->camera = MakeCameraModel(drive_->camera, image.cols, image.rows);
  out->image = ExtractImageFeatures(image, options_.ImageOptions());
  for (int kind = 0; kind < 2; ++kind) {
    const bool oriented = options_.oriented_maps && !out->image.empty();
    const OrientedMaps* m = oriented ? &out->image.oriented[kind] : nullptr;
    const cv::Mat& idt = m ? m->idt : out->image.idt;
    const cv::Mat& suppressed = options_.bandpass_score
                                    ? (m ? m->idt_bandpass : out->image.idt_bandpass)
                                    : (m ? m->idt_suppressed : out->image.idt_suppressed);
    out->score_maps[kind].push_back(options_.suppress_texture ? suppressed : idt);
    out->gray_map[kind] = idt;
    out->distance_px[kind] = m ? m->distance_px : out->image.distance_px;
    double max_value = 0;
    if (!out->distance_px[kind].empty()) cv::minMaxLoc(out->distance_px[kind], nullptr, &max_value);
    out->distance_cap_px = std::max(out->distance_cap_px, max_value);
  }

  // The acquisition's coarse maps, from the raw distances (released below).
  if (!out->image.empty()) {
    const bool oriented = options_.oriented_maps;
    for (int kind = 0; kind < 2; ++kind) {
      const cv::Mat& raw = !oriented   ? out->image.distance_raw_px
                           : kind == 0 ? out->image.distance_vertical_raw_px
                                       : out->image.distance_horizontal_raw_px;
      out->coarse_map[kind] = CoarseScoreMap(raw, kCoarseBasinPx, kCoarseMapScale);
    }
    out->coarse_map_scale = kCoarseMapScale;
  }
  out->score_maps_bandpass = options_.suppress_texture && options_.bandpass_score;
  ReleaseMapsNotRead(options_.ImageOptions().basin_px, out);

  LidarEdges map;
  LocalMapStats stats;
  STCALIB_RETURN_IF_ERROR(cache_->LocalMap(frame, options_.local_map, &map, &stats));
  out->TakePoints(std::move(map));

  const double lidar_s = motion_.Seconds(drive_->lidar_stamps_ns[frame]);
  out->e0_s = lidar_s - camera_s;
  out->camera_time_s = camera_s;
  out->twist = TwistFromPoses(motion_.PoseFunction(), camera_s);
  return Status::Ok();
}

}  // namespace stcalib
