#include "core/io/drive.h"

#include <glog/logging.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "core/io/image.h"

namespace fs = std::filesystem;

namespace stcalib {
namespace {

// Frame names (file stems) of `dir` with extension `ext`, sorted.
Status ListFrames(const std::string& dir, const std::string& ext, std::vector<std::string>* names) {
  names->clear();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return Status::Error(dir + ": folder not found");
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.is_regular_file() && entry.path().extension() == ext) {
      names->push_back(entry.path().stem().string());
    }
  }
  if (ec) return Status::Error(dir + ": cannot list folder: " + ec.message());
  std::sort(names->begin(), names->end());
  if (names->empty()) return Status::Error(dir + ": no " + ext + " files");
  return Status::Ok();
}

Status CheckSameFrames(const std::string& dir, const std::vector<std::string>& expected,
                       const std::vector<std::string>& actual, const std::string& reference_dir) {
  if (actual.size() != expected.size()) {
    return Status::Error(dir + ": " + std::to_string(actual.size()) + " frames, but " +
                         reference_dir + " has " + std::to_string(expected.size()));
  }
  for (size_t i = 0; i < expected.size(); ++i) {
    if (actual[i] != expected[i]) {
      return Status::Error(dir + ": frame '" + actual[i] + "' does not match '" + expected[i] +
                           "' of " + reference_dir);
    }
  }
  return Status::Ok();
}

Status ReadStamps(const std::string& path, size_t num_frames, std::vector<StampNs>* stamps) {
  STCALIB_RETURN_IF_ERROR(ReadTimestampsFile(path, stamps));
  if (stamps->size() != num_frames) {
    return Status::Error(path + ": " + std::to_string(stamps->size()) + " timestamps for " +
                         std::to_string(num_frames) + " frames");
  }
  for (size_t i = 1; i < stamps->size(); ++i) {
    if ((*stamps)[i] <= (*stamps)[i - 1]) {
      LOG(WARNING) << path << ":" << i + 1 << ": timestamp does not increase";
    }
  }
  return Status::Ok();
}

}  // namespace

std::string Drive::ImagePath(size_t frame) const {
  return drive_dir + "/" + camera_name + "/data/" + frame_names.at(frame) + ".png";
}

std::string Drive::VelodynePath(size_t frame) const {
  return drive_dir + "/velodyne_points/data/" + frame_names.at(frame) + ".bin";
}

std::string Drive::LabelsPath(size_t frame) const {
  return drive_dir + "/velodyne_points/labels/" + frame_names.at(frame) + ".bin";
}

std::string Drive::ScanName(size_t frame) const {
  return store ? store->ScanName(frame) : VelodynePath(frame);
}

Status Drive::CheckFrame(size_t frame) const {
  if (frame >= NumFrames()) {
    return Status::Error(drive_dir + ": frame " + std::to_string(frame) + " out of range (" +
                         std::to_string(NumFrames()) + " frames)");
  }
  return Status::Ok();
}

Status Drive::LoadRawImage(size_t frame, cv::Mat* image_bgr) const {
  STCALIB_RETURN_IF_ERROR(CheckFrame(frame));
  if (store) return store->LoadImage(frame, image_bgr);
  return ReadImage(ImagePath(frame), image_bgr);
}

Status Drive::LoadImage(size_t frame, cv::Mat* image_bgr) const {
  STCALIB_RETURN_IF_ERROR(LoadRawImage(frame, image_bgr));
  RectifyImage(rectify, image_bgr);
  return Status::Ok();
}

Status Drive::LoadScan(size_t frame, LidarScan* scan) const {
  STCALIB_RETURN_IF_ERROR(CheckFrame(frame));
  if (store) return store->LoadScan(frame, scan);
  return ReadVelodyneBin(VelodynePath(frame), scan);
}

bool IsKittiCameraName(const std::string& name) {
  return name.size() == 8 && name.compare(0, 6, "image_") == 0 && std::isdigit(name[6]) &&
         std::isdigit(name[7]);
}

