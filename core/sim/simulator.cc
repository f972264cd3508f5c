#include "core/sim/simulator.h"

#include <glog/logging.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/io/image.h"
#include "core/io/text.h"
#include "core/io/velodyne.h"
#include "core/types/enum_names.h"

namespace stcalib::sim {
namespace {

namespace fs = std::filesystem;

// Independent random streams per purpose and frame, so that any frame can be simulated alone.
enum Stream : uint64_t {
  kRoad = 1,
  kTrajectory,
  kScene,
  kCalibration,
  kFrameLidar,
  kFrameCamera,
  kFrameOxts,
  kFrameClock,
  kOxtsDrift,
  kRigCamera,  // per camera of the rig other than image_02
};

// The rig's other cameras, facing left, right and rear: their turn about the camera's y axis
// (down) and their centre in image_02's frame (x right, y down, z forward) [m].
struct RigMount {
  double turn_deg;
  Eigen::Vector3d centre_m;
};
constexpr int kMaxRigCameras = 4;
const RigMount kRigMounts[kMaxRigCameras - 1] = {
    {90.0, Eigen::Vector3d(-0.6, 0.0, -0.7)},
    {-90.0, Eigen::Vector3d(0.6, 0.0, -0.7)},
    {180.0, Eigen::Vector3d(0.0, 0.0, -1.6)},
};

std::mt19937_64 MakeRng(uint64_t seed, uint64_t stream, uint64_t frame = 0) {
  std::seed_seq seq{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32),
                    static_cast<uint32_t>(stream), static_cast<uint32_t>(frame)};
  return std::mt19937_64(seq);
}

// A KITTI-like mount (the values of KITTI's 2011_09_26 calibration); each seed moves the
// extrinsic by up to ±0.5° per axis and ±2 cm so that no tool can tune to one answer.
Rigid3d NominalTCameraLidar() {
  Eigen::Matrix3d R;
  R << 7.533745e-03, -9.999714e-01, -6.166020e-04, 1.480249e-02, 7.280733e-04, -9.998902e-01,
      9.998621e-01, 7.523790e-03, 1.480755e-02;
  const Eigen::Quaterniond q(R);  // re-orthonormalise the printed matrix
  return MakeRigid(q.normalized().toRotationMatrix(),
                   Eigen::Vector3d(-4.069766e-03, -7.631618e-02, -2.717806e-01));
}

Rigid3d NominalTLidarImu() {
  Eigen::Matrix3d R;
  R << 9.999976e-01, 7.553071e-04, -2.035826e-03, -7.854027e-04, 9.998898e-01, -1.482298e-02,
      2.024406e-03, 1.482454e-02, 9.998881e-01;
  const Eigen::Quaterniond q(R);
  return MakeRigid(q.normalized().toRotationMatrix(),
                   Eigen::Vector3d(-8.086759e-01, 3.195559e-01, -7.997231e-01));
}

nlohmann::json ToJson(const Rigid3d& T) {
  nlohmann::json values = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) values.push_back(T.matrix()(r, c));
  }
  return values;
}

std::string DataFormatText() {
  return "lat:   latitude of the oxts-unit (deg)\n"
         "lon:   longitude of the oxts-unit (deg)\n"
         "alt:   altitude of the oxts-unit (m)\n"
         "roll:  roll angle (rad),    0 = level, positive = left side up\n"
         "pitch: pitch angle (rad),   0 = level, positive = front down\n"
         "yaw:   heading (rad),       0 = east,  positive = counter clockwise\n"
         "vn:    velocity towards north (m/s)\n"
         "ve:    velocity towards east (m/s)\n"
         "vf:    forward velocity, parallel to earth-surface (m/s)\n"
         "vl:    leftward velocity, parallel to earth-surface (m/s)\n"
         "vu:    upward velocity, perpendicular to earth-surface (m/s)\n"
         "ax:    acceleration in x, vehicle front (m/s^2)\n"
         "ay:    acceleration in y, vehicle left (m/s^2)\n"
         "az:    acceleration in z, vehicle top (m/s^2)\n"
         "af:    forward acceleration (m/s^2)\n"
         "al:    leftward acceleration (m/s^2)\n"
         "au:    upward acceleration (m/s^2)\n"
         "wx:    angular rate around x (rad/s)\n"
         "wy:    angular rate around y (rad/s)\n"
         "wz:    angular rate around z (rad/s)\n"
         "wf:    angular rate around forward axis (rad/s)\n"
         "wl:    angular rate around leftward axis (rad/s)\n"
         "wu:    angular rate around upward axis (rad/s)\n"
         "pos_accuracy:  position accuracy (north/east in m)\n"
         "vel_accuracy:  velocity accuracy (north/east in m/s)\n"
         "navstat:       navigation status\n"
         "numsats:       number of satellites tracked by primary GPS receiver\n"
         "posmode:       position mode of primary GPS receiver\n"
         "velmode:       velocity mode of primary GPS receiver\n"
         "orimode:       orientation mode of primary GPS receiver\n";
}

