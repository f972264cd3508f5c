#include "core/sim/sensors.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace stcalib::sim {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kGravity = 9.80665;
constexpr double kEarthRadiusM = 6378137.0;

uint8_t LabelOf(const Scene& scene, int object) {
  if (object < 0) return static_cast<uint8_t>(PointLabel::kGround);
  switch (scene.objects()[object].object_class) {
    case ObjectClass::kGround:
      return static_cast<uint8_t>(PointLabel::kGround);
    case ObjectClass::kMoving:
      return static_cast<uint8_t>(PointLabel::kDynamic);
    case ObjectClass::kStructure:
      break;
  }
  return static_cast<uint8_t>(PointLabel::kStatic);
}

double TextureGain(const Material& m, const Eigen::Vector3d& p) {
  switch (m.texture) {
    case Texture::kPlain:
      return 1.0;
    case Texture::kFoliage:
      return 0.35 + 1.0 * CellNoise(p, 0.07);
    case Texture::kAsphalt:
      return 0.88 + 0.24 * CellNoise(p, 0.04);
    case Texture::kFacade:
      return 0.95 + 0.1 * CellNoise(p, 0.25);
  }
  return 1.0;
}

}  // namespace

double LidarModel::ElevationDeg(int beam) const {
  if (!beam_elevations_deg.empty()) return beam_elevations_deg.at(beam);
  const int half = beams / 2;
  if (beam < half) {
    return elevation_top_deg + (elevation_upper_bottom_deg - elevation_top_deg) * beam / (half - 1);
  }
  return elevation_lower_top_deg +
         (elevation_bottom_deg - elevation_lower_top_deg) * (beam - half) / (beams - half - 1);
}

LidarModel MakeLidarModel(SimLidar lidar) {
  LidarModel model;
  switch (lidar) {
    case SimLidar::kHdl64:
      break;
    case SimLidar::kVlp16:
      for (int k = 0; k < 16; ++k) model.beam_elevations_deg.push_back(15.0 - 2.0 * k);
      model.azimuth_step_deg = 0.2;
      model.max_range_m = 100.0;
      model.range_noise_m = 0.03;
      break;
    case SimLidar::kOs1_64:
      for (int k = 0; k < 64; ++k) model.beam_elevations_deg.push_back(16.6 - 33.2 * k / 63);
      model.azimuth_step_deg = 360.0 / 1024;
      model.range_noise_m = 0.03;
      break;
  }
  if (!model.beam_elevations_deg.empty()) {
    model.beams = static_cast<int>(model.beam_elevations_deg.size());
  }
  return model;
}

