#include "apps/flags.h"

DEFINE_string(drive, "", "KITTI raw synced drive folder (image_02/, velodyne_points/, oxts/)");
DEFINE_string(calib_dir, "",
              "folder with calib_cam_to_cam.txt, calib_velo_to_cam.txt, calib_imu_to_velo.txt "
              "(default: the drive's parent folder)");
DEFINE_int32(frame, 0, "frame index (0-based, in file-name order)");
DEFINE_string(out, "", "output file or folder");
DEFINE_int32(frames, 40, "simulate: number of frames");
DEFINE_uint64(seed, 1, "random seed (simulate: the whole drive)");
DEFINE_double(time_offset_s, 0.0,
              "simulate: true time offset δ [s]; LiDAR stamps are the true time minus δ");
DEFINE_int32(dynamic_objects, 6, "simulate: moving vehicles and pedestrians");
DEFINE_string(scene, "urban", "simulate: urban | poles (vertical structures only) | open");
DEFINE_double(lidar_hz, 10.0, "simulate: LiDAR spin rate = frame rate of every sensor [Hz]");
DEFINE_string(detector, "canny", "image edges: canny | lsd | fld (cv::ximgproc FastLineDetector)");
DEFINE_double(min_segment_px, 15, "lsd/fld: shorter segments are dropped as texture [px]");
DEFINE_double(max_edge_density, 0.0,
              "features: drop edge pixels in windows denser than this share (texture), 0 = off");
// calibrate
DEFINE_string(init_calib, "", "calibrate: initial calib_velo_to_cam.txt (default: the drive's)");
DEFINE_double(perturb_rot_deg, 0.0,
              "calibrate: add this roll/pitch/yaw error (random signs) [deg]");
DEFINE_double(perturb_trans_m, 0.0, "calibrate: add this x/y/z error (random signs) [m]");
DEFINE_double(perturb_time_s, 0.0, "calibrate: initial time offset δ0 [s]");
DEFINE_int32(first_frame, 0, "calibrate: first frame used");
DEFINE_int32(num_frames, 0, "calibrate: frames used (0 = to the end)");
DEFINE_int32(window_frames, 3, "calibrate: sliding window of frames searched and refined together");
DEFINE_double(time_offset_bound_s, 0.15, "calibrate: |δ| bound [s]");
DEFINE_bool(estimate_time_offset, true, "calibrate: estimate δ (false: keep δ0)");
DEFINE_string(loss, "cauchy", "calibrate: robust loss, cauchy | huber");
// Refinement from drive 0013's calibration over frames 0-29: 0.27 deg at 1 px, 0.35 at 3 px.
DEFINE_double(loss_scale_px, 1.0, "calibrate: robust-loss scale [px]");
// The defaults are set for real streets (KITTI drive 0013, tree-lined) and also serve simulated
// drives (configs/sim.flags). Horizontal LiDAR edges are the less faithful ones (foliage tops
// scatter; the tops of cars seen from above show a roof sliver in the image): at w = 0.5 the first
// 8 frames of drive 0013 sat on a side peak 4-6 deg off, at w = 0.2 they are 0.2-0.7 deg off by
// frame 5; over all 30 frames the score peaks at the same roll and yaw for any w in [0, 1].
DEFINE_double(horizontal_weight, 0.2, "calibrate: weight w of horizontal edges (vertical: 1 - w)");
DEFINE_double(alpha1_rotation_deg, 1.0, "search: large rotation step [deg]");
DEFINE_double(alpha2_translation_m, 0.04, "search: large translation step [m]");
DEFINE_double(alpha3_rotation_deg, 0.2, "search: small rotation step [deg]");
DEFINE_double(alpha4_translation_m, 0.01, "search: small translation step [m]");
DEFINE_double(gamma, 0.45, "search: gray-rate threshold between the large and the small step pair");
DEFINE_double(lost_health, 0.9, "calibrate: below this health the search goes coarse-to-fine");
DEFINE_double(prior_sigma_rotation_deg, 2.0, "refine: weak rotation prior [deg]");
DEFINE_double(prior_sigma_translation_m, 0.05,
              "search and refine: translation prior around the start [m]");
