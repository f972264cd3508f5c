#include "core/io/velodyne.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/io/text.h"

namespace stcalib {
namespace {

Status ReadBytes(const std::string& path, std::vector<char>* bytes) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return Status::Error(path + ": file not found");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open: " + std::strerror(errno));
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) return Status::Error(path + ": cannot determine file size");
  in.seekg(0, std::ios::beg);
  bytes->resize(static_cast<size_t>(size));
  if (size > 0 && !in.read(bytes->data(), size)) return Status::Error(path + ": read error");
  return Status::Ok();
}

}  // namespace

Status ReadVelodyneBin(const std::string& path, LidarScan* scan) {
  scan->points_lidar.clear();
  scan->reflectance.clear();
  std::vector<char> bytes;
  STCALIB_RETURN_IF_ERROR(ReadBytes(path, &bytes));
  constexpr size_t kPointBytes = 4 * sizeof(float);
  if (bytes.size() % kPointBytes != 0) {
    return Status::Error(path + ": truncated velodyne file: " + std::to_string(bytes.size()) +
                         " bytes is not a multiple of 16 (float32 x, y, z, reflectance)");
  }
  const size_t count = bytes.size() / kPointBytes;
  scan->points_lidar.resize(count);
  scan->reflectance.resize(count);
  for (size_t i = 0; i < count; ++i) {
    float v[4];
    std::memcpy(v, bytes.data() + i * kPointBytes, kPointBytes);
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]) ||
        !std::isfinite(v[3])) {
      scan->points_lidar.clear();
      scan->reflectance.clear();
      return Status::Error(path + ": point " + std::to_string(i) + " has a NaN or infinite value");
    }
    scan->points_lidar[i] = Eigen::Vector3d(v[0], v[1], v[2]);
    scan->reflectance[i] = v[3];
  }
  return Status::Ok();
}

Status WriteVelodyneBin(const std::string& path, const LidarScan& scan) {
  if (scan.reflectance.size() != scan.points_lidar.size()) {
    return Status::Error(path + ": scan has " + std::to_string(scan.points_lidar.size()) +
                         " points but " + std::to_string(scan.reflectance.size()) +
                         " reflectance values");
  }
  std::vector<float> data(scan.size() * 4);
  for (size_t i = 0; i < scan.size(); ++i) {
    data[4 * i + 0] = static_cast<float>(scan.points_lidar[i].x());
    data[4 * i + 1] = static_cast<float>(scan.points_lidar[i].y());
    data[4 * i + 2] = static_cast<float>(scan.points_lidar[i].z());
    data[4 * i + 3] = scan.reflectance[i];
  }
  return WriteFileAtomically(path, reinterpret_cast<const char*>(data.data()),
                             data.size() * sizeof(float));
}

Status ReadPointLabels(const std::string& path, std::vector<uint8_t>* labels) {
  std::vector<char> bytes;
  STCALIB_RETURN_IF_ERROR(ReadBytes(path, &bytes));
  labels->assign(bytes.begin(), bytes.end());
  for (size_t i = 0; i < labels->size(); ++i) {
    if ((*labels)[i] > static_cast<uint8_t>(PointLabel::kGround)) {
      return Status::Error(path + ": label of point " + std::to_string(i) + " is " +
                           std::to_string((*labels)[i]) + ", expected 0, 1 or 2");
    }
  }
  return Status::Ok();
}

Status WritePointLabels(const std::string& path, const std::vector<uint8_t>& labels) {
  return WriteFileAtomically(path, reinterpret_cast<const char*>(labels.data()), labels.size());
}

}  // namespace stcalib