SimulatedSweep SimulateLidarSweep(const Scene& scene, const SimTrajectory& trajectory,
                                  const Rigid3d& T_imu_lidar, const LidarModel& model,
                                  double t_mid_s, double sweep_duration_s, std::mt19937_64* rng) {
  const int columns = static_cast<int>(std::lround(360.0 / model.azimuth_step_deg));
  // Column j in file order: azimuth from just left of ahead, counter-clockwise all the way round.
  std::vector<double> azimuth(columns), time(columns);
  std::vector<Rigid3d> T_world_lidar(columns);
  for (int j = 0; j < columns; ++j) {
    double a = (0.5 + j) * model.azimuth_step_deg * kDegToRad;
    if (a > M_PI) a -= 2 * M_PI;
    azimuth[j] = a;
    time[j] = t_mid_s - a / (2 * M_PI) * sweep_duration_s;  // clockwise spin
    T_world_lidar[j] = trajectory.T_world_imu(time[j]) * T_imu_lidar;
  }
  const Rigid3d T_mid = trajectory.T_world_imu(t_mid_s) * T_imu_lidar;
  const double margin = SimTrajectory::kMaxSpeedMps * 0.5 * sweep_duration_s + 0.5;
  const AzimuthIndex index =
      scene.BuildIndex(T_mid.translation().head<2>(), t_mid_s - 0.5 * sweep_duration_s,
                       t_mid_s + 0.5 * sweep_duration_s, margin, model.max_range_m);

  std::normal_distribution<double> range_noise(0.0, model.range_noise_m);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  SimulatedSweep sweep;
  const size_t reserve = static_cast<size_t>(columns) * model.beams * 3 / 5;
  sweep.scan.points_lidar.reserve(reserve);
  sweep.scan.reflectance.reserve(reserve);
  sweep.labels.reserve(reserve);
  sweep.point_time_s.reserve(reserve);
  sweep.ring.reserve(reserve);
  std::vector<double> cos_az(columns), sin_az(columns);
  for (int j = 0; j < columns; ++j) {
    cos_az[j] = std::cos(azimuth[j]);
    sin_az[j] = std::sin(azimuth[j]);
  }
  for (int beam = 0; beam < model.beams; ++beam) {
    const double el = model.ElevationDeg(beam) * kDegToRad;
    const double ce = std::cos(el), se = std::sin(el);
    for (int j = 0; j < columns; ++j) {
      const Eigen::Vector3d dir_lidar(ce * cos_az[j], ce * sin_az[j], se);
      const Eigen::Vector3d dir_world = T_world_lidar[j].linear() * dir_lidar;
      RayHit hit;
      if (!scene.Intersect(index, T_world_lidar[j].translation(), dir_world, time[j],
                           model.max_range_m, &hit)) {
        continue;
      }
      const Material& material = scene.materials()[hit.material];
      double range = hit.range + range_noise(*rng);
      if (material.texture == Texture::kFoliage) {
        range += model.foliage_penetration_m * unit(*rng);
      }
      if (range < model.min_range_m || range > model.max_range_m) continue;
      const double incidence = std::abs(hit.normal_world.dot(dir_world));
      const double reflectance =
          std::clamp(material.reflectance * (0.4 + 0.6 * incidence), 0.0, 1.0);
      sweep.scan.points_lidar.push_back(dir_lidar * range);
      sweep.scan.reflectance.push_back(static_cast<float>(std::round(reflectance * 100) / 100));
      sweep.labels.push_back(LabelOf(scene, hit.object));
      sweep.point_time_s.push_back(time[j]);
      sweep.ring.push_back(static_cast<uint16_t>(beam));
    }
  }
  return sweep;
}

