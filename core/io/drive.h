#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/io/kitti_calib.h"
#include "core/io/oxts.h"
#include "core/io/timestamps.h"
#include "core/io/velodyne.h"
#include "core/types/status.h"
#include "core/types/transform.h"

namespace stcalib {

// A KITTI raw synced drive: image_02/, velodyne_points/ and (optionally) oxts/, each with data/
// and timestamps.txt, plus the three calibration files in `calib_dir` (by default the drive's
// parent folder). Frame i is the i-th file of image_02/data in name order; every sensor must
// hold the same frame names and one stamp per frame.
struct Drive {
  std::string drive_dir;
  std::string calib_dir;
  std::vector<std::string> frame_names;  ///< e.g. "0000000000"

  CameraCalibration camera;
  Rigid3d T_camera_lidar = Rigid3d::Identity();  ///< from calib_velo_to_cam.txt
  bool has_imu_calibration = false;              ///< calib_imu_to_velo.txt read (oxts need it)
  Rigid3d T_lidar_imu = Rigid3d::Identity();     ///< from calib_imu_to_velo.txt

  std::vector<StampNs> camera_stamps_ns;       ///< image_02/timestamps.txt
  std::vector<StampNs> lidar_stamps_ns;        ///< velodyne_points/timestamps.txt
  std::vector<StampNs> lidar_start_stamps_ns;  ///< timestamps_start.txt (empty if absent)
  std::vector<StampNs> lidar_end_stamps_ns;    ///< timestamps_end.txt (empty if absent)

  bool has_oxts = false;
  std::vector<StampNs> oxts_stamps_ns;  ///< oxts/timestamps.txt
  std::vector<OxtsPacket> oxts;         ///< one packet per frame

  size_t NumFrames() const { return frame_names.size(); }
  std::string ImagePath(size_t frame) const;
  std::string VelodynePath(size_t frame) const;
  std::string LabelsPath(size_t frame) const;  ///< simulated drives only
  Status LoadImage(size_t frame, cv::Mat* image_bgr) const;
  Status LoadScan(size_t frame, LidarScan* scan) const;
  // Checks `frame` against the number of frames; the error names the drive.
  Status CheckFrame(size_t frame) const;
};

// Opens a drive: lists frames, reads every stamp file, the oxts packets and the calibration.
// `calib_dir` empty means the parent of `drive_dir`.
Status OpenDrive(const std::string& drive_dir, const std::string& calib_dir, Drive* drive);

}  // namespace stcalib
