#pragma once

#include <gflags/gflags.h>

// Every flag of the stcalib CLI is defined in flags.cc and mapped into option structs by the
// subcommand that uses it; core/ never sees gflags.
DECLARE_string(drive);
DECLARE_string(calib_dir);
DECLARE_int32(frame);
DECLARE_string(out);
DECLARE_int32(frames);
DECLARE_uint64(seed);
DECLARE_double(time_offset_s);
DECLARE_int32(dynamic_objects);
DECLARE_string(scene);
DECLARE_double(lidar_hz);
DECLARE_string(detector);
DECLARE_double(min_segment_px);
DECLARE_double(max_edge_density);
DECLARE_string(init_calib);
DECLARE_double(perturb_rot_deg);
DECLARE_double(perturb_trans_m);
DECLARE_double(perturb_time_s);
DECLARE_int32(first_frame);
DECLARE_int32(num_frames);
DECLARE_int32(window_frames);
DECLARE_double(time_offset_bound_s);
DECLARE_bool(estimate_time_offset);
DECLARE_string(loss);
DECLARE_double(loss_scale_px);
DECLARE_double(horizontal_weight);
DECLARE_double(alpha1_rotation_deg);
DECLARE_double(alpha2_translation_m);
DECLARE_double(alpha3_rotation_deg);
DECLARE_double(alpha4_translation_m);
DECLARE_double(gamma);
DECLARE_double(lost_health);
DECLARE_double(prior_sigma_rotation_deg);
DECLARE_double(prior_sigma_translation_m);
DECLARE_double(prior_sigma_forward_m);
DECLARE_double(prior_sigma_time_s);
DECLARE_int32(refine_frames);
DECLARE_int32(max_points_per_frame);
DECLARE_double(tracking_gain);
DECLARE_double(observable_rotation_deg);
DECLARE_double(observable_translation_m);
DECLARE_double(observable_time_s);
DECLARE_double(min_health);
DECLARE_bool(check_suppressed_health);
DECLARE_int32(local_map_sweeps);
DECLARE_bool(remove_dynamic);
DECLARE_bool(use_ndt);
DECLARE_bool(suppress_texture);
DECLARE_int32(disturb_frame);
DECLARE_double(disturb_rot_deg);
DECLARE_bool(oriented_maps);
DECLARE_int32(lidar_decimation);
DECLARE_double(lidar_delay_s);
DECLARE_double(eval_max_range_m);
DECLARE_bool(coarse_until_window_full);
DECLARE_bool(wait_for_full_window);
DECLARE_bool(search_from_last_healthy);
DECLARE_bool(polish);
DECLARE_double(lost_grid_deg);
DECLARE_double(lost_grid_step_deg);
DECLARE_bool(acquire_time_offset);
DECLARE_bool(bandpass_score);
DECLARE_double(point_margin);