cv::Mat RenderCameraImage(const Scene& scene, const SimTrajectory& trajectory, const CameraRig& rig,
                          double t_s, std::mt19937_64* rng) {
  const Rigid3d T_world_camera = trajectory.T_world_imu(t_s) * rig.T_imu_camera;
  const Eigen::Matrix3d K = rig.P_rect.leftCols<3>();
  const Eigen::Matrix3d K_inv = K.inverse();
  // Rectified camera 2 centre: P = K [I | K⁻¹ p4], so c_rect = −K⁻¹ p4.
  const Eigen::Vector3d c_rect = -K_inv * rig.P_rect.col(3);
  const Eigen::Matrix3d R_world_rect = T_world_camera.linear() * rig.R_rect_00.transpose();
  const Eigen::Vector3d origin = T_world_camera * (rig.R_rect_00.transpose() * c_rect);
  constexpr double kMaxRange = 400.0;
  const AzimuthIndex index = scene.BuildIndex(origin.head<2>(), t_s, t_s, 0.5, kMaxRange);

  const Eigen::Vector3d sky_top(0.85, 0.62, 0.42), sky_horizon(0.95, 0.88, 0.82);  // BGR
  constexpr double kAmbient = 0.35, kDiffuse = 0.65;
  // Radiance along the ray through (u, v); `surface` receives what it hit (−2 sky, −1 ground,
  // else the object) and its material.
  auto shade = [&](double u, double v, int* surface, int* material) {
    const Eigen::Vector3d dir = (R_world_rect * (K_inv * Eigen::Vector3d(u, v, 1))).normalized();
    RayHit hit;
    if (scene.Intersect(index, origin, dir, t_s, kMaxRange, &hit)) {
      const Material& m = scene.materials()[hit.material];
      const double light = kAmbient + kDiffuse * std::max(0.0, hit.normal_world.dot(rig.sun_world));
      *surface = hit.object;
      *material = hit.material;
      return Eigen::Vector3d(m.albedo_bgr * (light * TextureGain(m, hit.point_world)));
    }
    *surface = -2;
    *material = -1;
    const double k = std::clamp(dir.z() * 3.0, 0.0, 1.0);
    return Eigen::Vector3d((1 - k) * sky_horizon + k * sky_top);
  };
  const int w = rig.width, h = rig.height;
  // A distorted camera: each raw pixel's ray is the rectified pixel it undistorts to (OpenCV's
  // undistortPoints at the pixel centres; between them, for the edge pixels' sub-samples,
  // interpolated bilinearly: the map is smooth).
  std::vector<cv::Point2d> centres;
  if (!rig.distortion.empty()) {
    cv::Mat K_cv, R_cv;
    cv::eigen2cv(K, K_cv);
    cv::eigen2cv(rig.R_rect_00, R_cv);
    const cv::Mat D_cv = cv::Mat(rig.distortion, true).reshape(1, 1);
    std::vector<cv::Point2d> raw;
    raw.reserve(static_cast<size_t>(w) * h);
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) raw.emplace_back(u, v);
    }
    cv::undistortPoints(raw, centres, K_cv, D_cv, R_cv, K_cv);
  }
  auto rectified = [&](double u, double v) {
    if (centres.empty()) return cv::Point2d(u, v);
    const double uc = std::clamp(u, 0.0, w - 1.0), vc = std::clamp(v, 0.0, h - 1.0);
    const int u0 = std::min(static_cast<int>(uc), w - 2),
              v0 = std::min(static_cast<int>(vc), h - 2);
    const double a = uc - u0, b = vc - v0;
    auto at = [&](int uu, int vv) { return centres[static_cast<size_t>(vv) * w + uu]; };
    const cv::Point2d q = (1 - a) * (1 - b) * at(u0, v0) + a * (1 - b) * at(u0 + 1, v0) +
                          (1 - a) * b * at(u0, v0 + 1) + a * b * at(u0 + 1, v0 + 1);
    return q + cv::Point2d(u - uc, v - vc);  // beyond the border, the border's offset
  };
  auto shade_raw = [&](double u, double v, int* surface, int* material) {
    const cv::Point2d q = rectified(u, v);
    return shade(q.x, q.y, surface, material);
  };
  // First pass: one ray through each pixel centre.
  std::vector<Eigen::Vector3d> radiance(static_cast<size_t>(w) * h);
  std::vector<int> surface(radiance.size()), material(radiance.size());
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      radiance[i] = shade_raw(u, v, &surface[i], &material[i]);
    }
  }
  // Second pass: a pixel whose neighbours see another surface or material straddles an edge; it
  // integrates over its area (3×3 samples), as a real pixel does. Without this, a step edge gives
  // two equal gradient maxima and edge detectors pick one side: a half-pixel bias.
  constexpr int kSub = 3;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      bool edge = false;
      for (const auto& [du, dv] :
           {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
        const int uu = u + du, vv = v + dv;
        if (uu < 0 || vv < 0 || uu >= w || vv >= h) continue;
        const size_t j = static_cast<size_t>(vv) * w + uu;
        edge = edge || surface[j] != surface[i] || material[j] != material[i];
      }
      if (!edge) continue;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int unused_surface, unused_material;
      for (int a = 0; a < kSub; ++a) {
        for (int b = 0; b < kSub; ++b) {
          sum += shade_raw(u + (a + 0.5) / kSub - 0.5, v + (b + 0.5) / kSub - 0.5, &unused_surface,
                           &unused_material);
        }
      }
      radiance[i] = sum / (kSub * kSub);
    }
  }
  std::normal_distribution<double> noise(0.0, rig.noise_sigma);
  cv::Mat image(h, w, CV_8UC3);
  for (int v = 0; v < h; ++v) {
    auto* row = image.ptr<cv::Vec3b>(v);
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector3d& colour = radiance[static_cast<size_t>(v) * w + u];
      for (int c = 0; c < 3; ++c) {
        row[u][c] = cv::saturate_cast<uint8_t>(255.0 * colour[c] + noise(*rng));
      }
    }
  }
  return image;
}

