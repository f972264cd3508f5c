#include "core/io/kitti_calib.h"

#include <cmath>
#include <cstdio>

#include "core/io/text.h"

namespace stcalib {
namespace {

std::string Trim(const std::string& s) {
  const size_t begin = s.find_first_not_of(" \t");
  if (begin == std::string::npos) return "";
  const size_t end = s.find_last_not_of(" \t");
  return s.substr(begin, end - begin + 1);
}

bool IsTextKey(const std::string& key) {
  return key == "calib_time" || key == "distortion_model_02";
}

std::string FormatNumber(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.12e", value);
  return buffer;
}

Status ReadRigid(const std::string& path, Rigid3d* T) {
  KittiCalibFile file;
  STCALIB_RETURN_IF_ERROR(KittiCalibFile::Read(path, &file));
  Eigen::MatrixXd R, t;
  STCALIB_RETURN_IF_ERROR(file.GetMatrix("R", 3, 3, &R));
  STCALIB_RETURN_IF_ERROR(file.GetMatrix("T", 3, 1, &t));
  STCALIB_RETURN_IF_ERROR(CheckRotation(R, path + ": key 'R'"));
  *T = MakeRigid(NearestRotation(R), t);
  return Status::Ok();
}

KittiCalibFile RigidFile(const Rigid3d& T, bool with_deltas, const std::string& note = "") {
  KittiCalibFile file;
  file.SetText("calib_time", "written by stcalib" + (note.empty() ? "" : "; " + note));
  file.SetMatrix("R", T.linear());
  file.SetMatrix("T", T.translation());
  if (with_deltas) {
    file.SetNumbers("delta_f", {0.0, 0.0});
    file.SetNumbers("delta_c", {0.0, 0.0});
  }
  return file;
}

}  // namespace

Status KittiCalibFile::Read(const std::string& path, KittiCalibFile* file) {
  *file = KittiCalibFile();
  file->path_ = path;
  std::vector<std::string> lines;
  STCALIB_RETURN_IF_ERROR(ReadLines(path, &lines));
  for (size_t i = 0; i < lines.size(); ++i) {
    if (IsBlank(lines[i])) continue;
    const std::string where = path + ":" + std::to_string(i + 1) + ": ";
    const size_t colon = lines[i].find(':');
    if (colon == std::string::npos) {
      return Status::Error(where + "expected 'key: values', got '" + lines[i] + "'");
    }
    const std::string key = Trim(lines[i].substr(0, colon));
    const std::string value = Trim(lines[i].substr(colon + 1));
    if (key.empty()) return Status::Error(where + "empty key");
    if (file->lines_.count(key) > 0) {
      return Status::Error(where + "key '" + key + "' repeated (first on line " +
                           std::to_string(file->lines_[key]) + ")");
    }
    file->lines_[key] = static_cast<int>(i + 1);
    if (IsTextKey(key)) {
      file->SetText(key, value);
      continue;
    }
    std::vector<double> values;
    std::string bad;
    if (!ParseNumbers(value, &values, &bad)) {
      return Status::Error(where + "key '" + key + "': '" + bad + "' is not a finite number");
    }
    if (values.empty()) return Status::Error(where + "key '" + key + "' has no values");
    file->SetNumbers(key, values);
  }
  if (file->order_.empty()) return Status::Error(path + ": no calibration keys in file");
  return Status::Ok();
}

Status KittiCalibFile::Write(const std::string& path) const {
  return WriteTextFile(path, ToString());
}

std::string KittiCalibFile::ToString() const {
  std::string contents;
  for (const std::string& key : order_) {
    contents += key + ":";
    const auto text = texts_.find(key);
    if (text != texts_.end()) {
      contents += " " + text->second;
    } else {
      for (double v : numbers_.at(key)) contents += " " + FormatNumber(v);
    }
    contents += "\n";
  }
  return contents;
}

Status KittiCalibFile::GetMatrix(const std::string& key, int rows, int cols,
                                 Eigen::MatrixXd* matrix) const {
  const auto it = numbers_.find(key);
  if (it == numbers_.end()) {
    return Status::Error(path_ + ": missing key '" + key + "'");
  }
  if (static_cast<int>(it->second.size()) != rows * cols) {
    const auto line = lines_.find(key);
    const std::string where =
        line == lines_.end() ? path_ : path_ + ":" + std::to_string(line->second);
    return Status::Error(where + ": key '" + key + "' has " + std::to_string(it->second.size()) +
                         " numbers, expected " + std::to_string(rows * cols));
  }
  matrix->resize(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) (*matrix)(r, c) = it->second[r * cols + c];
  }
  return Status::Ok();
}

