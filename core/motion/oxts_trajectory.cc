#include "core/motion/oxts_trajectory.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace stcalib {

Status OxtsTrajectory::Create(const std::vector<OxtsPacket>& packets,
                              const std::vector<StampNs>& stamps_ns, OxtsTrajectory* trajectory) {
  if (packets.empty()) return Status::Error("oxts: no packets");
  if (packets.size() != stamps_ns.size()) {
    return Status::Error("oxts: " + std::to_string(packets.size()) + " packets but " +
                         std::to_string(stamps_ns.size()) + " stamps");
  }
  OxtsTrajectory t;
  t.reference_ns_ = stamps_ns.front();
  const OxtsOrigin origin{packets.front().lat, packets.front().lon, packets.front().alt};
  for (size_t i = 0; i < packets.size(); ++i) {
    const double time_s = NsToSeconds(stamps_ns[i] - t.reference_ns_);
    if (!t.times_s_.empty() && time_s <= t.times_s_.back()) {
      LOG(WARNING) << "oxts: packet " << i
                   << " skipped: its stamp does not increase (duplicated or out of order)";
      continue;
    }
    const OxtsPacket& p = packets[i];
    t.times_s_.push_back(time_s);
    t.poses_.push_back(OxtsPose(origin, p));
    const double c = std::cos(p.yaw), s = std::sin(p.yaw);
    t.velocities_world_.emplace_back(c * p.vf - s * p.vl, s * p.vf + c * p.vl, p.vu);
    t.rates_body_.emplace_back(p.wx, p.wy, p.wz);
  }
  *trajectory = std::move(t);
  return Status::Ok();
}

Status OxtsTrajectory::FromOdometry(const std::vector<OdometrySample>& samples,
                                    OxtsTrajectory* trajectory) {
  if (samples.empty()) return Status::Error("odometry: no messages");
  OxtsTrajectory t;
  t.reference_ns_ = samples.front().stamp_ns;
  for (size_t i = 0; i < samples.size(); ++i) {
    const double time_s = NsToSeconds(samples[i].stamp_ns - t.reference_ns_);
    if (!t.times_s_.empty() && time_s <= t.times_s_.back()) {
      LOG(WARNING) << "odometry: message " << i
                   << " skipped: its stamp does not increase (duplicated or out of order)";
      continue;
    }
    t.times_s_.push_back(time_s);
    t.poses_.push_back(samples[i].T_world_body);
    t.velocities_world_.push_back(samples[i].velocity_world_m_s);
    t.rates_body_.push_back(samples[i].rate_body_rad_s);
  }
  *trajectory = std::move(t);
  return Status::Ok();
}

double OxtsTrajectory::GapAround(double t) const {
  if (times_s_.empty()) return std::numeric_limits<double>::infinity();
  if (t <= times_s_.front()) return times_s_.front() - t;
  if (t >= times_s_.back()) return t - times_s_.back();
  const size_t i = std::upper_bound(times_s_.begin(), times_s_.end(), t) - times_s_.begin() - 1;
  return times_s_[i + 1] - times_s_[i];
}

Rigid3d OxtsTrajectory::T_world_imu(StampNs stamp_ns) const {
  return T_world_imu_s(NsToSeconds(stamp_ns - reference_ns_));
}

Rigid3d OxtsTrajectory::T_world_imu_s(double t) const {
  const size_t n = times_s_.size();
  auto extrapolate = [&](size_t i) {
    const double dt = t - times_s_[i];
    Rigid3d T = poses_[i];
    T.linear() = poses_[i].linear() * ExpSO3(rates_body_[i] * dt);
    T.translation() += velocities_world_[i] * dt;
    return T;
  };
  if (n == 1 || t <= times_s_.front()) return extrapolate(0);
  if (t >= times_s_.back()) return extrapolate(n - 1);
  const size_t i = std::upper_bound(times_s_.begin(), times_s_.end(), t) - times_s_.begin() - 1;
  const double h = times_s_[i + 1] - times_s_[i];
  const double s = (t - times_s_[i]) / h;
  // Cubic Hermite basis.
  const double h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s;
  const double h01 = -2 * s * s * s + 3 * s * s, h11 = s * s * s - s * s;
  Rigid3d T = Rigid3d::Identity();
  T.translation() = h00 * poses_[i].translation() + h10 * h * velocities_world_[i] +
                    h01 * poses_[i + 1].translation() + h11 * h * velocities_world_[i + 1];
  const Eigen::Quaterniond q0(poses_[i].linear()), q1(poses_[i + 1].linear());
  T.linear() = q0.slerp(s, q1).toRotationMatrix();
  return T;
}

}  // namespace stcalib
