#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/types/status.h"
#include "core/types/transform.h"

namespace stcalib {

// A KITTI calibration text file: lines "key: values". Numeric keys keep every number; text keys
// (calib_time) keep their text. Entry order is kept so that a file can be written back as read.
class KittiCalibFile {
 public:
  static Status Read(const std::string& path, KittiCalibFile* file);
  Status Write(const std::string& path) const;
  std::string ToString() const;  ///< the text Write writes

  bool Has(const std::string& key) const { return numbers_.count(key) > 0; }
  // Fetches a numeric key holding exactly rows*cols numbers (row-major); errors name the file,
  // the key and, when present, its line.
  Status GetMatrix(const std::string& key, int rows, int cols, Eigen::MatrixXd* matrix) const;
  const std::map<std::string, std::vector<double>>& numbers() const { return numbers_; }
  const std::vector<std::string>& keys() const { return order_; }
  std::string Text(const std::string& key) const;

  void SetNumbers(const std::string& key, const std::vector<double>& values);
  void SetText(const std::string& key, const std::string& text);
  void SetMatrix(const std::string& key, const Eigen::MatrixXd& matrix);  // row-major
  const std::string& path() const { return path_; }

 private:
  void AddKey(const std::string& key);

  std::string path_;
  std::vector<std::string> order_;
  std::map<std::string, std::vector<double>> numbers_;
  std::map<std::string, std::string> texts_;
  std::map<std::string, int> lines_;
};

// calib_cam_to_cam.txt, for one camera: the rectification R_rect_00 and the camera's own
// P_rect_<id> and S_rect_<id> (id "02" for image_02, "03" for image_03).
struct CameraCalibration {
  std::string id = "02";  ///< the camera's number in the file's keys
  Eigen::Matrix3d R_rect_00 = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 3, 4> P_rect = Eigen::Matrix<double, 3, 4>::Zero();  ///< P_rect_<id>
  int image_width = 0;   ///< from S_rect_<id> [px]
  int image_height = 0;  ///< from S_rect_<id> [px]
  KittiCalibFile file;   ///< every key of the file
  // A camera whose images are raw, not rectified (a bag's CameraInfo): its model ("plumb_bob",
  // "rational_polynomial", "equidistant"), matrix and coefficients, which RectifyImage
  // (core/io/image.h) undoes onto P_rect. Empty model: the images are rectified (KITTI's).
  std::string distortion_model;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  std::vector<double> distortion;
  // The camera's frame (the one P_rect·R_rect_00 projects from) relative to the frame of
  // calib_velo_to_cam.txt, x_camera = R·x + T: stcalib's keys R_rig_<id> and T_rig_<id>, for a
  // rig whose cameras turn away from camera 0 (a simulated rig, docs/simulator.md). Identity
  // without them, as for KITTI's cameras, which all project from camera 0's frame.
  Rigid3d T_camera_reference = Rigid3d::Identity();
};

// calib_cam_to_cam.txt's keys for camera `id` ("02"); errors name the file and the key.
Status ReadCamToCam(const std::string& path, CameraCalibration* calibration,
                    const std::string& id = "02");
// The camera's rectified optical frame (its own centre, axes as its rectified image) from its
// frame: x_rectified = R_rect_00·x + t, where P_rect = K·[I | t] places the camera's centre
// (KITTI: image_03's 0.54 m baseline to image_02 is in P_rect_03's last column).
Rigid3d RectifiedFromCamera(const CameraCalibration& calibration);

// calib_velo_to_cam.txt: R (9) and T (3) of T_camera_lidar (LiDAR to unrectified camera 0); R
// is replaced by the nearest rotation.
Status ReadVeloToCam(const std::string& path, Rigid3d* T_camera_lidar);
// Writes R, T (and KITTI's delta_f / delta_c, zero) with 12 significant digits; a `note` (which
// axes a partial claim held) goes into the calib_time line, after "written by stcalib".
Status WriteVeloToCam(const std::string& path, const Rigid3d& T_camera_lidar,
                      const std::string& note = "");
std::string VeloToCamText(const Rigid3d& T_camera_lidar);  ///< what WriteVeloToCam writes

// time_offset.txt (stcalib's, beside its calib_velo_to_cam.txt): δ in seconds, one finite
// number within ±1 s; blank lines and comments (from # to the end of a line) are ignored. Errors
// name the file and what is wrong.
inline constexpr char kTimeOffsetFileName[] = "time_offset.txt";
Status ReadTimeOffset(const std::string& path, double* time_offset_s);
// 9 decimals; a `note` follows on a comment line ("# note").
Status WriteTimeOffset(const std::string& path, double time_offset_s, const std::string& note = "");

// calib_imu_to_velo.txt: R (9) and T (3) of T_lidar_imu.
Status ReadImuToVelo(const std::string& path, Rigid3d* T_lidar_imu);
Status WriteImuToVelo(const std::string& path, const Rigid3d& T_lidar_imu);

// Checks that a 3x3 matrix read from `what` is a rotation: orthonormal and det +1 to within
// kRotationTolerance (largest entry of R·Rᵀ − I). Files print ~7 digits (KITTI's rotations are
// ~1e-7 from orthonormal); the rigid transforms (velo_to_cam, imu_to_velo) are then moved to the
// nearest exact rotation, so that nothing downstream works with a slightly skewed matrix.
constexpr double kRotationTolerance = 1e-3;
Status CheckRotation(const Eigen::Matrix3d& rotation, const std::string& what);

}  // namespace stcalib
