#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/io/image.h"
#include "core/io/kitti_calib.h"
#include "core/io/oxts.h"
#include "core/io/timestamps.h"
#include "core/io/velodyne.h"
#include "core/types/status.h"
#include "core/types/transform.h"

namespace stcalib {

// Where a drive's images and sweeps come from when they are not KITTI files (a ROS 2 bag,
// core/io/bag_drive.h).
class FrameStore {
 public:
  virtual ~FrameStore() = default;
  virtual Status LoadImage(size_t frame, cv::Mat* image_bgr) const = 0;  ///< as stored (raw)
  virtual Status LoadScan(size_t frame, LidarScan* scan) const = 0;
  virtual std::string ScanName(size_t frame) const = 0;  ///< names the sweep in messages
};

// One sample of the vehicle's motion from odometry: the body's pose in a world frame, its
// velocity in that world and its angular rates in the body frame.
struct OdometrySample {
  StampNs stamp_ns = 0;
  Rigid3d T_world_body = Rigid3d::Identity();
  Eigen::Vector3d velocity_world_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d rate_body_rad_s = Eigen::Vector3d::Zero();
};

// One IMU sample: its angular rates in the IMU frame.
struct ImuSample {
  StampNs stamp_ns = 0;
  Eigen::Vector3d rate_rad_s = Eigen::Vector3d::Zero();
};

// A drive as one camera and the LiDAR see it: KITTI raw synced (OpenDrive) or a ROS 2 bag read as
// one (OpenBagDrive, whose `store` serves the images and sweeps). KITTI's: the camera's folder
// (image_02/ by default), velodyne_points/ and (optionally) oxts/, each with data/ and
// timestamps.txt, plus the three calibration files in `calib_dir` (by default the drive's parent
// folder). Frame i is the i-th file of the camera's data/ in name order; every sensor must hold
// the same frame names and one stamp per frame. Several cameras of one drive are several Drives
// (one per camera) that share the LiDAR (DriveFrameSource::Create reads it once).
struct Drive {
  std::string drive_dir;
  std::string calib_dir;
  std::string camera_name = "image_02";  ///< the camera's folder (KITTI) or image topic (a bag)
  std::vector<std::string> frame_names;  ///< e.g. "0000000000"

  CameraCalibration camera;
  RectifyMaps rectify;  ///< raw images to rectified (camera.distortion_model set), else empty
  // LiDAR to the camera's frame: calib_velo_to_cam.txt, carried to the camera's own frame when it
  // is not camera 0's (CameraCalibration::T_camera_reference).
  Rigid3d T_camera_lidar = Rigid3d::Identity();
  bool has_imu_calibration = false;           ///< calib_imu_to_velo.txt read (oxts need it)
  Rigid3d T_lidar_imu = Rigid3d::Identity();  ///< from calib_imu_to_velo.txt

  std::vector<StampNs> camera_stamps_ns;       ///< <camera>/timestamps.txt
  std::vector<StampNs> lidar_stamps_ns;        ///< velodyne_points/timestamps.txt
  std::vector<StampNs> lidar_start_stamps_ns;  ///< timestamps_start.txt (empty if absent)
  std::vector<StampNs> lidar_end_stamps_ns;    ///< timestamps_end.txt (empty if absent)

  bool has_oxts = false;
  std::vector<StampNs> oxts_stamps_ns;  ///< oxts/timestamps.txt
  std::vector<OxtsPacket> oxts;         ///< one packet per frame

  // A bag's odometry instead of oxts (the body is the frame T_lidar_imu places, "imu" above).
  std::vector<OdometrySample> odometry;
  // A bag's IMU: angular rates in its frame (T_lidar_imu places it), which shape the rotation
  // between registered sweeps (DriveMotion::CreateFromScans).
  std::vector<ImuSample> imu;
  // Set for a drive read from a bag: its images and sweeps come from there, not from files.
  std::shared_ptr<const FrameStore> store;

  size_t NumFrames() const { return frame_names.size(); }
  std::string ImagePath(size_t frame) const;
  std::string VelodynePath(size_t frame) const;
  std::string LabelsPath(size_t frame) const;  ///< simulated drives only
  std::string ScanName(size_t frame) const;    ///< the .bin path, or the store's name for it
  Status LoadImage(size_t frame, cv::Mat* image_bgr) const;     ///< rectified
  Status LoadRawImage(size_t frame, cv::Mat* image_bgr) const;  ///< as stored
  Status LoadScan(size_t frame, LidarScan* scan) const;
  // Checks `frame` against the number of frames; the error names the drive.
  Status CheckFrame(size_t frame) const;
};

// Opens a drive as `camera` sees it ("image_02", "image_03", …: its folder, and "02", "03", … in
// calib_cam_to_cam.txt's keys): lists frames, reads every stamp file, the oxts packets and the
// calibration. `calib_dir` empty means the parent of `drive_dir`. Errors name the camera when its
// folder or keys are missing.
Status OpenDrive(const std::string& drive_dir, const std::string& calib_dir, Drive* drive,
                 const std::string& camera = "image_02");
// Whether `name` names a KITTI camera folder: "image_" and two digits.
bool IsKittiCameraName(const std::string& name);

}  // namespace stcalib
