#pragma once

#include <vector>

#include "core/io/drive.h"
#include "core/io/oxts.h"
#include "core/io/timestamps.h"
#include "core/motion/oxts_poses.h"
#include "core/types/status.h"
#include "core/types/transform.h"

namespace stcalib {

// The vehicle (IMU) pose at any time from a drive's oxts packets: GPS/INS poses at the packet
// stamps (oxts_poses.h, origin at the first packet), cubic Hermite interpolation of the position
// with the packets' velocities, slerp of the attitude; beyond the first/last packet the pose is
// extrapolated with that packet's velocity and body rates.
class OxtsTrajectory {
 public:
  // A packet whose stamp does not increase (duplicated or out of order) is skipped with a
  // warning; fewer than one usable packet is an error.
  static Status Create(const std::vector<OxtsPacket>& packets,
                       const std::vector<StampNs>& stamps_ns, OxtsTrajectory* trajectory);

  // The same from odometry samples (a bag's nav_msgs/Odometry): their poses, world velocities
  // and body rates stand for the packets'.
  static Status FromOdometry(const std::vector<OdometrySample>& samples,
                             OxtsTrajectory* trajectory);

  Rigid3d T_world_imu(StampNs stamp_ns) const;
  Rigid3d T_world_imu_s(double seconds_since_reference) const;
  StampNs reference_ns() const { return reference_ns_; }
  size_t size() const { return times_s_.size(); }
  // The span between the packets around t [s], or to the nearest packet when t is outside them:
  // how far the pose at t is interpolated or extrapolated.
  double GapAround(double seconds_since_reference) const;

 private:
  StampNs reference_ns_ = 0;
  std::vector<double> times_s_;
  std::vector<Rigid3d> poses_;
  std::vector<Eigen::Vector3d> velocities_world_;
  std::vector<Eigen::Vector3d> rates_body_;
};

}  // namespace stcalib
