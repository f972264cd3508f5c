#include "apps/flags.h"

#include "core/features/image_features.h"
#include "core/online/convergence.h"
#include "core/online/frame_source.h"
#include "core/online/online_calibrator.h"

DEFINE_string(drive, "", "KITTI raw synced drive folder (image_02/, velodyne_points/, oxts/)");
DEFINE_string(calib_dir, "",
              "folder with calib_cam_to_cam.txt, calib_velo_to_cam.txt, calib_imu_to_velo.txt "
              "(default: the drive's parent folder)");
DEFINE_string(bag, "",
              "ROS 2 bag folder (metadata.yaml with .mcap or .db3 files): info, project, "
              "features, check and calibrate read it instead of --drive; convert writes there");
DEFINE_string(image_topic, "", "--bag: sensor_msgs/msg/Image or CompressedImage topic");
DEFINE_string(cloud_topic, "", "--bag: sensor_msgs/msg/PointCloud2 topic");
DEFINE_string(camera_info_topic, "",
              "--bag: sensor_msgs/msg/CameraInfo topic (default: beside the image "
              "topic, NS/camera_info)");
DEFINE_string(odom_topic, "",
              "--bag: nav_msgs/msg/Odometry topic for the motion (default: none, the "
              "sweeps are registered)");
DEFINE_string(imu_topic, "",
              "--bag: sensor_msgs/msg/Imu topic whose rates shape the rotation between "
              "registered sweeps (without --odom_topic)");
DEFINE_int32(frame, 0, "frame index (0-based, in file-name order)");
DEFINE_string(out, "",
              "output file or folder (calibrate, eval-temporal: optional; without it nothing "
              "is written and the result is printed)");
DEFINE_int32(frames, 40, "simulate: number of frames");
DEFINE_uint64(seed, 1, "random seed (simulate: the whole drive)");
DEFINE_double(time_offset_s, 0.0,
              "simulate: true time offset δ [s]; LiDAR stamps are the true time minus δ");
DEFINE_int32(dynamic_objects, 6, "simulate: moving vehicles and pedestrians");
DEFINE_string(scene, "urban", "simulate: urban | poles (vertical structures only) | open");
DEFINE_string(camera, "kitti",
              "simulate: kitti (1242x375) | kitti_1003 (1241x376) | hd720 (1280x720, 3 deg "
              "nose-down)");
DEFINE_string(lidar, "hdl64",
              "simulate: hdl64 (KITTI's Velodyne HDL-64E) | vlp16 (Velodyne VLP-16) | os1-64 "
              "(Ouster OS1-64)");
DEFINE_double(distortion_k1, 0.0,
              "simulate: radial distortion k1 of raw camera images (plumb_bob; 0 = rectified "
              "images, as KITTI's)");
DEFINE_double(
    speed_mps, 0.0,
    "simulate: mean speed of the ego vehicle [m/s] (0 = a random 10-13 m/s; 1.5 = walking "
    "pace, too slow for the time offset to be seen)");
DEFINE_double(lidar_hz, 10.0, "simulate: LiDAR spin rate = frame rate of every sensor [Hz]");
DEFINE_double(oxts_white_position_m, 0.001,
              "simulate: σ of each oxts packet's own position noise per axis, on top of the "
              "smooth drift of a GPS/INS solution [m]; 0.01 stresses the local map");
DEFINE_double(oxts_error_scale, 1.0,
              "simulate: multiplies every σ of the oxts error, drift and white noise alike "
              "(after --oxts_white_position_m); 0 = exact navigation, 2-3 = a poorer GPS/INS");
DEFINE_string(detector, stcalib::DetectorName(stcalib::ImageFeatureOptions().detector).c_str(),
              "features, calibrate, demo, check: image edges: canny | lsd | fld "
              "(cv::ximgproc FastLineDetector)");
DEFINE_double(min_segment_px, stcalib::ImageFeatureOptions().min_segment_length_px,
              "features, calibrate, demo, check: lsd/fld segments shorter than this are dropped "
              "as texture [px]");
DEFINE_double(max_edge_density, stcalib::ImageFeatureOptions().max_edge_density,
              "features, calibrate, demo, check: drop edge pixels in windows denser than this "
              "share (texture, any detector), 0 = off");
// calibrate
DEFINE_string(cameras, "",
              "calibrate: KITTI camera folders to calibrate in one pass over the LiDAR, comma "
              "separated (image_02,image_03); each gets OUT/<camera>/, the rig OUT/result.json "
              "(default: image_02 alone, outputs in OUT). simulate: the rig's number of cameras, "
              "1-4 (image_02 ahead, image_03 left, image_04 right, image_05 rear; default 1)");
DEFINE_bool(rig_joint, false,
            "calibrate with several --cameras: also refine one LiDAR extrinsic for the rig over "
            "every claimed camera's frames, the rig's camera-to-camera transforms imposed "
            "(result.json's `joint`, beside each camera's own estimate)");
DEFINE_string(init_calib, "", "calibrate: initial calib_velo_to_cam.txt (default: the drive's)");
DEFINE_double(perturb_rot_deg, 0.0,
              "calibrate: add this roll/pitch/yaw error (random signs) [deg]");