constexpr EnumNames<SimCamera, 3> kCameraNames = {{{SimCamera::kKitti, "kitti"},
                                                   {SimCamera::kKitti1003, "kitti_1003"},
                                                   {SimCamera::kHd720, "hd720"}}};

constexpr EnumNames<SimLidar, 3> kLidarNames = {
    {{SimLidar::kHdl64, "hdl64"}, {SimLidar::kVlp16, "vlp16"}, {SimLidar::kOs1_64, "os1-64"}}};

}  // namespace

bool ParseSimLidar(const std::string& name, SimLidar* lidar) {
  return ParseEnumName(kLidarNames, name, lidar);
}
std::string SimLidarName(SimLidar lidar) { return EnumName(kLidarNames, lidar); }
std::string SimLidarChoices() { return EnumNameChoices(kLidarNames); }

bool ParseSimCamera(const std::string& name, SimCamera* camera) {
  return ParseEnumName(kCameraNames, name, camera);
}

std::string SimCameraName(SimCamera camera) { return EnumName(kCameraNames, camera); }

std::string SimCameraChoices() { return EnumNameChoices(kCameraNames); }

CameraRig MakeCameraRig(SimCamera camera) {
  CameraRig rig;
  switch (camera) {
    case SimCamera::kKitti:
      rig.R_rect_00 << 9.999239e-01, 9.837760e-03, -7.445048e-03, -9.869795e-03, 9.999421e-01,
          -4.278459e-03, 7.402527e-03, 4.351614e-03, 9.999631e-01;
      rig.P_rect << 7.215377e+02, 0.0, 6.095593e+02, 4.485728e+01, 0.0, 7.215377e+02, 1.728540e+02,
          2.163791e-01, 0.0, 0.0, 1.0, 2.745884e-03;
      rig.width = 1242;
      rig.height = 375;
      break;
    case SimCamera::kKitti1003:
      rig.R_rect_00 << 9.999454e-01, 7.259129e-03, -7.519551e-03, -7.292213e-03, 9.999638e-01,
          -4.381729e-03, 7.487471e-03, 4.436324e-03, 9.999621e-01;
      rig.P_rect << 7.188560e+02, 0.0, 6.071928e+02, 4.538225e+01, 0.0, 7.188560e+02, 1.852157e+02,
          -1.130887e-01, 0.0, 0.0, 1.0, 3.779761e-03;
      rig.width = 1241;
      rig.height = 376;
      break;
    case SimCamera::kHd720:
      rig.R_rect_00.setIdentity();
      rig.P_rect << 800.0, 0.0, 652.0, 0.0, 0.0, 800.0, 349.0, 0.0, 0.0, 0.0, 1.0, 0.0;
      rig.width = 1280;
      rig.height = 720;
      rig.nose_down_deg = 3.0;
      break;
  }
  rig.R_rect_00 = Eigen::Quaterniond(rig.R_rect_00).normalized().toRotationMatrix();
  return rig;
}