std::string KittiCalibFile::Text(const std::string& key) const {
  const auto it = texts_.find(key);
  return it == texts_.end() ? "" : it->second;
}

void KittiCalibFile::AddKey(const std::string& key) {
  if (numbers_.count(key) == 0 && texts_.count(key) == 0) order_.push_back(key);
}

void KittiCalibFile::SetNumbers(const std::string& key, const std::vector<double>& values) {
  AddKey(key);
  texts_.erase(key);
  numbers_[key] = values;
}

void KittiCalibFile::SetText(const std::string& key, const std::string& text) {
  AddKey(key);
  numbers_.erase(key);
  texts_[key] = text;
}

void KittiCalibFile::SetMatrix(const std::string& key, const Eigen::MatrixXd& matrix) {
  std::vector<double> values;
  for (int r = 0; r < matrix.rows(); ++r) {
    for (int c = 0; c < matrix.cols(); ++c) values.push_back(matrix(r, c));
  }
  SetNumbers(key, values);
}

Status CheckRotation(const Eigen::Matrix3d& rotation, const std::string& what) {
  const double orthogonality =
      (rotation * rotation.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = rotation.determinant();
  if (orthogonality > kRotationTolerance || std::abs(det - 1.0) > kRotationTolerance) {
    return Status::Error(what + " is not a rotation matrix (|R·Rᵀ − I| = " +
                         std::to_string(orthogonality) + ", det = " + std::to_string(det) + ")");
  }
  return Status::Ok();
}

Status ReadCamToCam(const std::string& path, CameraCalibration* calibration,
                    const std::string& id) {
  *calibration = CameraCalibration();
  calibration->id = id;
  STCALIB_RETURN_IF_ERROR(KittiCalibFile::Read(path, &calibration->file));
  const KittiCalibFile& file = calibration->file;
  const std::string p_key = "P_rect_" + id, s_key = "S_rect_" + id;
  Eigen::MatrixXd R_rect, P_rect, size;
  STCALIB_RETURN_IF_ERROR(file.GetMatrix("R_rect_00", 3, 3, &R_rect));
  STCALIB_RETURN_IF_ERROR(file.GetMatrix(p_key, 3, 4, &P_rect));
  STCALIB_RETURN_IF_ERROR(file.GetMatrix(s_key, 1, 2, &size));
  STCALIB_RETURN_IF_ERROR(CheckRotation(R_rect, path + ": key 'R_rect_00'"));
  calibration->R_rect_00 = R_rect;
  calibration->P_rect = P_rect;
  const double width = size(0, 0), height = size(0, 1);
  if (width < 1 || height < 1 || width > 100000 || height > 100000 ||
      width != static_cast<int>(width) || height != static_cast<int>(height)) {
    return Status::Error(path + ": key '" + s_key + "' is not a valid image size");
  }
  calibration->image_width = static_cast<int>(width);
  calibration->image_height = static_cast<int>(height);
  if (P_rect(0, 0) <= 0 || P_rect(1, 1) <= 0 || P_rect(2, 2) <= 0) {
    return Status::Error(path + ": key '" + p_key + "' has non-positive focal lengths");
  }
  // stcalib's key for raw images (a simulated distorted camera): KITTI's own files carry K_02 and
  // D_02 too, but their images are rectified, and they have no such key.
  const std::string model = file.Text("distortion_model_" + id);
  if (!model.empty()) {
    Eigen::MatrixXd K;
    STCALIB_RETURN_IF_ERROR(file.GetMatrix("K_" + id, 3, 3, &K));
    if (!file.Has("D_" + id)) {
      return Status::Error(path + ": key 'D_" + id + "' missing (distortion_model_" + id + ")");
    }
    calibration->distortion_model = model;
    calibration->K = K;
    calibration->distortion = file.numbers().at("D_" + id);
  }
  // stcalib's rig keys (a simulated rig): the camera's frame relative to calib_velo_to_cam's.
  const std::string r_key = "R_rig_" + id, t_key = "T_rig_" + id;
  if (file.Has(r_key) || file.Has(t_key)) {
    Eigen::MatrixXd R, T;
    STCALIB_RETURN_IF_ERROR(file.GetMatrix(r_key, 3, 3, &R));
    STCALIB_RETURN_IF_ERROR(file.GetMatrix(t_key, 3, 1, &T));
    STCALIB_RETURN_IF_ERROR(CheckRotation(R, path + ": key '" + r_key + "'"));
    calibration->T_camera_reference = MakeRigid(NearestRotation(R), T.col(0));
  }
  return Status::Ok();
}

Rigid3d RectifiedFromCamera(const CameraCalibration& calibration) {
  const Eigen::Matrix3d K = calibration.P_rect.leftCols<3>();
  return MakeRigid(calibration.R_rect_00, K.inverse() * calibration.P_rect.col(3));
}

Status ReadVeloToCam(const std::string& path, Rigid3d* T_camera_lidar) {
  return ReadRigid(path, T_camera_lidar);
}

std::string VeloToCamText(const Rigid3d& T_camera_lidar) {
  return RigidFile(T_camera_lidar, /*with_deltas=*/true).ToString();
}

Status WriteVeloToCam(const std::string& path, const Rigid3d& T_camera_lidar,
                      const std::string& note) {
  return RigidFile(T_camera_lidar, /*with_deltas=*/true, note).Write(path);
}

Status ReadTimeOffset(const std::string& path, double* time_offset_s) {
  std::vector<std::string> lines;
  STCALIB_RETURN_IF_ERROR(ReadLines(path, &lines));
  std::string text;
  for (const std::string& line : lines) text += line.substr(0, line.find('#')) + " ";
  std::vector<double> values;
  std::string bad;
  if (!ParseNumbers(text, &values, &bad)) {
    return Status::Error(path + ": '" + bad + "' is not a finite number of seconds");
  }
  if (values.size() != 1) {
    return Status::Error(path + ": expected one number (the time offset in seconds), found " +
                         std::to_string(values.size()));
  }
  if (std::abs(values[0]) > 1.0) {
    return Status::Error(path + ": time offset " + std::to_string(values[0]) +
                         " s is beyond ±1 s (a whole second between two sensors of one rig)");
  }
  *time_offset_s = values[0];
  return Status::Ok();
}

Status WriteTimeOffset(const std::string& path, double time_offset_s, const std::string& note) {
  char line[64];
  std::snprintf(line, sizeof(line), "%.9f\n", time_offset_s);
  return WriteTextFile(path, line + (note.empty() ? "" : "# " + note + "\n"));
}

Status ReadImuToVelo(const std::string& path, Rigid3d* T_lidar_imu) {
  return ReadRigid(path, T_lidar_imu);
}

Status WriteImuToVelo(const std::string& path, const Rigid3d& T_lidar_imu) {
  return RigidFile(T_lidar_imu, /*with_deltas=*/false).Write(path);
}

}  // namespace stcalib
