#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/types/status.h"

namespace stcalib {

// KITTI stamps are kept exactly, as nanoseconds since the Unix epoch (UTC).
using StampNs = int64_t;

inline double NsToSeconds(int64_t ns) { return static_cast<double>(ns) * 1e-9; }
inline int64_t SecondsToNs(double s) { return static_cast<int64_t>(std::llround(s * 1e9)); }

// Parses "YYYY-MM-DD HH:MM:SS.nnnnnnnnn" (1–9 fraction digits, years 1900–2200). False on any
// malformation.
bool ParseKittiTimestamp(const std::string& text, StampNs* stamp_ns);

// Formats as "YYYY-MM-DD HH:MM:SS.nnnnnnnnn" (always 9 fraction digits).
std::string FormatKittiTimestamp(StampNs stamp_ns);

// Reads a KITTI timestamps file: one stamp per line; trailing blank lines are ignored.
// Errors name the file and line.
Status ReadTimestampsFile(const std::string& path, std::vector<StampNs>* stamps_ns);

Status WriteTimestampsFile(const std::string& path, const std::vector<StampNs>& stamps_ns);

}  // namespace stcalib
