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
  const double fx = camera.P_rect(0, 0), fy = camera.P_rect(1, 1);
  const double cx = camera.P_rect(0, 2), cy = camera.P_rect(1, 2);
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

Eigen::Vector2d AzimuthWindowUnionDeg(const std::vector<Eigen::Vector2d>& windows) {
  if (windows.empty()) return Eigen::Vector2d::Zero();
  if (windows.size() == 1) return windows.front();
  constexpr int kBins = 720;  // 0.5° each, bin b covering [−180 + b/2, −180 + (b+1)/2)
  std::vector<bool> covered(kBins, false);
  for (const Eigen::Vector2d& w : windows) {
    if (w.y() <= 0) return Eigen::Vector2d::Zero();
    const int from = static_cast<int>(std::floor(2 * (w.x() - w.y() + 180)));
    const int to = static_cast<int>(std::ceil(2 * (w.x() + w.y() + 180)));
    for (int b = from; b < to; ++b) covered[((b % kBins) + kBins) % kBins] = true;
  }
  // The longest run of uncovered bins, around the circle: the window is its complement.
  int best_start = -1, best_length = 0;
  for (int start = 0; start < kBins; ++start) {
    if (covered[start] || !covered[(start + kBins - 1) % kBins]) continue;
    int length = 0;
    while (length < kBins && !covered[(start + length) % kBins]) ++length;
    if (length > best_length) best_length = length, best_start = start;
  }
  if (best_length == 0) return Eigen::Vector2d::Zero();
  const double gap_centre_deg = -180 + 0.5 * (best_start + 0.5 * best_length);
  const double half_deg = 0.5 * (360 - 0.5 * best_length);
  return Eigen::Vector2d(std::remainder(gap_centre_deg + 180, 360.0), half_deg);
}

Status DriveFrameSource::Create(const std::vector<const Drive*>& cameras,
                                const FrameSourceOptions& options,
                                std::unique_ptr<DriveFrameSource>* source) {
  CHECK(!cameras.empty());
  STCALIB_RETURN_IF_ERROR(options.Validate());
  const Drive& first = *cameras.front();
  for (const Drive* camera : cameras) {
    if (camera->frame_names != first.frame_names ||
        camera->lidar_stamps_ns != first.lidar_stamps_ns) {
      return Status::Error(camera->drive_dir + ": camera " + camera->camera_name +
                           ": its frames or LiDAR stamps differ from camera " + first.camera_name +
                           "'s (" + std::to_string(camera->NumFrames()) + " and " +
                           std::to_string(first.NumFrames()) +
                           " frames): the cameras must be of one drive");
    }
  }
  std::unique_ptr<DriveFrameSource> s(new DriveFrameSource(cameras, options));
  if (options.view_margin_deg >= 0) {
    std::vector<Eigen::Vector2d> windows;
    bool known = true;
    for (const Drive* drive : cameras) {
      known = known && drive->camera.image_width > 0 && drive->camera.image_height > 0 &&
              drive->camera.P_rect(0, 0) > 0 && drive->camera.P_rect(1, 1) > 0;
      if (!known) break;
      // The view of camera k ≠ 0 as the start places the first one: the rig's relative mount.
      const Rigid3d T_camera_first = drive->T_camera_lidar * first.T_camera_lidar.inverse();
      windows.push_back(CameraAzimuthWindowDeg(
          drive->camera, drive->camera.image_width, drive->camera.image_height,
          T_camera_first * options.view_T_camera_lidar.value_or(first.T_camera_lidar),
          options.view_margin_deg));
    }
    if (known) {
      const Eigen::Vector2d window = AzimuthWindowUnionDeg(windows);
      s->options_.lidar.dynamic.roi_center_azimuth_deg = window.x();
      s->options_.lidar.dynamic.roi_half_angle_deg = window.y();
    }
  }
  STCALIB_RETURN_IF_ERROR(DriveMotion::CreateForDrive(first, &s->motion_));
  // A sequential pass needs the local map's sweeps and the dynamic filter's long-baseline
  // reference, which the cache's least capacity holds: no more (each sweep kept costs ~4 MB).
  s->cache_ = std::make_unique<SweepCache>(first, s->motion_, s->options_.lidar, /*capacity=*/0);
  s->cache_->ReleaseCaptureFieldsOnceFinished();  // Load reads local maps only
  *source = std::move(s);
  return Status::Ok();
}

Status DriveFrameSource::LoadImageAndMotion(size_t camera, size_t frame,
                                            CalibrationFrame* out) const {
  const Drive& drive = *drives_[camera];
  STCALIB_RETURN_IF_ERROR(drive.CheckFrame(frame));
  *out = CalibrationFrame();
  const double camera_s = motion_.Seconds(drive.camera_stamps_ns[frame]);
  const double oxts_gap_s = motion_.GapAround(camera_s);
  if (oxts_gap_s > options_.max_oxts_gap_s) {
    const bool oxts = motion_.source() == DriveMotion::Source::kOxts;
    const bool odometry = motion_.source() == DriveMotion::Source::kOdometry;
    return Status::Error(drive.drive_dir +
                         (oxts       ? "/oxts"
                          : odometry ? " (odometry)"
                                     : "/velodyne_points") +
                         ": frame " + std::to_string(frame) + " falls in a gap of " +
                         std::to_string(oxts_gap_s) + " s between motion measurements (more than " +
                         std::to_string(options_.max_oxts_gap_s) + " s): no motion model");
  }
  out->index = static_cast<int>(frame);
  cv::Mat image;
  STCALIB_RETURN_IF_ERROR(drive.LoadImage(frame, &image));
  out->camera = MakeCameraModel(drive.camera, image.cols, image.rows);
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

  const double lidar_s = motion_.Seconds(drive.lidar_stamps_ns[frame]);
  out->e0_s = lidar_s - camera_s;
  out->camera_time_s = camera_s;
  out->twist = TwistFromPoses(motion_.PoseFunction(), camera_s);
  return Status::Ok();
}

Status DriveFrameSource::Load(size_t frame, CalibrationFrame* out) {
  CHECK_EQ(drives_.size(), 1u) << "Load reads a single-camera source; LoadCameras reads several";
  std::vector<CameraFrameLoad> loads;
  LoadCameras(frame, &loads);
  if (!loads.front().status.ok()) return loads.front().status;
  *out = std::move(*loads.front().frame);
  return Status::Ok();
}

void DriveFrameSource::LoadCameras(size_t frame, std::vector<CameraFrameLoad>* out) {
  out->assign(drives_.size(), CameraFrameLoad());
  for (size_t k = 0; k < drives_.size(); ++k) {
    (*out)[k].frame = std::make_shared<CalibrationFrame>();
    (*out)[k].status = LoadImageAndMotion(k, frame, (*out)[k].frame.get());
  }
  LidarEdges map;
  LocalMapStats stats;
  const Status lidar = cache_->LocalMap(frame, options_.local_map, &map, &stats);
  // Every camera but the last copies the map's points; the last takes them.
  for (size_t k = 0; k < drives_.size(); ++k) {
    CameraFrameLoad& load = (*out)[k];
    if (load.status.ok() && !lidar.ok()) load.status = lidar;
    if (!load.status.ok()) continue;
    load.frame->TakePoints(k + 1 == drives_.size() ? std::move(map) : LidarEdges(map));
  }
}

}  // namespace stcalib
