#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/sim/road.h"
#include "core/sim/trajectory.h"

namespace stcalib::sim {

enum class SceneType { kUrban, kPoles, kOpen };
bool ParseSceneType(const std::string& name, SceneType* type);
std::string SceneTypeName(SceneType type);
std::string SceneTypeChoices();  ///< "urban, poles or open"

enum class Texture : uint8_t { kPlain, kFoliage, kAsphalt, kFacade };

struct Material {
  Eigen::Vector3d albedo_bgr = Eigen::Vector3d::Constant(0.5);  ///< 0..1 per channel
  double reflectance = 0.3;                                     ///< LiDAR reflectance 0..1
  Texture texture = Texture::kPlain;
};

// Primitives in an object's local frame (x forward along the road, y left, z up).
struct Shape {
  enum class Kind : uint8_t { kBox, kCylinder, kSphere } kind = Kind::kBox;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  ///< box min | cylinder (x, y, z_min) | centre
  Eigen::Vector3d b = Eigen::Vector3d::Zero();  ///< box max | cylinder (radius, -, z_max) | (r,-,-)
  int material = 0;
};

enum class ObjectClass : uint8_t { kStructure, kGround, kMoving };

// A rigid object placed on the road: its pose is (x, y, yaw) in the world, either fixed or
// moving along the road at s(t) = s0 + speed·t (+ the ego's own s(t) when it follows the ego).
struct SceneObject {
  std::vector<Shape> shapes;
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero();  ///< local bounds of all shapes
  Eigen::Vector3d box_max = Eigen::Vector3d::Zero();
  ObjectClass object_class = ObjectClass::kStructure;
  bool moving = false;
  // Static pose.
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double yaw = 0;
  // Motion along the road (moving objects).
  double s0 = 0, speed = 0, lateral = 0, yaw_offset = 0;
  bool follows_ego = false;
  std::string name;  ///< "car", "pedestrian", "building", ...

  void UpdateBounds();
};

struct Pose2 {
  Eigen::Vector2d position;
  double yaw;
};

struct RayHit {
  double range = 0;  ///< distance along the unit ray [m]
  Eigen::Vector3d normal_world = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d point_world = Eigen::Vector3d::Zero();
  int material = 0;
  int object = -1;  ///< index into Scene::objects, -1 for the ground plane
};

// Objects binned by azimuth around one sensor position for one time window, so that a ray only
// tests the objects in its direction.
struct AzimuthIndex {
  static constexpr int kBins = 720;
  std::vector<std::vector<int>> bins;
  int Bin(double azimuth_rad) const;
};

class Scene {
 public:
  static Scene Build(SceneType type, int dynamic_objects, const SimRoad* road,
                     const SimTrajectory* trajectory, std::mt19937_64* rng);

  Pose2 ObjectPose(int object, double t_s) const;
  // Index of the objects that can be hit from within `margin_m` of `sensor_xy` during
  // [t_begin, t_end], up to `max_range_m`.
  AzimuthIndex BuildIndex(const Eigen::Vector2d& sensor_xy, double t_begin_s, double t_end_s,
                          double margin_m, double max_range_m) const;
  // Nearest hit of the ray origin + r·dir (dir unit, r ≤ max_range) at time t; false on a miss.
  bool Intersect(const AzimuthIndex& index, const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& dir, double t_s, double max_range_m, RayHit* hit) const;

  const std::vector<SceneObject>& objects() const { return objects_; }
  const std::vector<Material>& materials() const { return materials_; }
  int ground_material() const { return ground_material_; }
  double MaxObjectSpeed() const { return max_object_speed_; }

 private:
  int AddMaterial(const Material& m);
  void AddObject(SceneObject object);

  const SimRoad* road_ = nullptr;
  const SimTrajectory* trajectory_ = nullptr;
  std::vector<SceneObject> objects_;
  std::vector<Material> materials_;
  int ground_material_ = 0;
  double max_object_speed_ = 0;

  friend class SceneBuilder;
};

// Deterministic value noise in [0, 1) on a grid of `cell_m` [m].
double CellNoise(const Eigen::Vector3d& p, double cell_m);

}  // namespace stcalib::sim
