#include <algorithm>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "apps/commands.h"
#include "apps/flags.h"
#include "core/io/image.h"
#include "core/io/kitti_calib.h"
#include "core/io/text.h"

namespace stcalib::cli {

int ReportError(const std::string& command, const Status& status) {
  std::cerr << "stcalib " << command << ": error: " << status.message() << "\n";
  return kExitFailure;
}

int UsageError(const std::string& command, const std::string& message) {
  std::cerr << "stcalib " << command << ": usage error: " << message << "\n(run `stcalib "
            << command << " --help`)\n";
  return kExitUsage;
}

namespace {

Status ReadJson(const std::string& path, nlohmann::json* json) {
  std::vector<std::string> lines;
  STCALIB_RETURN_IF_ERROR(ReadLines(path, &lines));
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  try {
    *json = nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    return Status::Error(path + ": " + e.what());
  }
  return Status::Ok();
}

}  // namespace

Status ReadGroundTruth(const Drive& drive, bool* found, CalibrationState* truth) {
  const std::string path = drive.calib_dir + "/ground_truth.json";
  *found = std::filesystem::exists(path);
  if (!*found) return Status::Ok();
  nlohmann::json j;
  STCALIB_RETURN_IF_ERROR(ReadJson(path, &j));
  try {
    // A simulated rig's other cameras have their own entry (their frame, their δ).
    if (drive.camera_name != "image_02") {
      if (!j.contains("cameras") || !j["cameras"].contains(drive.camera_name)) {
        return Status::Error(path + ": no ground truth for camera " + drive.camera_name +
                             " (its 'cameras' entry)");
      }
      const nlohmann::json camera = j["cameras"][drive.camera_name];
      j = camera;
    }
    const auto& m = j.at("T_camera_lidar");
    if (m.size() != 16) return Status::Error(path + ": T_camera_lidar must have 16 numbers");
    Eigen::Matrix4d T;
    for (int k = 0; k < 16; ++k) T(k / 4, k % 4) = m.at(k).get<double>();
    truth->T_camera_lidar.matrix() = T;
    truth->time_offset_s = j.at("time_offset_s").get<double>();
  } catch (const std::exception& e) {
    return Status::Error(path + ": " + e.what());
  }
  return Status::Ok();
}

Status ReadSimulatedLidarName(const Drive& drive, std::string* lidar) {
  lidar->clear();
  const std::string path = drive.calib_dir + "/ground_truth.json";
  if (!std::filesystem::exists(path)) return Status::Ok();
  nlohmann::json j;
  STCALIB_RETURN_IF_ERROR(ReadJson(path, &j));
  if (j.contains("lidar") && j["lidar"].is_string()) *lidar = j["lidar"].get<std::string>();
  return Status::Ok();
}

Status StartingCalibration(const Drive& drive, const std::string& init_calib,
                           double perturb_rot_deg, double perturb_trans_m, std::mt19937_64* rng,
                           Rigid3d* T_camera_lidar) {
  *T_camera_lidar = drive.T_camera_lidar;
  if (!init_calib.empty()) {
    // The file's frame is calib_velo_to_cam's (KITTI's camera 0), the camera's own after its
    // rig transform.
    STCALIB_RETURN_IF_ERROR(ReadVeloToCam(init_calib, T_camera_lidar));
    *T_camera_lidar = drive.camera.T_camera_reference * *T_camera_lidar;
  }
  auto sign = [&]() { return ((*rng)() & 1) ? 1.0 : -1.0; };
  // One draw per statement, last axis first: the order every seed's start was drawn in so far
  // (the arguments of one call are evaluated in an order C++ leaves open).
  Eigen::Vector3d rpy, dt;
  for (int axis = 2; axis >= 0; --axis) rpy[axis] = sign() * perturb_rot_deg;
  for (int axis = 2; axis >= 0; --axis) dt[axis] = sign() * perturb_trans_m;
  *T_camera_lidar = PerturbTcameraLidar(*T_camera_lidar, rpy, dt);
  return Status::Ok();
}

Status OpenDriveFromFlags(Drive* drive) { return OpenDrive(FLAGS_drive, FLAGS_calib_dir, drive); }

BagDriveOptions BagOptionsFromFlags() {
  BagDriveOptions options;
  options.bag_dir = FLAGS_bag;
  options.image_topic = FLAGS_image_topic;
  options.cloud_topic = FLAGS_cloud_topic;
  options.camera_info_topic = FLAGS_camera_info_topic;
  options.odom_topic = FLAGS_odom_topic;
  options.imu_topic = FLAGS_imu_topic;
  options.require_tf_extrinsic = FLAGS_init_calib.empty();
  return options;
}

Status OpenDriveOrBagFromFlags(Drive* drive) {
  if (FLAGS_bag.empty()) return OpenDriveFromFlags(drive);
  return OpenBagDrive(BagOptionsFromFlags(), drive);
}

Status ImageOptionsFromFlags(ImageFeatureOptions* options) {
  ImageFeatureOptions::Detector detector;
  if (!ParseDetector(FLAGS_detector, &detector)) {
    return Status::Error("--detector must be " + DetectorChoices() + ", got '" + FLAGS_detector +
                         "'");
  }
  options->detector = detector;
  options->min_segment_length_px = FLAGS_min_segment_px;
  options->max_edge_density = FLAGS_max_edge_density;
  return Status::Ok();
}

cv::Mat DrawEdgeOverlay(const cv::Mat& image, const CalibrationFrame& frame,
                        const CalibrationState& state, const std::string& title) {
  cv::Mat canvas;
  image.convertTo(canvas, CV_8UC3, 0.55);
  // What the score reads: a vertical LiDAR edge point against near-vertical image edges, a
  // horizontal one against near-horizontal ones (the frame's smoothed distance maps).
  for (size_t i = 0; i < frame.size(); ++i) {
    Eigen::Vector2d pixel;
    if (!ProjectFramePoint(frame, state, i, &pixel) || !frame.camera.InImage(pixel)) continue;
    const int u = static_cast<int>(std::lround(pixel.x())),
              v = static_cast<int>(std::lround(pixel.y()));
    const cv::Mat& distance_px = frame.distance_px[static_cast<int>(frame.kinds[i])];
    const bool near = !distance_px.empty() && distance_px.at<float>(v, u) <= 2.0f;
    cv::circle(canvas, cv::Point(u, v), 2, near ? cv::Scalar(60, 255, 60) : cv::Scalar(40, 40, 255),
               cv::FILLED);
  }
  cv::putText(canvas, title, cv::Point(10, 22), cv::FONT_HERSHEY_SIMPLEX, 0.6,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  // Legend, bottom left: what the two colours mean.
  const int y = canvas.rows - 12;
  cv::circle(canvas, cv::Point(14, y - 4), 4, cv::Scalar(60, 255, 60), cv::FILLED);
  cv::putText(canvas, "LiDAR edge point within 2 px of an image edge of its direction",
              cv::Point(24, y), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  cv::circle(canvas, cv::Point(14, y - 22), 4, cv::Scalar(40, 40, 255), cv::FILLED);
  cv::putText(canvas, "LiDAR edge point farther from every image edge of its direction",
              cv::Point(24, y - 18), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  return canvas;
}

Status WriteFrameStrip(const Drive& drive,
                       const std::vector<std::shared_ptr<const CalibrationFrame>>& frames,
                       const std::vector<StripView>& views, const std::string& dir,
                       std::vector<std::string>* written) {
  constexpr size_t kStripFrames = 4;
  std::error_code ec;
  std::filesystem::remove_all(dir + "/frames", ec);
  std::filesystem::create_directories(dir + "/frames", ec);
  for (size_t k = 0; k < std::min(kStripFrames, frames.size()); ++k) {
    const size_t pick =
        frames.size() <= kStripFrames ? k : k * (frames.size() - 1) / (kStripFrames - 1);
    const CalibrationFrame& frame = *frames[pick];
    cv::Mat image;
    STCALIB_RETURN_IF_ERROR(drive.LoadImage(frame.index, &image));
    const std::string index = std::to_string(frame.index);
    for (const StripView& view : views) {
      const std::string path = dir + "/frames/" + view.prefix + index + ".png";
      STCALIB_RETURN_IF_ERROR(WriteImage(
          path, DrawEdgeOverlay(image, frame, view.state, "frame " + index + " " + view.title)));
      if (written != nullptr) written->push_back(path);
    }
  }
  return Status::Ok();
}

}  // namespace stcalib::cli
