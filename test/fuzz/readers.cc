#include "test/fuzz/readers.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "core/io/kitti_calib.h"
#include "core/io/oxts.h"
#include "core/io/timestamps.h"
#include "core/io/velodyne.h"

namespace stcalib::fuzz {
namespace {

[[noreturn]] void Broken(const std::string& reader, const std::string& path,
                         const std::string& what) {
  std::fprintf(stderr, "reader %s on %s: %s\n", reader.c_str(), path.c_str(), what.c_str());
  std::abort();
}

// An error must name the file it is about.
void CheckError(const std::string& reader, const std::string& path, const Status& status) {
  if (status.ok()) return;
  if (status.message().find(path) == std::string::npos) {
    Broken(reader, path, "error does not name the file: " + status.message());
  }
}

void CheckRigid(const std::string& reader, const std::string& path, const Rigid3d& T) {
  if (!T.matrix().allFinite()) Broken(reader, path, "non-finite transform accepted");
  // The reader moves R to the nearest rotation: orthonormal to rounding.
  const Eigen::Matrix3d R = T.linear();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-9 ||
      std::abs(R.determinant() - 1.0) > 1e-9) {
    Broken(reader, path, "a matrix that is not a rotation accepted");
  }
}

}  // namespace

const char* const kReaders[6] = {"velodyne",   "oxts",        "timestamps",
                                 "cam_to_cam", "velo_to_cam", "imu_to_velo"};

bool CheckReader(const std::string& name, const std::string& path) {
  if (name == "velodyne") {
    LidarScan scan;
    const Status status = ReadVelodyneBin(path, &scan);
    CheckError(name, path, status);
    if (status.ok()) {
      for (size_t i = 0; i < scan.size(); ++i) {
        if (!scan.points_lidar[i].allFinite() || !std::isfinite(scan.reflectance[i])) {
          Broken(name, path, "non-finite point accepted");
        }
      }
    }
    std::vector<uint8_t> labels;
    CheckError(name, path, ReadPointLabels(path, &labels));
  } else if (name == "oxts") {
    OxtsPacket packet;
    const Status status = ReadOxtsPacket(path, &packet);
    CheckError(name, path, status);
    if (status.ok() &&
        !(std::isfinite(packet.lat) && std::isfinite(packet.lon) && std::isfinite(packet.alt) &&
          std::isfinite(packet.roll) && std::isfinite(packet.pitch) && std::isfinite(packet.yaw) &&
          std::isfinite(packet.vf) && std::isfinite(packet.wz))) {
      Broken(name, path, "non-finite oxts field accepted");
    }
  } else if (name == "timestamps") {
    std::vector<StampNs> stamps;
    CheckError(name, path, ReadTimestampsFile(path, &stamps));
  } else if (name == "cam_to_cam") {
    CameraCalibration calibration;
    const Status status = ReadCamToCam(path, &calibration);
    CheckError(name, path, status);
    if (status.ok() && (!calibration.P_rect_02.allFinite() || !calibration.R_rect_00.allFinite())) {
      Broken(name, path, "non-finite camera calibration accepted");
    }
  } else if (name == "velo_to_cam" || name == "imu_to_velo") {
    Rigid3d T;
    const Status status = name == "velo_to_cam" ? ReadVeloToCam(path, &T) : ReadImuToVelo(path, &T);
    CheckError(name, path, status);
    if (status.ok()) CheckRigid(name, path, T);
  } else {
    return false;
  }
  return true;
}

}  // namespace stcalib::fuzz