DEFINE_double(prior_sigma_forward_m, 0.05,
              "refine: translation prior along the direction of travel, per point [m]");
DEFINE_double(prior_sigma_time_s, 0.03, "search and refine: time-offset prior around δ0 [s]");
// A few frames can prefer a side peak 3.5 deg off (drive 0013, frames 10-16): refine on 20.
DEFINE_int32(refine_frames, 20, "calibrate: latest frames in the refinement");
DEFINE_int32(max_points_per_frame, 300, "refine: LiDAR edge points used per frame");
// Single windows on a street scatter by a few tenths of a degree: average while tracking.
DEFINE_double(tracking_gain, 0.3, "calibrate: share of an accepted update taken while tracking");
DEFINE_double(observable_rotation_deg, 0.15,
              "refine: a rotation axis is observable below this std [deg]");
DEFINE_double(observable_translation_m, 0.04,
              "refine: a translation axis is observable below this std [m]");
DEFINE_double(observable_time_s, 0.006, "refine: δ is observable below this std [s]");
DEFINE_double(min_health, 0.85,
              "check, calibrate: the calibration holds when the mean health reaches this");
DEFINE_bool(check_suppressed_health, true,
            "calibrate: converged also needs the health check on texture-suppressed maps of the "
            "last 9 frames to hold");
DEFINE_int32(local_map_sweeps, 3, "calibrate: sweeps merged into the local map");
DEFINE_bool(remove_dynamic, true, "calibrate: remove LiDAR points of moving objects");
DEFINE_bool(use_ndt, false, "calibrate: refine the local map's poses with PCL NDT");
// Dense foliage traps the plain score degrees from the truth (method.md §10): score on
// texture-suppressed maps, band-pass (not clipped: foliage averages to zero instead of pulling
// points into it).
DEFINE_bool(suppress_texture, true, "calibrate: score on texture-suppressed maps");
DEFINE_bool(
    oriented_maps, true,
    "calibrate: vertical/horizontal LiDAR edges read maps of vertical/horizontal image edges");
DEFINE_int32(disturb_frame, -1,
             "calibrate: at this frame add a rotation disturbance (test protocol)");
DEFINE_double(disturb_rot_deg, 2.0,
              "calibrate: size of that disturbance on roll, pitch and yaw [deg]");
// eval-temporal
DEFINE_int32(lidar_decimation, 2, "eval-temporal: keep every n-th sweep");
DEFINE_double(lidar_delay_s, 0.1, "eval-temporal: the kept sweeps arrive this late [s]");
DEFINE_double(eval_max_range_m, 120.0, "eval-temporal: points beyond this range are left out [m]");
DEFINE_bool(coarse_until_window_full, true,
            "calibrate: coarse-to-fine search on every frame until the search window is full");
DEFINE_bool(wait_for_full_window, true,
            "calibrate: no update before the search window holds --window_frames frames");
DEFINE_bool(search_from_last_healthy, true,
            "calibrate: when lost, also search from the last healthy estimate");
DEFINE_bool(polish, true,
            "calibrate: refine the final estimate over the refinement's frames from itself");
// The band-pass peak is narrow (about +-1 deg) but global: find it with a rotation grid of
// +-3 deg around the initial calibration while acquiring and when lost.
DEFINE_double(lost_grid_deg, 3.0,
              "calibrate: when lost, first an exhaustive rotation grid of +-this [deg] (0 = none)");
DEFINE_double(lost_grid_step_deg, 0.5, "calibrate: step of that grid [deg]");
DEFINE_bool(acquire_time_offset, true,
            "calibrate: while acquiring, scan δ over its whole bound after the rotation grid");
DEFINE_bool(bandpass_score, true,
            "calibrate: with --suppress_texture, score on the band-pass IDT (not clipped at 0)");
// A band-pass score is near zero on average, so points just outside the image cost nothing:
// keep them (pruning at a wrong estimate would favour it).
DEFINE_double(point_margin, -0.1,
              "calibrate: LiDAR edge points are kept when they project inside the image shrunk by "
              "this share of its size (negative: grown) at the estimate when their frame arrives");
