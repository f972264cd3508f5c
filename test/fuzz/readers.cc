#include "test/fuzz/readers.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "core/io/kitti_calib.h"
#include "core/io/mcap.h"
#include "core/io/oxts.h"
#include "core/io/ros_messages.h"
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

const char* const kReaders[8] = {"velodyne",    "oxts",        "timestamps", "cam_to_cam",
                                 "velo_to_cam", "imu_to_velo", "mcap",       "ros_cdr"};

namespace {

// A decoder's error must name the message type it decoded.
void ExpectTypeNamed(const std::string& reader, const std::string& path, const Status& status,
                     const std::string& type) {
  if (!status.ok() && status.message().find(type) == std::string::npos) {
    Broken(reader, path, type + " error does not name the type: " + status.message());
  }
}

// A CDR message decoded as each message type: each decoder either names the message type in its
// error or returns sizes that its data holds, and only finite points.
void CheckCdr(const std::string& reader, const std::string& path, const std::vector<uint8_t>& cdr) {
  RosImage image;
  Status status = DecodeImage(cdr, &image);
  ExpectTypeNamed(reader, path, status, "sensor_msgs/msg/Image");
  if (status.ok() && uint64_t{image.step} * image.height > image.data.size()) {
    Broken(reader, path, "image rows past its data accepted");
  }
  if (status.ok() && uint64_t{image.width} * image.height <= (1u << 22)) {
    cv::Mat bgr;
    if (ImageToBgr(image, &bgr).ok() &&
        (bgr.rows != static_cast<int>(image.height) || bgr.cols != static_cast<int>(image.width))) {
      Broken(reader, path, "converted image of another size");
    }
  }
  int64_t stamp_ns = 0;
  cv::Mat decoded;
  ExpectTypeNamed(reader, path, DecodeCompressedImage(cdr, &stamp_ns, &decoded),
                  "sensor_msgs/msg/CompressedImage");
  RosCameraInfo info;
  ExpectTypeNamed(reader, path, DecodeCameraInfo(cdr, &info), "sensor_msgs/msg/CameraInfo");
  RosImu imu;
  ExpectTypeNamed(reader, path, DecodeImu(cdr, &imu), "sensor_msgs/msg/Imu");
  RosOdometry odometry;
  ExpectTypeNamed(reader, path, DecodeOdometry(cdr, &odometry), "nav_msgs/msg/Odometry");
  std::vector<RosTransform> transforms;
  status = DecodeTfMessage(cdr, &transforms);
  ExpectTypeNamed(reader, path, status, "tf2_msgs/msg/TFMessage");
  for (const RosTransform& t : transforms) {
    if (!t.T_parent_child.matrix().allFinite() ||
        !(t.T_parent_child.linear().determinant() > 0.999)) {
      Broken(reader, path, "a transform that is not rigid accepted");
    }
  }
  RosPointCloud cloud;
  status = DecodePointCloud2(cdr, &cloud);
  ExpectTypeNamed(reader, path, status, "sensor_msgs/msg/PointCloud2");
  CloudPoints points;
  if (status.ok() && uint64_t{cloud.width} * cloud.height <= (1u << 22) &&
      ExtractCloudPoints(cloud, &points).ok()) {
    for (const Eigen::Vector3d& p : points.points) {
      if (!p.allFinite()) Broken(reader, path, "non-finite cloud point accepted");
    }
  }
}

}  // namespace

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
    if (status.ok() && (!calibration.P_rect.allFinite() || !calibration.R_rect_00.allFinite())) {
      Broken(name, path, "non-finite camera calibration accepted");
    }
  } else if (name == "velo_to_cam" || name == "imu_to_velo") {
    Rigid3d T;
    const Status status = name == "velo_to_cam" ? ReadVeloToCam(path, &T) : ReadImuToVelo(path, &T);
    CheckError(name, path, status);
    if (status.ok()) CheckRigid(name, path, T);
  } else if (name == "mcap") {
    McapSummary summary;
    const Status status = ReadMcap(
        path,
        [&](const McapChannel& channel, const McapMessage& message) {
          if (channel.id != message.channel_id) {
            Broken(name, path, "a message delivered with another channel");
          }
          CheckCdr(name, path, message.data);
        },
        &summary);
    CheckError(name, path, status);
  } else if (name == "ros_cdr") {
    std::FILE* file = std::fopen(path.c_str(), "rb");
    if (file == nullptr) return true;
    std::vector<uint8_t> bytes;
    int c;
    while ((c = std::fgetc(file)) != EOF) bytes.push_back(static_cast<uint8_t>(c));
    std::fclose(file);
    CheckCdr(name, path, bytes);
  } else {
    return false;
  }
  return true;
}

}  // namespace stcalib::fuzz