Status OpenDrive(const std::string& drive_dir_in, const std::string& calib_dir_in, Drive* drive,
                 const std::string& camera) {
  *drive = Drive();
  if (!IsKittiCameraName(camera)) {
    return Status::Error("camera '" + camera +
                         "' is not a KITTI camera folder name (image_ and two digits, e.g. "
                         "image_02)");
  }
  drive->camera_name = camera;
  std::error_code ec;
  std::string drive_dir = drive_dir_in;
  while (drive_dir.size() > 1 && drive_dir.back() == '/') drive_dir.pop_back();
  if (drive_dir.empty()) return Status::Error("no drive folder given (--drive)");
  if (!fs::is_directory(drive_dir, ec))
    return Status::Error(drive_dir + ": drive folder not found");
  drive->drive_dir = drive_dir;
  drive->calib_dir =
      calib_dir_in.empty() ? fs::path(drive_dir).parent_path().string() : calib_dir_in;
  if (drive->calib_dir.empty()) drive->calib_dir = ".";

  const std::string image_dir = drive_dir + "/" + camera;
  if (!fs::is_directory(image_dir, ec)) {
    return Status::Error(drive_dir + ": camera " + camera + ": folder " + image_dir + " not found");
  }
  const std::string velo_dir = drive_dir + "/velodyne_points";
  const std::string oxts_dir = drive_dir + "/oxts";
  STCALIB_RETURN_IF_ERROR(ListFrames(image_dir + "/data", ".png", &drive->frame_names));
  const size_t n = drive->frame_names.size();
  std::vector<std::string> names;
  STCALIB_RETURN_IF_ERROR(ListFrames(velo_dir + "/data", ".bin", &names));
  STCALIB_RETURN_IF_ERROR(
      CheckSameFrames(velo_dir + "/data", drive->frame_names, names, image_dir + "/data"));

  STCALIB_RETURN_IF_ERROR(ReadStamps(image_dir + "/timestamps.txt", n, &drive->camera_stamps_ns));
  STCALIB_RETURN_IF_ERROR(ReadStamps(velo_dir + "/timestamps.txt", n, &drive->lidar_stamps_ns));
  const std::string start_path = velo_dir + "/timestamps_start.txt";
  const std::string end_path = velo_dir + "/timestamps_end.txt";
  if (fs::exists(start_path, ec) || fs::exists(end_path, ec)) {
    STCALIB_RETURN_IF_ERROR(ReadStamps(start_path, n, &drive->lidar_start_stamps_ns));
    STCALIB_RETURN_IF_ERROR(ReadStamps(end_path, n, &drive->lidar_end_stamps_ns));
  }

  if (fs::exists(oxts_dir, ec)) {
    STCALIB_RETURN_IF_ERROR(ListFrames(oxts_dir + "/data", ".txt", &names));
    STCALIB_RETURN_IF_ERROR(
        CheckSameFrames(oxts_dir + "/data", drive->frame_names, names, image_dir + "/data"));
    STCALIB_RETURN_IF_ERROR(ReadStamps(oxts_dir + "/timestamps.txt", n, &drive->oxts_stamps_ns));
    drive->oxts.resize(n);
    for (size_t i = 0; i < n; ++i) {
      STCALIB_RETURN_IF_ERROR(
          ReadOxtsPacket(oxts_dir + "/data/" + names[i] + ".txt", &drive->oxts[i]));
    }
    drive->has_oxts = true;
  } else {
    VLOG(1) << oxts_dir << ": no oxts folder";
  }

  const std::string cam_to_cam = drive->calib_dir + "/calib_cam_to_cam.txt";
  STCALIB_RETURN_IF_ERROR(ReadCamToCam(cam_to_cam, &drive->camera, camera.substr(6))
                              .WithContext("camera " + camera + ": "));
  STCALIB_RETURN_IF_ERROR(
      MakeRectifyMaps(drive->camera, &drive->rectify).WithContext(cam_to_cam + ": "));
  STCALIB_RETURN_IF_ERROR(
      ReadVeloToCam(drive->calib_dir + "/calib_velo_to_cam.txt", &drive->T_camera_lidar));
  drive->T_camera_lidar = drive->camera.T_camera_reference * drive->T_camera_lidar;
  const std::string imu_path = drive->calib_dir + "/calib_imu_to_velo.txt";
  if (fs::exists(imu_path, ec)) {
    STCALIB_RETURN_IF_ERROR(ReadImuToVelo(imu_path, &drive->T_lidar_imu));
    drive->has_imu_calibration = true;
  }
  // Without it the oxts motion cannot be carried to the LiDAR (DriveMotion::CreateForDrive
  // registers the sweeps instead, and says so).
  return Status::Ok();
}

}  // namespace stcalib
