#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/io/kitti_calib.h"
#include "core/io/timestamps.h"
#include "core/motion/oxts_poses.h"
#include "core/sim/road.h"
#include "core/sim/scene.h"
#include "core/sim/sensors.h"
#include "core/sim/trajectory.h"
#include "core/types/status.h"

namespace stcalib::sim {

// The camera of a simulated rig. Each has its own image size, intrinsics and rectification, so
// that nothing downstream can assume one (the size is read from the image and the calib files).
enum class SimCamera {
  kKitti,      ///< KITTI 2011_09_26: 1242×375, f 721.5 px (default)
  kKitti1003,  ///< KITTI 2011_10_03 geometry: 1241×376, f 718.9 px, its own rectification
  kHd720,  ///< 1280×720, f 800 px (77°×48°), principal point off centre, mounted 3° nose-down;
           ///< the image reaches far above the LiDAR's +2° top beam
};
bool ParseSimCamera(const std::string& name, SimCamera* camera);
std::string SimCameraName(SimCamera camera);
std::string SimCameraChoices();  ///< "kitti, kitti_1003 or hd720"
// Intrinsics, rectification and size of `camera` (pose, sun and noise keep their defaults).
CameraRig MakeCameraRig(SimCamera camera);
bool ParseSimLidar(const std::string& name, SimLidar* lidar);
std::string SimLidarName(SimLidar lidar);
std::string SimLidarChoices();  ///< "hdl64, vlp16 or os1-64"

struct SimulatorOptions {
  int frames = 40;             ///< frames to simulate (camera, LiDAR and oxts each)
  uint64_t seed = 1;           ///< everything random derives from it
  double time_offset_s = 0.0;  ///< δ: LiDAR stamps = true mid-sweep time − δ [s]
  int dynamic_objects = 6;     ///< moving vehicles and pedestrians
  SceneType scene = SceneType::kUrban;
  double lidar_hz = 10.0;          ///< spin rate = frame rate of every sensor [Hz]
  double camera_delay_s = 0.0105;  ///< camera exposure after the LiDAR faces forward [s]
  SimCamera camera = SimCamera::kKitti;
  SimLidar lidar = SimLidar::kHdl64;
  // Radial distortion k1 of a raw camera image (0: rectified images, as KITTI's); the drive's
  // calib_cam_to_cam.txt then says so (distortion_model_02, K_02, D_02).
  double distortion_k1 = 0.0;
  // Mean speed of the ego vehicle [m/s]; 0: a random 10–13 m/s. A slow drive (walking pace)
  // moves too little over δ for the time offset to be seen.
  double speed_mps = 0.0;
  NavigationErrorOptions oxts_error;  ///< the oxts packets' drift and noise
  // Cameras of the rig (1 to 4): image_02 facing forward, then image_03 left, image_04 right and
  // image_05 rear, each with its own mount and δ (SimRigCamera); all share image_02's intrinsics.
  int cameras = 1;

  Status Validate() const;
};

// A camera of the rig other than image_02: where it is and how its clock is off.
struct SimRigCamera {
  std::string name;  ///< "image_03", …
  // Its frame from image_02's (x = R·x_02 + T): turned to face its side, off by up to ±0.5° per
  // axis and ±2 cm per seed; calib_cam_to_cam.txt's R_rig_0N and T_rig_0N.
  Rigid3d T_camera_reference = Rigid3d::Identity();
  Rigid3d T_camera_lidar = Rigid3d::Identity();  ///< its true extrinsic
  // Its δ: image_02's plus up to ±20 ms. Its image stamps are the true capture time + δ_k − δ.
  double time_offset_s = 0;
  CameraRig rig;  ///< image_02's intrinsics at its own pose
};

// True times and written stamps of one frame.
struct FrameTiming {
  double camera_time_s = 0;     ///< true capture time of the image (= its stamp) [s]
  double lidar_mid_time_s = 0;  ///< true time the LiDAR faces forward [s]
  double oxts_time_s = 0;       ///< true time of the oxts packet (= its stamp) [s]
  StampNs camera_stamp_ns = 0, lidar_stamp_ns = 0, lidar_start_stamp_ns = 0, lidar_end_stamp_ns = 0,
          oxts_stamp_ns = 0;
};

struct SimulatedFrame : FrameTiming {
  SimulatedSweep sweep;
  cv::Mat image_bgr;
  OxtsPacket oxts;
  // The rig's other cameras (Simulator::rig_cameras()'s order): their images and stamps.
  std::vector<cv::Mat> rig_images_bgr;
  std::vector<StampNs> rig_camera_stamps_ns;
};

// Ground truth and sensors of one simulated drive. Times are seconds from the drive's start
// epoch (stamps add `start_stamp_ns`); the camera clock is the true clock.
class Simulator {
 public:
  // `options` must be valid (call Validate() on user input first).
  explicit Simulator(const SimulatorOptions& options);

  SimulatedFrame SimulateFrame(int frame) const;
  FrameTiming Timing(int frame) const;
  OxtsPacket SimulateOxts(int frame) const;       ///< the packet of SimulateFrame(frame), alone
  SimulatedSweep SimulateSweep(int frame) const;  ///< the sweep of SimulateFrame(frame), alone

  const SimulatorOptions& options() const { return options_; }
  const Rigid3d& T_camera_lidar() const { return T_camera_lidar_; }
  const Rigid3d& T_lidar_imu() const { return T_lidar_imu_; }
  const CameraRig& camera_rig() const { return rig_; }
  const std::vector<SimRigCamera>& rig_cameras() const { return rig_cameras_; }
  const LidarModel& lidar_model() const { return lidar_; }
  const SimTrajectory& trajectory() const { return *trajectory_; }
  const Scene& scene() const { return *scene_; }
  const OxtsOrigin& oxts_origin() const { return origin_; }
  StampNs start_stamp_ns() const { return start_stamp_ns_; }
  double SweepDuration() const { return 1.0 / options_.lidar_hz; }
  double LidarMidTime(int frame) const { return 0.05 + frame / options_.lidar_hz; }
  // calib_cam_to_cam.txt contents (KITTI keys for image_02 and the rectification; each other
  // camera's P_rect_0N and S_rect_0N, and stcalib's R_rig_0N and T_rig_0N).
  KittiCalibFile CameraCalibFile() const;
  std::string DateFolder() const;  ///< e.g. "2026_01_02"

 private:
  SimulatorOptions options_;
  std::unique_ptr<SimRoad> road_;
  std::unique_ptr<SimTrajectory> trajectory_;
  std::unique_ptr<Scene> scene_;
  Rigid3d T_camera_lidar_, T_lidar_imu_;
  CameraRig rig_;
  std::vector<SimRigCamera> rig_cameras_;
  LidarModel lidar_;
  OxtsOrigin origin_;
  NavigationError oxts_error_;
  StampNs start_stamp_ns_ = 0;
};

// Writes a drive in KITTI raw layout (docs/method.md §9) under out_dir/<date>/: the three
// calibration files, ground_truth.json, and <date>_drive_0001_sync/ with image_02, velodyne_points
// (+ labels) and oxts. Everything goes to a hidden temporary folder first and is renamed into place
// at the end, so an interrupted run never leaves a drive that looks complete. `progress` (optional)
// is called after each frame.
Status WriteSimulatedDrive(const SimulatorOptions& options, const std::string& out_dir,
                           std::string* drive_dir,
                           const std::function<void(int done, int total)>& progress = nullptr);

}  // namespace stcalib::sim