NavigationErrorOptions NavigationErrorOptions::Scaled(double factor) const {
  NavigationErrorOptions o = *this;
  for (double* sigma : o.Sigmas()) *sigma *= factor;
  return o;
}

NavigationError::NavigationError(const NavigationErrorOptions& options, std::mt19937_64* rng)
    : options_(options) {
  // Periods log-uniform in [min, max]; equal amplitudes so that each axis has the set σ
  // (a sinusoid of amplitude a has variance a²/2).
  std::uniform_real_distribution<double> phase(0, 2 * M_PI);
  auto draw = [&](const Eigen::Vector3d& sigma, double min_period_s, double max_period_s,
                  std::array<Axis, 3>* axes) {
    std::uniform_real_distribution<double> log_period(std::log(min_period_s),
                                                      std::log(max_period_s));
    for (int i = 0; i < 3; ++i) {
      for (Term& term : (*axes)[i]) {
        term.amplitude = sigma[i] * std::sqrt(2.0 / kTerms);
        term.angular_frequency = 2 * M_PI / std::exp(log_period(*rng));
        term.phase = phase(*rng);
      }
    }
  };
  const NavigationErrorOptions& o = options;
  draw(Eigen::Vector3d::Constant(o.position_drift_m), o.min_period_s, o.max_period_s, &position_);
  draw(Eigen::Vector3d::Constant(o.angle_drift_rad), o.min_period_s, o.max_period_s, &angle_);
  draw(Eigen::Vector3d(o.velocity_drift_mps, o.velocity_drift_mps, o.vertical_velocity_drift_mps),
       o.velocity_min_period_s, o.velocity_max_period_s, &velocity_);
}

Eigen::Vector3d NavigationError::Evaluate(const std::array<Axis, 3>& axes, double t_s, bool rate) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    for (const Term& term : axes[i]) {
      const double angle = term.angular_frequency * t_s + term.phase;
      out[i] += rate ? term.amplitude * term.angular_frequency * std::cos(angle)
                     : term.amplitude * std::sin(angle);
    }
  }
  return out;
}

Eigen::Vector3d NavigationError::PositionDrift(double t_s) const {
  return Evaluate(position_, t_s, /*rate=*/false);
}

Eigen::Vector3d NavigationError::PositionDriftRate(double t_s) const {
  return Evaluate(position_, t_s, /*rate=*/true);
}

Eigen::Vector3d NavigationError::AngleDrift(double t_s) const {
  return Evaluate(angle_, t_s, /*rate=*/false);
}

Eigen::Vector3d NavigationError::VelocityDrift(double t_s) const {
  return Evaluate(velocity_, t_s, /*rate=*/false);
}