DEFINE_double(perturb_trans_m, 0.0, "calibrate: add this x/y/z error (random signs) [m]");
DEFINE_double(
    perturb_time_s, 0.0,
    "calibrate: initial time offset δ0 [s]; check: added to the stored δ (time_offset.txt "
    "beside the checked calib_velo_to_cam.txt, else 0)");
DEFINE_int32(first_frame, 0, "calibrate: first frame used");
DEFINE_int32(num_frames, 0, "calibrate: frames used (0 = to the end)");
// Defaults of the tuning flags come from the library's option structs, where the reasons for
// each value are written down: `stcalib calibrate` and a library user start alike.
namespace {
const stcalib::OnlineCalibratorOptions kOnline;
const stcalib::FrameSourceOptions kSource;
const stcalib::ConvergenceOptions kConvergence;
}  // namespace
DEFINE_string(init_uncertainty, StartUncertaintyText(kOnline.start_uncertainty).c_str(),
              "calibrate: how far off the start may be on each axis, ROT_DEG,TRANS_M,TIME_S "
              "(positive): the acquisition's hypothesis lattice spans it, and the bounds and the "
              "translation and time offset priors hold it");
DEFINE_int32(window_frames, kOnline.window_frames,
             "calibrate: sliding window of frames searched and refined together");
DEFINE_double(time_offset_bound_s, kOnline.time_offset_bound_s, "calibrate: |δ| bound [s]");
DEFINE_bool(estimate_time_offset, kOnline.refine.estimate_time_offset,
            "calibrate: estimate δ (false: keep δ0)");
DEFINE_string(loss, LossName(kOnline.refine.loss).c_str(),
              "calibrate: robust loss while acquiring, huber | cauchy | tukey");
DEFINE_double(horizontal_weight, kOnline.horizontal_weight,
              "calibrate: weight w of horizontal edges (vertical: 1 - w)");
DEFINE_double(prior_sigma_translation_m, kOnline.refine.prior_sigma_translation_m,
              "search and refine: translation prior around the start [m]");
DEFINE_double(prior_sigma_time_s, kOnline.refine.prior_sigma_time_s,
              "search and refine: time-offset prior around δ0 [s]");
DEFINE_int32(refine_frames, kOnline.refine_frames, "calibrate: latest frames in the refinement");
DEFINE_double(tracking_gain, kOnline.tracking_gain,
              "calibrate: share of an accepted update taken while tracking");
DEFINE_double(tracking_max_lag_deg, kOnline.tracking_max_lag_deg,
              "calibrate: while tracking, the rotation moves at least to within this of an "
              "accepted update's estimate (0 = tracking_gain only) [deg]");
DEFINE_double(refined_score_tolerance, kOnline.refined_score_tolerance,
              "calibrate: the refined rotation is taken when it scores within this share of "
              "the best candidate (0 = the best score wins)");
DEFINE_int32(tracking_update_every, kOnline.tracking_update_every,
             "calibrate: while tracking, search and refine on every n-th frame (1 = every frame)");
DEFINE_double(observable_rotation_deg, kOnline.refine.observable_rotation_deg,
              "refine: a rotation axis is observable below this std [deg]");
DEFINE_double(min_health, kConvergence.health_check.min_health,
              "check, calibrate: the calibration holds when the mean health reaches this");
DEFINE_int32(local_map_sweeps, kSource.local_map.sweeps,
             "calibrate: sweeps merged into the local map");
DEFINE_bool(remove_dynamic, kSource.lidar.remove_dynamic,
            "calibrate: remove LiDAR points of moving objects");
DEFINE_bool(use_ndt, kSource.local_map.use_ndt,
            "calibrate: refine the local map's poses with PCL NDT");
DEFINE_bool(suppress_texture, kSource.suppress_texture,
            "calibrate: score on texture-suppressed maps");
DEFINE_int32(disturb_frame, -1,
             "calibrate: at this frame add a rotation disturbance (test protocol)");
DEFINE_double(disturb_rot_deg, 2.0,
              "calibrate: size of that disturbance on roll, pitch and yaw [deg]");
// eval-temporal
DEFINE_int32(lidar_decimation, 2, "eval-temporal: keep every n-th sweep");
DEFINE_double(lidar_delay_s, 0.1, "eval-temporal: the kept sweeps arrive this late [s]");
DEFINE_double(eval_max_range_m, 120.0, "eval-temporal: points beyond this range are left out [m]");
DEFINE_bool(polish, true,
            "calibrate: refine the final estimate over the refinement's frames from itself");
DEFINE_bool(bandpass_score, kSource.bandpass_score,
            "calibrate: with --suppress_texture, score on the band-pass IDT (not clipped at 0)");
DEFINE_string(
    lidar_folds, stcalib::FoldsName(kOnline.folds).c_str(),
    "calibrate: LiDAR horizontal edges below the sensor whose beam above returns at their "
    "own height (a top's front corner seen from above, or its outline against a "
    "background at that height): keep | drop | drop_when_tracking (the default: dropped "
    "from the first frame after the acquisition, which then updates by a full step); the "
    "health always reads them");
DEFINE_double(point_margin, kOnline.point_margin,
              "calibrate: LiDAR edge points are kept when they project inside the image shrunk by "
              "this share of its size (negative: grown) at the estimate when their frame arrives");
