#include "core/motion/oxts_poses.h"

#include <glog/logging.h>

#include <cmath>

namespace stcalib {
namespace {
constexpr double kEarthRadiusM = 6378137.0;
constexpr double kDegToRad = M_PI / 180.0;
}  // namespace

Eigen::Vector2d MercatorOffset(const OxtsOrigin& origin, double lat_deg, double lon_deg) {
  const double scale = std::cos(origin.lat_deg * kDegToRad);
  auto mercator = [&](double lat, double lon) {
    return Eigen::Vector2d(scale * kEarthRadiusM * lon * kDegToRad,
                           scale * kEarthRadiusM * std::log(std::tan(M_PI * (90.0 + lat) / 360.0)));
  };
  return mercator(lat_deg, lon_deg) - mercator(origin.lat_deg, origin.lon_deg);
}

Eigen::Matrix3d OxtsAttitude(const OxtsPacket& packet) {
  return (Eigen::AngleAxisd(packet.yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(packet.pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(packet.roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Rigid3d OxtsPose(const OxtsOrigin& origin, const OxtsPacket& packet) {
  const Eigen::Vector2d xy = MercatorOffset(origin, packet.lat, packet.lon);
  return MakeRigid(OxtsAttitude(packet),
                   Eigen::Vector3d(xy.x(), xy.y(), packet.alt - origin.alt_m));
}

std::vector<Eigen::Vector3d> IntegrateOxtsVelocities(const std::vector<OxtsPacket>& packets,
                                                     const std::vector<double>& stamps_s,
                                                     const Eigen::Vector3d& start_position) {
  CHECK_EQ(packets.size(), stamps_s.size());
  auto world_velocity = [](const OxtsPacket& p) {
    const double c = std::cos(p.yaw), s = std::sin(p.yaw);
    return Eigen::Vector3d(c * p.vf - s * p.vl, s * p.vf + c * p.vl, p.vu);
  };
  std::vector<Eigen::Vector3d> positions;
  if (packets.empty()) return positions;
  positions.push_back(start_position);
  for (size_t i = 1; i < packets.size(); ++i) {
    const double dt = stamps_s[i] - stamps_s[i - 1];
    positions.push_back(positions.back() +
                        0.5 * dt * (world_velocity(packets[i - 1]) + world_velocity(packets[i])));
  }
  return positions;
}

}  // namespace stcalib
