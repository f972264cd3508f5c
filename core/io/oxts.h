#pragma once

#include <string>
#include <vector>

#include "core/types/status.h"

namespace stcalib {

// One OXTS RT3003 packet, the 30 fields of KITTI's oxts/dataformat.txt in file order.
struct OxtsPacket {
  double lat = 0;           ///< latitude [deg]
  double lon = 0;           ///< longitude [deg]
  double alt = 0;           ///< altitude [m]
  double roll = 0;          ///< [rad], 0 = level, positive = left side up
  double pitch = 0;         ///< [rad], 0 = level, positive = front down
  double yaw = 0;           ///< heading [rad], 0 = east, positive = counter-clockwise
  double vn = 0;            ///< velocity towards north [m/s]
  double ve = 0;            ///< velocity towards east [m/s]
  double vf = 0;            ///< forward velocity, parallel to earth surface [m/s]
  double vl = 0;            ///< leftward velocity, parallel to earth surface [m/s]
  double vu = 0;            ///< upward velocity, perpendicular to earth surface [m/s]
  double ax = 0;            ///< acceleration along body x (front) [m/s^2]
  double ay = 0;            ///< acceleration along body y (left) [m/s^2]
  double az = 0;            ///< acceleration along body z (top) [m/s^2]
  double af = 0;            ///< forward acceleration [m/s^2]
  double al = 0;            ///< leftward acceleration [m/s^2]
  double au = 0;            ///< upward acceleration [m/s^2]
  double wx = 0;            ///< angular rate around body x [rad/s]
  double wy = 0;            ///< angular rate around body y [rad/s]
  double wz = 0;            ///< angular rate around body z [rad/s]
  double wf = 0;            ///< angular rate around forward axis [rad/s]
  double wl = 0;            ///< angular rate around leftward axis [rad/s]
  double wu = 0;            ///< angular rate around upward axis [rad/s]
  double pos_accuracy = 0;  ///< position accuracy (north/east) [m]
  double vel_accuracy = 0;  ///< velocity accuracy (north/east) [m/s]
  int navstat = 0;          ///< navigation status
  int numsats = 0;          ///< satellites tracked by the primary GPS receiver
  int posmode = 0;          ///< position mode of the primary GPS receiver
  int velmode = 0;          ///< velocity mode of the primary GPS receiver
  int orimode = 0;          ///< orientation mode of the primary GPS receiver
};

constexpr int kOxtsFieldCount = 30;

// Parses one packet line; errors name `path` and line 1.
Status ParseOxtsPacket(const std::string& line, const std::string& path, OxtsPacket* packet);
// Reads one oxts/data/NNNNNNNNNN.txt file (one line of 30 numbers).
Status ReadOxtsPacket(const std::string& path, OxtsPacket* packet);
// Writes a packet line in KITTI's field order with full precision.
std::string FormatOxtsPacket(const OxtsPacket& packet);
Status WriteOxtsPacket(const std::string& path, const OxtsPacket& packet);

}  // namespace stcalib