Status SimulatorOptions::Validate() const {
  if (frames < 1 || frames > 100000) {
    return Status::Error("--frames must be between 1 and 100000, got " + std::to_string(frames));
  }
  if (!(lidar_hz >= 1.0 && lidar_hz <= 50.0)) {
    return Status::Error("--lidar_hz must be between 1 and 50 Hz, got " + std::to_string(lidar_hz));
  }
  if (!(std::abs(time_offset_s) <= 0.5)) {
    return Status::Error("--time_offset_s must be within ±0.5 s, got " +
                         std::to_string(time_offset_s));
  }
  if (dynamic_objects < 0 || dynamic_objects > 200) {
    return Status::Error("--dynamic_objects must be between 0 and 200, got " +
                         std::to_string(dynamic_objects));
  }
  if (!(speed_mps == 0 || (speed_mps >= 0.5 && speed_mps <= SimTrajectory::kMaxSpeedMps))) {
    return Status::Error(
        "--speed_mps must be 0 (the default profile) or between 0.5 and 15 m/s, "
        "got " +
        std::to_string(speed_mps));
  }
  if (!(std::abs(distortion_k1) <= 1.0)) {
    return Status::Error("--distortion_k1 must be within ±1, got " + std::to_string(distortion_k1));
  }
  if (cameras < 1 || cameras > kMaxRigCameras) {
    return Status::Error("--cameras must be a number of cameras from 1 to " +
                         std::to_string(kMaxRigCameras) + ", got " + std::to_string(cameras));
  }
  if (!(std::abs(camera_delay_s) < 0.5 / lidar_hz)) {
    return Status::Error("camera delay must be under half a frame period");
  }
  const NavigationErrorOptions& e = oxts_error;
  if (!(e.position_white_m >= 0.0 && e.position_white_m <= 1.0)) {
    return Status::Error("--oxts_white_position_m must be between 0 and 1 m, got " +
                         std::to_string(e.position_white_m));
  }
  for (const double* sigma : e.Sigmas()) {
    if (!(*sigma >= 0.0 && *sigma <= 10.0)) {
      return Status::Error("oxts noise σ must be between 0 and 10, got " + std::to_string(*sigma));
    }
  }
  if (!(e.min_period_s > 0.0 && e.max_period_s >= e.min_period_s && e.velocity_min_period_s > 0.0 &&
        e.velocity_max_period_s >= e.velocity_min_period_s)) {
    return Status::Error("oxts drift periods must be positive and ordered");
  }
  return Status::Ok();
}