OxtsPacket SynthesizeOxtsPacket(const SimTrajectory& trajectory, const OxtsOrigin& origin,
                                const NavigationError& error, double t_s, std::mt19937_64* rng) {
  constexpr double h = 1e-3;  // central differences [s]
  const Rigid3d T0 = trajectory.T_world_imu(t_s - h);
  const Rigid3d T1 = trajectory.T_world_imu(t_s);
  const Rigid3d T2 = trajectory.T_world_imu(t_s + h);
  const Eigen::Vector3d rpy = trajectory.RollPitchYaw(t_s);
  const Eigen::Vector3d v_world = (T2.translation() - T0.translation()) / (2 * h);
  const Eigen::Vector3d a_world =
      (T2.translation() - 2 * T1.translation() + T0.translation()) / (h * h);
  const Eigen::Vector3d w_body = LogSO3(T0.linear().transpose() * T2.linear()) / (2 * h);
  const Eigen::Matrix3d R_heading =
      Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d specific_force = a_world + Eigen::Vector3d(0, 0, kGravity);

  const NavigationErrorOptions& noise = error.options();
  // Unit normals scaled by σ: a σ of 0 (exact navigation) is no valid normal_distribution.
  std::normal_distribution<double> n_angle, n_vel, n_pos, n_acc, n_rate;
  auto white = [&](std::normal_distribution<double>& n, double sigma) {  // x, y, z order
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = sigma * n(*rng);
    return v;
  };
  OxtsPacket p;
  // Invert the Mercator projection of oxts_poses.h (scale of the origin latitude).
  const double scale = std::cos(origin.lat_deg * M_PI / 180.0);
  const double x0 = scale * kEarthRadiusM * origin.lon_deg * M_PI / 180.0;
  const double y0 =
      scale * kEarthRadiusM * std::log(std::tan(M_PI * (90.0 + origin.lat_deg) / 360.0));
  const Eigen::Vector3d position =
      T1.translation() + error.PositionDrift(t_s) + white(n_pos, noise.position_white_m);
  p.lon = (position.x() + x0) / (scale * kEarthRadiusM) * 180.0 / M_PI;
  p.lat = 360.0 / M_PI * std::atan(std::exp((position.y() + y0) / (scale * kEarthRadiusM))) - 90.0;
  p.alt = origin.alt_m + position.z();
  const Eigen::Vector3d attitude =
      rpy + error.AngleDrift(t_s) + white(n_angle, noise.angle_white_rad);
  p.roll = attitude.x();
  p.pitch = attitude.y();
  p.yaw = std::remainder(attitude.z(), 2 * M_PI);
  // The velocity carries the position drift's rate and a drift of its own; the heading frame is
  // the written yaw's.
  const Eigen::Vector3d velocity = v_world + error.PositionDriftRate(t_s) +
                                   error.VelocityDrift(t_s) +
                                   white(n_vel, noise.velocity_white_mps);
  p.vn = velocity.y();
  p.ve = velocity.x();
  const Eigen::Vector3d v_heading =
      Eigen::AngleAxisd(attitude.z(), Eigen::Vector3d::UnitZ()).inverse() * velocity;
  p.vf = v_heading.x();
  p.vl = v_heading.y();
  p.vu = v_heading.z();
  const double acc = noise.acceleration_white_mps2, rate = noise.rate_white_radps;
  const Eigen::Vector3d a_body = T1.linear().transpose() * specific_force + white(n_acc, acc);
  p.ax = a_body.x();
  p.ay = a_body.y();
  p.az = a_body.z();
  const Eigen::Vector3d a_heading = R_heading.transpose() * specific_force + white(n_acc, acc);
  p.af = a_heading.x();
  p.al = a_heading.y();
  p.au = a_heading.z();
  const Eigen::Vector3d w = w_body + white(n_rate, rate);
  p.wx = w.x();
  p.wy = w.y();
  p.wz = w.z();
  const Eigen::Vector3d w_heading =
      R_heading.transpose() * (T1.linear() * w_body) + white(n_rate, rate);
  p.wf = w_heading.x();
  p.wl = w_heading.y();
  p.wu = w_heading.z();
  p.pos_accuracy = 0.05;
  p.vel_accuracy = 0.02;
  p.navstat = 4;
  p.numsats = 9;
  p.posmode = 4;
  p.velmode = 4;
  p.orimode = 4;
  return p;
}

}  // namespace stcalib::sim
