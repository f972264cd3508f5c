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
