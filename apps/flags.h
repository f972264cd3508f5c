#pragma once

#include <gflags/gflags.h>

// Every flag of the stcalib CLI is defined in flags.cc and mapped into option structs by the
// subcommand that uses it; core/ never sees gflags.
DECLARE_string(drive);
DECLARE_string(calib_dir);
DECLARE_string(bag);
DECLARE_string(image_topic);
DECLARE_string(cloud_topic);
DECLARE_string(camera_info_topic);
DECLARE_string(odom_topic);
DECLARE_string(imu_topic);
DECLARE_int32(frame);
DECLARE_string(out);
DECLARE_int32(frames);
DECLARE_uint64(seed);
DECLARE_double(time_offset_s);
DECLARE_int32(dynamic_objects);
DECLARE_string(scene);
DECLARE_string(camera);
DECLARE_string(lidar);
DECLARE_double(distortion_k1);
DECLARE_double(speed_mps);
DECLARE_double(lidar_hz);
DECLARE_double(oxts_white_position_m);
DECLARE_double(oxts_error_scale);
DECLARE_string(detector);
DECLARE_double(min_segment_px);
DECLARE_double(max_edge_density);
DECLARE_string(cameras);
DECLARE_bool(rig_joint);
DECLARE_string(init_calib);
DECLARE_string(init_uncertainty);
DECLARE_double(perturb_rot_deg);
DECLARE_double(perturb_trans_m);
DECLARE_double(perturb_time_s);
DECLARE_int32(first_frame);
DECLARE_int32(num_frames);
DECLARE_int32(window_frames);
DECLARE_double(time_offset_bound_s);
DECLARE_bool(estimate_time_offset);
DECLARE_string(loss);
DECLARE_double(horizontal_weight);
DECLARE_double(prior_sigma_translation_m);
DECLARE_double(prior_sigma_time_s);
DECLARE_int32(refine_frames);
DECLARE_double(tracking_gain);
DECLARE_double(tracking_max_lag_deg);
DECLARE_double(refined_score_tolerance);
DECLARE_int32(tracking_update_every);
DECLARE_double(observable_rotation_deg);
DECLARE_double(min_health);
DECLARE_int32(local_map_sweeps);
DECLARE_bool(remove_dynamic);
DECLARE_bool(use_ndt);
DECLARE_bool(suppress_texture);
DECLARE_int32(disturb_frame);
DECLARE_double(disturb_rot_deg);
DECLARE_int32(lidar_decimation);
DECLARE_double(lidar_delay_s);
DECLARE_double(eval_max_range_m);
DECLARE_bool(polish);
DECLARE_bool(bandpass_score);
DECLARE_double(point_margin);
DECLARE_string(lidar_folds);
