#pragma once

#include <vector>

#include "core/io/oxts.h"
#include "core/types/transform.h"

namespace stcalib {

// GPS/INS poses from oxts packets, as KITTI's devkit builds them: a local east-north-up world
// whose x/y come from a Mercator projection scaled by cos(origin latitude), z = altitude, and
// the vehicle (IMU) attitude R = Rz(yaw) · Ry(pitch) · Rx(roll).
struct OxtsOrigin {
  double lat_deg = 0;
  double lon_deg = 0;
  double alt_m = 0;
};

// Mercator coordinates [m] of a latitude/longitude with the scale of `origin`, relative to it.
Eigen::Vector2d MercatorOffset(const OxtsOrigin& origin, double lat_deg, double lon_deg);

// T_world_imu of one packet in the world of `origin`.
Rigid3d OxtsPose(const OxtsOrigin& origin, const OxtsPacket& packet);

// Vehicle attitude of a packet: Rz(yaw) · Ry(pitch) · Rx(roll).
Eigen::Matrix3d OxtsAttitude(const OxtsPacket& packet);

// Dead reckoning: starting at `start_position`, integrates the earth-parallel velocities
// (vf, vl, vu, rotated by each packet's yaw) over the packet stamps with the trapezoidal rule.
// Returns one position per packet.
std::vector<Eigen::Vector3d> IntegrateOxtsVelocities(const std::vector<OxtsPacket>& packets,
                                                     const std::vector<double>& stamps_s,
                                                     const Eigen::Vector3d& start_position);

}  // namespace stcalib
