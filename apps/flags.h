#pragma once

#include <gflags/gflags.h>

// Every flag of the stcalib CLI is defined in flags.cc and mapped into option structs by the
// subcommand that uses it; core/ never sees gflags.
DECLARE_string(drive);
DECLARE_string(calib_dir);
DECLARE_int32(frame);
DECLARE_string(out);