Simulator::Simulator(const SimulatorOptions& options) : options_(options) {
  const Status valid = options.Validate();
  CHECK(valid.ok()) << valid.message();
  const uint64_t seed = options.seed;
  std::mt19937_64 road_rng = MakeRng(seed, kRoad);
  // Speed is at most 15 m/s; leave 150 m of scenery beyond the last frame and 80 m behind.
  const double duration = LidarMidTime(options.frames - 1) + 1.0;
  road_ = std::make_unique<SimRoad>(
      SimRoad::Generate(-80.0, SimTrajectory::kMaxSpeedMps * duration + 150.0,
                        /*with_turns=*/true, &road_rng));
  std::mt19937_64 trajectory_rng = MakeRng(seed, kTrajectory);
  trajectory_ = std::make_unique<SimTrajectory>(road_.get(), &trajectory_rng, options.speed_mps);
  std::mt19937_64 scene_rng = MakeRng(seed, kScene);
  scene_ = std::make_unique<Scene>(Scene::Build(options.scene, options.dynamic_objects, road_.get(),
                                                trajectory_.get(), &scene_rng));

  std::mt19937_64 calib_rng = MakeRng(seed, kCalibration);
  std::uniform_real_distribution<double> angle(-0.5, 0.5), offset(-0.02, 0.02);
  const Eigen::Vector3d rpy_deg(angle(calib_rng), angle(calib_rng), angle(calib_rng));
  rig_ = MakeCameraRig(options.camera);
  if (options.distortion_k1 != 0.0) rig_.distortion = {options.distortion_k1, 0.0, 0.0, 0.0, 0.0};
  lidar_ = MakeLidarModel(options.lidar);
  // The rig's nose-down tilt about the camera centre (which stays at KITTI's mount): a point
  // straight ahead moves up the image (camera y is down).
  T_camera_lidar_ = MakeRigid(ExpSO3(Eigen::Vector3d(rig_.nose_down_deg * M_PI / 180.0, 0, 0)),
                              Eigen::Vector3d::Zero()) *
                    NominalTCameraLidar();
  T_camera_lidar_.linear() = T_camera_lidar_.linear() * ExpSO3(rpy_deg * M_PI / 180.0);
  T_camera_lidar_.translation() +=
      Eigen::Vector3d(offset(calib_rng), offset(calib_rng), offset(calib_rng));
  T_lidar_imu_ = NominalTLidarImu();

  rig_.T_imu_camera = T_lidar_imu_.inverse() * T_camera_lidar_.inverse();
  for (int k = 1; k < options.cameras; ++k) {
    std::mt19937_64 rng = MakeRng(seed, kRigCamera, k);
    const RigMount& mount = kRigMounts[k - 1];
    const Eigen::Matrix3d turn =
        Eigen::AngleAxisd(mount.turn_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).matrix();
    Eigen::Vector3d wobble_deg, shift;  // one draw per statement: a fixed order
    for (int axis = 0; axis < 3; ++axis) wobble_deg[axis] = angle(rng);
    for (int axis = 0; axis < 3; ++axis) shift[axis] = offset(rng);
    SimRigCamera camera;
    camera.name = "image_0" + std::to_string(2 + k);
    const Eigen::Matrix3d R = ExpSO3(wobble_deg * M_PI / 180.0) * turn;
    camera.T_camera_reference = MakeRigid(R, -R * (mount.centre_m + shift));
    camera.T_camera_lidar = camera.T_camera_reference * T_camera_lidar_;
    std::uniform_real_distribution<double> clock(-0.02, 0.02);
    camera.time_offset_s = options.time_offset_s + clock(rng);
    camera.rig = rig_;
    camera.rig.T_imu_camera = T_lidar_imu_.inverse() * camera.T_camera_lidar.inverse();
    rig_cameras_.push_back(camera);
  }
  std::uniform_real_distribution<double> sun_azimuth(0, 2 * M_PI), sun_elevation(0.6, 1.1);
  const double az = sun_azimuth(calib_rng), el = sun_elevation(calib_rng);
  rig_.sun_world =
      Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  std::uniform_real_distribution<double> lat(48.9, 49.1), lon(8.3, 8.5), alt(100, 130);
  origin_ = {lat(calib_rng), lon(calib_rng), alt(calib_rng)};
  std::mt19937_64 drift_rng = MakeRng(seed, kOxtsDrift);
  oxts_error_ = NavigationError(options.oxts_error, &drift_rng);
  // 2026-01-01 12:00:00 UTC plus one day per seed (mod a year).
  start_stamp_ns_ = (1767268800LL + static_cast<int64_t>(seed % 365) * 86400LL) * 1000000000LL;
}

std::string Simulator::DateFolder() const {
  std::string date = FormatKittiTimestamp(start_stamp_ns_).substr(0, 10);
  for (char& c : date) {
    if (c == '-') c = '_';
  }
  return date;
}

KittiCalibFile Simulator::CameraCalibFile() const {
  KittiCalibFile file;
  file.SetText("calib_time", "simulated by stcalib");
  file.SetNumbers("S_rect_00", {static_cast<double>(rig_.width), static_cast<double>(rig_.height)});
  file.SetMatrix("R_rect_00", rig_.R_rect_00);
  Eigen::Matrix<double, 3, 4> P_rect_00 = rig_.P_rect;
  P_rect_00.col(3).setZero();
  file.SetMatrix("P_rect_00", P_rect_00);
  file.SetNumbers("S_rect_02", {static_cast<double>(rig_.width), static_cast<double>(rig_.height)});
  file.SetMatrix("R_rect_02", Eigen::Matrix3d::Identity());
  file.SetMatrix("P_rect_02", rig_.P_rect);
  auto set_distortion = [&](const std::string& id) {
    if (rig_.distortion.empty()) return;
    file.SetText("distortion_model_" + id, "plumb_bob");
    file.SetMatrix("K_" + id, rig_.P_rect.leftCols<3>());
    file.SetNumbers("D_" + id, rig_.distortion);
  };
  set_distortion("02");
  for (const SimRigCamera& camera : rig_cameras_) {
    const std::string id = camera.name.substr(6);
    file.SetNumbers("S_rect_" + id,
                    {static_cast<double>(rig_.width), static_cast<double>(rig_.height)});
    file.SetMatrix("P_rect_" + id, rig_.P_rect);
    file.SetMatrix("R_rig_" + id, camera.T_camera_reference.linear());
    file.SetMatrix("T_rig_" + id, camera.T_camera_reference.translation());
    set_distortion(id);
  }
  return file;
}

