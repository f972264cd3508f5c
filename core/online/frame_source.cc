#include "core/online/frame_source.h"

#include <glog/logging.h>

#include "core/score/projection.h"

namespace stcalib {

Status FrameSourceOptions::Validate() const {
  STCALIB_RETURN_IF_ERROR(image.Validate());
  return lidar.Validate();
}

Status DriveFrameSource::Create(const Drive* drive, const FrameSourceOptions& options,
                                std::unique_ptr<DriveFrameSource>* source) {
  STCALIB_RETURN_IF_ERROR(options.Validate());
  std::unique_ptr<DriveFrameSource> s(new DriveFrameSource(drive, options));
  if (drive->has_oxts) {
    STCALIB_RETURN_IF_ERROR(DriveMotion::Create(*drive, &s->motion_));
  } else {
    LOG(WARNING) << drive->drive_dir
                 << ": no oxts; the motion comes from registering consecutive sweeps (NDT) "
                    "with a constant velocity between them";
    STCALIB_RETURN_IF_ERROR(DriveMotion::CreateFromScans(*drive, &s->motion_));
  }
  s->cache_ = std::make_unique<SweepCache>(*drive, s->motion_, s->options_.lidar);
  *source = std::move(s);
  return Status::Ok();
}

Status DriveFrameSource::Load(size_t frame, CalibrationFrame* out) {
  STCALIB_RETURN_IF_ERROR(drive_->CheckFrame(frame));
  *out = CalibrationFrame();
  const double camera_s = motion_.Seconds(drive_->camera_stamps_ns[frame]);
  const double oxts_gap_s = motion_.GapAround(camera_s);
  if (oxts_gap_s > options_.max_oxts_gap_s) {
    return Status::Error(drive_->drive_dir + (drive_->has_oxts ? "/oxts" : "/velodyne_points") +
                         ": frame " + std::to_string(frame) + " falls in a gap of " +
                         std::to_string(oxts_gap_s) + " s between motion measurements (more than " +
                         std::to_string(options_.max_oxts_gap_s) + " s): no motion model");
  }
  out->index = static_cast<int>(frame);
  cv::Mat image;
  STCALIB_RETURN_IF_ERROR(drive_->LoadImage(frame, &image));
  out->camera = MakeCameraModel(drive_->camera, image.cols, image.rows);
  ImageFeatureOptions image_options = options_.image;
  image_options.suppress_pyramid = options_.suppress_texture;
  image_options.split_orientation = options_.oriented_maps;
  out->image = ExtractImageFeatures(image, image_options);
  for (int kind = 0; kind < 2; ++kind) {
    const bool oriented = options_.oriented_maps && !out->image.empty();
    const OrientedMaps* m = oriented ? &out->image.oriented[kind] : nullptr;
    const std::vector<cv::Mat>& pyramid = m ? m->pyramid : out->image.idt_pyramid;
    for (const cv::Mat& level : pyramid) out->score_maps[kind].push_back(level);
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

  LidarEdges map;
  LocalMapStats stats;
  STCALIB_RETURN_IF_ERROR(cache_->LocalMap(frame, options_.local_map, &map, &stats));
  out->points_lidar = std::move(map.points_lidar);
  out->kinds = std::move(map.kind);

  const double lidar_s = motion_.Seconds(drive_->lidar_stamps_ns[frame]);
  out->e0_s = lidar_s - camera_s;
  out->camera_time_s = camera_s;
  out->twist = TwistFromPoses(motion_.PoseFunction(), camera_s);
  return Status::Ok();
}

}  // namespace stcalib