FrameTiming Simulator::Timing(int frame) const {
  CHECK_GE(frame, 0);
  FrameTiming out;
  std::mt19937_64 clock_rng = MakeRng(options_.seed, kFrameClock, frame);
  std::uniform_real_distribution<double> camera_jitter(-2e-4, 2e-4), oxts_jitter(-1e-3, 1e-3);
  out.lidar_mid_time_s = LidarMidTime(frame);
  out.camera_time_s = out.lidar_mid_time_s + options_.camera_delay_s + camera_jitter(clock_rng);
  out.oxts_time_s = out.camera_time_s - 0.004 + oxts_jitter(clock_rng);
  auto stamp = [&](double t) { return start_stamp_ns_ + SecondsToNs(t); };
  out.camera_stamp_ns = stamp(out.camera_time_s);
  // LiDAR stamps carry −δ: a frame stamped t_l was captured at t_l + δ (docs/method.md §2).
  out.lidar_stamp_ns = stamp(out.lidar_mid_time_s - options_.time_offset_s);
  out.lidar_start_stamp_ns = out.lidar_stamp_ns - SecondsToNs(0.5 * SweepDuration());
  out.lidar_end_stamp_ns = out.lidar_stamp_ns + SecondsToNs(0.5 * SweepDuration());
  out.oxts_stamp_ns = stamp(out.oxts_time_s);
  return out;
}

OxtsPacket Simulator::SimulateOxts(int frame) const {
  std::mt19937_64 oxts_rng = MakeRng(options_.seed, kFrameOxts, frame);
  return SynthesizeOxtsPacket(*trajectory_, origin_, oxts_error_, Timing(frame).oxts_time_s,
                              &oxts_rng);
}

SimulatedSweep Simulator::SimulateSweep(int frame) const {
  std::mt19937_64 lidar_rng = MakeRng(options_.seed, kFrameLidar, frame);
  return SimulateLidarSweep(*scene_, *trajectory_, T_lidar_imu_.inverse(), lidar_,
                            LidarMidTime(frame), SweepDuration(), &lidar_rng);
}

SimulatedFrame Simulator::SimulateFrame(int frame) const {
  SimulatedFrame out;
  static_cast<FrameTiming&>(out) = Timing(frame);
  out.sweep = SimulateSweep(frame);
  std::mt19937_64 camera_rng = MakeRng(options_.seed, kFrameCamera, frame);
  out.image_bgr = RenderCameraImage(*scene_, *trajectory_, rig_, out.camera_time_s, &camera_rng);
  out.oxts = SimulateOxts(frame);
  // The other cameras expose with image_02; their stamps carry their δ's difference.
  for (size_t k = 0; k < rig_cameras_.size(); ++k) {
    const SimRigCamera& camera = rig_cameras_[k];
    std::mt19937_64 rng =
        MakeRng(options_.seed, kFrameCamera, static_cast<uint64_t>(frame) | ((k + 1) << 32));
    out.rig_images_bgr.push_back(
        RenderCameraImage(*scene_, *trajectory_, camera.rig, out.camera_time_s, &rng));
    out.rig_camera_stamps_ns.push_back(
        start_stamp_ns_ +
        SecondsToNs(out.camera_time_s - options_.time_offset_s + camera.time_offset_s));
  }
  return out;
}

Status WriteSimulatedDrive(const SimulatorOptions& options, const std::string& out_dir,
                           std::string* drive_dir, const std::function<void(int, int)>& progress) {
  STCALIB_RETURN_IF_ERROR(options.Validate());
  if (out_dir.empty()) return Status::Error("no output folder given (--out)");
  const Simulator simulator(options);
  const std::string date = simulator.DateFolder();
  const fs::path final_dir = fs::path(out_dir) / date;
  std::error_code ec;
  if (fs::exists(final_dir, ec)) {
    return Status::Error(final_dir.string() +
                         ": already exists; remove it or choose another --out or --seed");
  }
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir)) {
    return Status::Error(out_dir + ": cannot create output folder" +
                         (ec ? ": " + ec.message() : std::string()));
  }
  const fs::path partial =
      fs::path(out_dir) / (".partial_" + date + "_" + std::to_string(::getpid()));
  fs::remove_all(partial, ec);
  const std::string drive_name = date + "_drive_0001_sync";
  const fs::path drive = partial / drive_name;
  std::vector<std::string> folders = {"image_02/data", "velodyne_points/data",
                                      "velodyne_points/labels", "oxts/data"};
  for (const SimRigCamera& camera : simulator.rig_cameras())
    folders.push_back(camera.name + "/data");
  for (const std::string& sub : folders) {
    fs::create_directories(drive / sub, ec);
    if (ec) {
      fs::remove_all(partial, ec);
      return Status::Error(out_dir + ": cannot write into output folder: " + ec.message());
    }
  }

  auto write_all = [&]() -> Status {
    const std::string d = drive.string();
    STCALIB_RETURN_IF_ERROR(
        simulator.CameraCalibFile().Write((partial / "calib_cam_to_cam.txt").string()));
    STCALIB_RETURN_IF_ERROR(
        WriteVeloToCam((partial / "calib_velo_to_cam.txt").string(), simulator.T_camera_lidar()));
    STCALIB_RETURN_IF_ERROR(
        WriteImuToVelo((partial / "calib_imu_to_velo.txt").string(), simulator.T_lidar_imu()));
    STCALIB_RETURN_IF_ERROR(WriteTextFile(d + "/oxts/dataformat.txt", DataFormatText()));

    std::vector<StampNs> camera, lidar, lidar_start, lidar_end, oxts;
    const std::vector<SimRigCamera>& rig_cameras = simulator.rig_cameras();
    std::vector<std::vector<StampNs>> rig_stamps(rig_cameras.size());
    nlohmann::json frames = nlohmann::json::array();
    for (int i = 0; i < options.frames; ++i) {
      const SimulatedFrame f = simulator.SimulateFrame(i);
      char name[16];
      std::snprintf(name, sizeof(name), "%010d", i);
      STCALIB_RETURN_IF_ERROR(WriteImage(d + "/image_02/data/" + name + ".png", f.image_bgr));
      for (size_t k = 0; k < rig_cameras.size(); ++k) {
        STCALIB_RETURN_IF_ERROR(WriteImage(d + "/" + rig_cameras[k].name + "/data/" + name + ".png",
                                           f.rig_images_bgr[k]));
        rig_stamps[k].push_back(f.rig_camera_stamps_ns[k]);
      }
      STCALIB_RETURN_IF_ERROR(
          WriteVelodyneBin(d + "/velodyne_points/data/" + name + ".bin", f.sweep.scan));
      STCALIB_RETURN_IF_ERROR(
          WritePointLabels(d + "/velodyne_points/labels/" + name + ".bin", f.sweep.labels));
      STCALIB_RETURN_IF_ERROR(WriteOxtsPacket(d + "/oxts/data/" + name + ".txt", f.oxts));
      camera.push_back(f.camera_stamp_ns);
      lidar.push_back(f.lidar_stamp_ns);
      lidar_start.push_back(f.lidar_start_stamp_ns);
      lidar_end.push_back(f.lidar_end_stamp_ns);
      oxts.push_back(f.oxts_stamp_ns);
      size_t dynamic = 0;
      for (uint8_t label : f.sweep.labels) dynamic += label == 1;
      frames.push_back({
          {"index", i},
          {"camera_time_s", f.camera_time_s},
          {"lidar_mid_time_s", f.lidar_mid_time_s},
          {"T_world_imu_at_camera", ToJson(simulator.trajectory().T_world_imu(f.camera_time_s))},
          {"T_world_imu_at_lidar_mid",
           ToJson(simulator.trajectory().T_world_imu(f.lidar_mid_time_s))},
          {"points", f.sweep.scan.size()},
          {"dynamic_points", dynamic},
      });
      if (progress) progress(i + 1, options.frames);
    }
    STCALIB_RETURN_IF_ERROR(WriteTimestampsFile(d + "/image_02/timestamps.txt", camera));
    nlohmann::json rig_truth = nlohmann::json::object();
    for (size_t k = 0; k < rig_cameras.size(); ++k) {
      STCALIB_RETURN_IF_ERROR(
          WriteTimestampsFile(d + "/" + rig_cameras[k].name + "/timestamps.txt", rig_stamps[k]));
      rig_truth[rig_cameras[k].name] = {
          {"T_camera_lidar", ToJson(rig_cameras[k].T_camera_lidar)},
          {"time_offset_s", rig_cameras[k].time_offset_s},
          {"T_camera_image_02", ToJson(rig_cameras[k].T_camera_reference)}};
    }
    STCALIB_RETURN_IF_ERROR(WriteTimestampsFile(d + "/velodyne_points/timestamps.txt", lidar));
    STCALIB_RETURN_IF_ERROR(
        WriteTimestampsFile(d + "/velodyne_points/timestamps_start.txt", lidar_start));
    STCALIB_RETURN_IF_ERROR(
        WriteTimestampsFile(d + "/velodyne_points/timestamps_end.txt", lidar_end));
    STCALIB_RETURN_IF_ERROR(WriteTimestampsFile(d + "/oxts/timestamps.txt", oxts));

    nlohmann::json moving = nlohmann::json::array();
    for (const SceneObject& o : simulator.scene().objects()) {
      if (!o.moving) continue;
      moving.push_back({{"class", o.name},
                        {"s0_m", o.s0},
                        {"speed_mps", o.speed},
                        {"lateral_m", o.lateral},
                        {"follows_ego", o.follows_ego}});
    }
    nlohmann::json truth = {
        {"generator", "stcalib simulate"},
        {"seed", options.seed},
        {"scene", SceneTypeName(options.scene)},
        {"camera", SimCameraName(options.camera)},
        {"lidar", SimLidarName(options.lidar)},
        {"distortion_k1", options.distortion_k1},
        {"frames", options.frames},
        {"lidar_hz", options.lidar_hz},
        {"dynamic_objects", options.dynamic_objects},
        {"T_camera_lidar", ToJson(simulator.T_camera_lidar())},
        {"time_offset_s", options.time_offset_s},
        {"T_lidar_imu", ToJson(simulator.T_lidar_imu())},
        {"camera_delay_s", options.camera_delay_s},
        {"start_stamp_ns", simulator.start_stamp_ns()},
        {"image_width", simulator.camera_rig().width},
        {"image_height", simulator.camera_rig().height},
        {"oxts_origin",
         {{"lat_deg", simulator.oxts_origin().lat_deg},
          {"lon_deg", simulator.oxts_origin().lon_deg},
          {"alt_m", simulator.oxts_origin().alt_m}}},
        {"world_frame", "east-north-up; x/y Mercator about oxts_origin (KITTI devkit scale)"},
        {"labels", "velodyne_points/labels/*.bin: uint8 per point, 0 static, 1 dynamic, 2 ground"},
        {"moving_objects", moving},
        {"per_frame", frames},
    };
    if (!rig_truth.empty()) truth["cameras"] = rig_truth;
    return WriteTextFile((partial / "ground_truth.json").string(), truth.dump(2) + "\n");
  };

  const Status status = write_all();
  if (!status.ok()) {
    fs::remove_all(partial, ec);
    return status;
  }
  fs::rename(partial, final_dir, ec);
  if (ec) {
    fs::remove_all(partial, ec);
    return Status::Error(final_dir.string() + ": cannot move the finished drive into place");
  }
  *drive_dir = (final_dir / drive_name).string();
  return Status::Ok();
}

}  // namespace stcalib::sim
