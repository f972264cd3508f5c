#include "core/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/types/enum_names.h"

namespace stcalib::sim {
namespace {

constexpr double kRightKerbM = -4.0;  ///< right road edge (parking strip beyond the lane)
constexpr double kLeftKerbM = 5.5;    ///< left road edge (beyond the oncoming lane)
constexpr double kSidewalkHeightM = 0.15;
constexpr double kRightFrontM = 9.0;  ///< nearest building front, right side (|lateral|)
constexpr double kLeftFrontM = 10.0;  ///< nearest building front, left side

Shape Box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int material) {
  Shape s;
  s.kind = Shape::Kind::kBox;
  s.a = lo;
  s.b = hi;
  s.material = material;
  return s;
}

Shape Cylinder(double x, double y, double radius, double z0, double z1, int material) {
  Shape s;
  s.kind = Shape::Kind::kCylinder;
  s.a = Eigen::Vector3d(x, y, z0);
  s.b = Eigen::Vector3d(radius, 0, z1);
  s.material = material;
  return s;
}

Shape Sphere(const Eigen::Vector3d& centre, double radius, int material) {
  Shape s;
  s.kind = Shape::Kind::kSphere;
  s.a = centre;
  s.b = Eigen::Vector3d(radius, 0, 0);
  s.material = material;
  return s;
}

// Slab test of a ray against an axis-aligned box; entering axis in *axis (−1 when inside).
bool RayBox(const Eigen::Vector3d& o, const Eigen::Vector3d& inv_d, const Eigen::Vector3d& lo,
            const Eigen::Vector3d& hi, double* t_near, double* t_far, int* axis) {
  double t0 = -std::numeric_limits<double>::infinity();
  double t1 = std::numeric_limits<double>::infinity();
  int entering = -1;
  for (int k = 0; k < 3; ++k) {
    double a = (lo[k] - o[k]) * inv_d[k];
    double b = (hi[k] - o[k]) * inv_d[k];
    if (std::isnan(a) || std::isnan(b)) {  // parallel ray on the slab boundary
      if (o[k] < lo[k] || o[k] > hi[k]) return false;
      continue;
    }
    if (a > b) std::swap(a, b);
    if (a > t0) {
      t0 = a;
      entering = k;
    }
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  *t_near = t0;
  *t_far = t1;
  *axis = entering;
  return t1 >= 0;
}

// Nearest positive hit of a shape in local coordinates; updates *best and *normal.
bool IntersectShape(const Shape& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                    const Eigen::Vector3d& inv_d, double* best, Eigen::Vector3d* normal) {
  switch (s.kind) {
    case Shape::Kind::kBox: {
      double t0, t1;
      int axis;
      if (!RayBox(o, inv_d, s.a, s.b, &t0, &t1, &axis)) return false;
      if (t0 <= 1e-6 || t0 >= *best || axis < 0) return false;
      *best = t0;
      *normal = Eigen::Vector3d::Zero();
      (*normal)[axis] = d[axis] > 0 ? -1.0 : 1.0;
      return true;
    }
    case Shape::Kind::kCylinder: {
      const double r = s.b.x(), z0 = s.a.z(), z1 = s.b.z();
      const double ox = o.x() - s.a.x(), oy = o.y() - s.a.y();
      bool hit = false;
      const double a = d.x() * d.x() + d.y() * d.y();
      if (a > 1e-12) {
        const double b = ox * d.x() + oy * d.y();
        const double c = ox * ox + oy * oy - r * r;
        const double disc = b * b - a * c;
        if (disc >= 0) {
          const double t = (-b - std::sqrt(disc)) / a;
          const double z = o.z() + t * d.z();
          if (t > 1e-6 && t < *best && z >= z0 && z <= z1) {
            *best = t;
            *normal = Eigen::Vector3d(ox + t * d.x(), oy + t * d.y(), 0).normalized();
            hit = true;
          }
        }
      }
      if (d.z() < 0 && o.z() > z1) {  // top cap
        const double t = (z1 - o.z()) / d.z();
        const double x = ox + t * d.x(), y = oy + t * d.y();
        if (t > 1e-6 && t < *best && x * x + y * y <= r * r) {
          *best = t;
          *normal = Eigen::Vector3d::UnitZ();
          hit = true;
        }
      }
      return hit;
    }
    case Shape::Kind::kSphere: {
      const Eigen::Vector3d oc = o - s.a;
      const double b = oc.dot(d);
      const double c = oc.squaredNorm() - s.b.x() * s.b.x();
      const double disc = b * b - c;
      if (disc < 0) return false;
      const double t = -b - std::sqrt(disc);
      if (t <= 1e-6 || t >= *best) return false;
      *best = t;
      *normal = (oc + t * d).normalized();
      return true;
    }
  }
  return false;
}

Eigen::Vector3d RandomColour(std::mt19937_64* rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  return Eigen::Vector3d(u(*rng), u(*rng), u(*rng));
}

constexpr EnumNames<SceneType, 3> kSceneNames = {
    {{SceneType::kUrban, "urban"}, {SceneType::kPoles, "poles"}, {SceneType::kOpen, "open"}}};

}  // namespace

bool ParseSceneType(const std::string& name, SceneType* type) {
  return ParseEnumName(kSceneNames, name, type);
}

std::string SceneTypeName(SceneType type) { return EnumName(kSceneNames, type); }

std::string SceneTypeChoices() { return EnumNameChoices(kSceneNames); }

double CellNoise(const Eigen::Vector3d& p, double cell_m) {
  uint64_t h = 0x9E3779B97F4A7C15ULL;
  for (int k = 0; k < 3; ++k) {
    const int64_t c = static_cast<int64_t>(std::floor(p[k] / cell_m));
    h ^= static_cast<uint64_t>(c) + 0x9E3779B97F4A7C15ULL + (h << 6) + (h >> 2);
    h *= 0xBF58476D1CE4E5B9ULL;
    h ^= h >> 31;
  }
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

void SceneObject::UpdateBounds() {
  box_min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  box_max = -box_min;
  for (const Shape& s : shapes) {
    Eigen::Vector3d lo = s.a, hi = s.b;
    switch (s.kind) {
      case Shape::Kind::kBox:
        lo = s.a;
        hi = s.b;
        break;
      case Shape::Kind::kCylinder:
        lo = Eigen::Vector3d(s.a.x() - s.b.x(), s.a.y() - s.b.x(), s.a.z());
        hi = Eigen::Vector3d(s.a.x() + s.b.x(), s.a.y() + s.b.x(), s.b.z());
        break;
      case Shape::Kind::kSphere:
        lo = s.a - Eigen::Vector3d::Constant(s.b.x());
        hi = s.a + Eigen::Vector3d::Constant(s.b.x());
        break;
    }
    box_min = box_min.cwiseMin(lo);
    box_max = box_max.cwiseMax(hi);
  }
}

int AzimuthIndex::Bin(double azimuth_rad) const {
  int b = static_cast<int>(std::floor((azimuth_rad + M_PI) / (2 * M_PI) * kBins));
  return ((b % kBins) + kBins) % kBins;
}

int Scene::AddMaterial(const Material& m) {
  materials_.push_back(m);
  return static_cast<int>(materials_.size()) - 1;
}

void Scene::AddObject(SceneObject object) {
  object.UpdateBounds();
  if (object.moving) {
    max_object_speed_ =
        std::max(max_object_speed_,
                 std::abs(object.speed) + (object.follows_ego ? SimTrajectory::kMaxSpeedMps : 0.0));
  }
  objects_.push_back(std::move(object));
}

// Places the scene's objects along the road.
class SceneBuilder {
 public:
  SceneBuilder(Scene* scene, std::mt19937_64* rng) : scene_(scene), rng_(rng) {}

  double U(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(*rng_); }

  // A static object in the road frame at arc length s (local x along the road, y left).
  SceneObject RoadsideObject(double s, const std::string& name) {
    SceneObject o;
    o.position = scene_->road_->Position(s);
    o.yaw = scene_->road_->Heading(s);
    o.name = name;
    return o;
  }

  int Mat(const Eigen::Vector3d& bgr, double reflectance, Texture texture = Texture::kPlain) {
    Material m;
    m.albedo_bgr = bgr;
    m.reflectance = reflectance;
    m.texture = texture;
    return scene_->AddMaterial(m);
  }

  void Sidewalks(double s_min, double s_max) {
    const int pavement = Mat(Eigen::Vector3d(0.62, 0.63, 0.66), 0.25, Texture::kAsphalt);
    for (double s = s_min; s < s_max; s += 4.0) {
      SceneObject o = RoadsideObject(s + 2.0, "sidewalk");
      o.object_class = ObjectClass::kGround;
      o.shapes.push_back(Box(Eigen::Vector3d(-2.02, -kRightFrontM - 1.0, 0),
                             Eigen::Vector3d(2.02, kRightKerbM, kSidewalkHeightM), pavement));
      o.shapes.push_back(Box(Eigen::Vector3d(-2.02, kLeftKerbM, 0),
                             Eigen::Vector3d(2.02, kLeftFrontM + 1.0, kSidewalkHeightM), pavement));
      scene_->AddObject(o);
    }
  }

  void LaneMarkings(double s_min, double s_max) {
    const int paint = Mat(Eigen::Vector3d(0.92, 0.92, 0.92), 0.6);
    for (double s = s_min; s < s_max; s += 9.0) {  // dashed centre line: 3 m dash, 6 m gap
      SceneObject o = RoadsideObject(s + 1.5, "marking");
      o.object_class = ObjectClass::kGround;
      o.shapes.push_back(
          Box(Eigen::Vector3d(-1.5, 1.675, 0), Eigen::Vector3d(1.5, 1.825, 0.01), paint));
      scene_->AddObject(o);
    }
    for (double s = s_min; s < s_max; s += 6.0) {  // solid line at the parking strip
      SceneObject o = RoadsideObject(s + 3.0, "marking");
      o.object_class = ObjectClass::kGround;
      o.shapes.push_back(
          Box(Eigen::Vector3d(-3.02, -2.1, 0), Eigen::Vector3d(3.02, -1.95, 0.01), paint));
      scene_->AddObject(o);
    }
  }

  void Buildings(double s_min, double s_max, bool right) {
    const double side = right ? -1.0 : 1.0;
    double s = s_min + U(0, 5);
    while (s < s_max) {
      const double k = std::max(std::abs(scene_->road_->Curvature(s)),
                                std::abs(scene_->road_->Curvature(s + 20)));
      const double length = k > 1.0 / 60 ? U(7, 12) : U(8, 22);
      const double front = (right ? kRightFrontM : kLeftFrontM) + U(0.0, 4.0);
      const double depth = U(8, 12), height = U(6, 20);
      SceneObject o = RoadsideObject(s + length / 2, "building");
      const int wall = Mat(RandomColour(rng_, 0.45, 0.85), U(0.2, 0.5), Texture::kFacade);
      const int glass = Mat(RandomColour(rng_, 0.08, 0.2), 0.05);
      const int trim = Mat(RandomColour(rng_, 0.7, 0.95), 0.4);
      const double face = side * front;  // the wall's face towards the road
      const double back = side * (front + depth);
      o.shapes.push_back(Box(Eigen::Vector3d(-length / 2, std::min(face, back), 0),
                             Eigen::Vector3d(length / 2, std::max(face, back), height), wall));
      // Protruding window panes and a door (image edges; small depth steps).
      auto facade_box = [&](double x0, double x1, double z0, double z1, double out, int mat) {
        const double y0 = face, y1 = face - side * out;
        o.shapes.push_back(Box(Eigen::Vector3d(x0, std::min(y0, y1), z0),
                               Eigen::Vector3d(x1, std::max(y0, y1), z1), mat));
      };
      const double column = U(2.2, 3.2);
      const int columns = std::max(1, static_cast<int>((length - 1.0) / column));
      const double x_start = -0.5 * (columns - 1) * column;
      const double window_w = U(0.9, 1.5), window_h = U(1.2, 1.7);
      for (double floor_z = 3.0; floor_z + 2.0 < height; floor_z += 3.0) {
        for (int c = 0; c < columns; ++c) {
          const double x = x_start + c * column;
          facade_box(x - window_w / 2, x + window_w / 2, floor_z + 0.8, floor_z + 0.8 + window_h,
                     0.06, glass);
        }
      }
      facade_box(-0.6, 0.6, 0.0, 2.2, 0.08, glass);  // door
      // Cornice at the top (a strong horizontal depth edge) and balconies on some buildings.
      facade_box(-length / 2, length / 2, height - 0.35, height, 0.35, trim);
      if (U(0, 1) < 0.35) {
        for (double floor_z = 3.0; floor_z + 3.0 < height; floor_z += 3.0) {
          facade_box(x_start - 0.8, x_start + 0.8, floor_z, floor_z + 0.15, 1.0, trim);
          facade_box(x_start - 0.8, x_start + 0.8, floor_z + 0.15, floor_z + 1.05, 0.95, trim);
        }
      }
      scene_->AddObject(o);
      s += length + U(1.0, 8.0);
    }
  }

  void Poles(double s_min, double s_max, bool right, double spacing_lo, double spacing_hi,
             bool with_signs) {
    const double lateral = right ? kRightKerbM - 0.7 : kLeftKerbM + 0.7;
    const int metal = Mat(Eigen::Vector3d(0.35, 0.36, 0.38), 0.5);
    for (double s = s_min + U(0, spacing_hi); s < s_max; s += U(spacing_lo, spacing_hi)) {
      SceneObject o = RoadsideObject(s, "pole");
      const bool sign = with_signs && U(0, 1) < 0.4;
      if (sign) {
        const int plate = Mat(
            U(0, 1) < 0.5 ? Eigen::Vector3d(0.7, 0.3, 0.1) : Eigen::Vector3d(0.1, 0.1, 0.75), 0.9);
        o.shapes.push_back(Cylinder(0, lateral, 0.04, 0, 2.6, metal));
        o.shapes.push_back(Box(Eigen::Vector3d(-0.03, lateral - 0.35, 2.0),
                               Eigen::Vector3d(0.03, lateral + 0.35, 2.7), plate));
        o.name = "sign";
      } else {
        o.shapes.push_back(Cylinder(0, lateral, U(0.07, 0.13), 0, U(5, 8), metal));
      }
      scene_->AddObject(o);
    }
  }

  void Trees(double s_min, double s_max, bool right, bool with_crowns) {
    const double lateral = right ? kRightKerbM - 2.2 : kLeftKerbM + 2.2;
    const int bark = Mat(Eigen::Vector3d(0.12, 0.2, 0.28), 0.3);
    for (double s = s_min + U(0, 20); s < s_max; s += U(12, 30)) {
      SceneObject o = RoadsideObject(s, "tree");
      const double trunk_h = U(2.2, 3.5), crown_r = U(1.4, 2.6);
      o.shapes.push_back(Cylinder(0, lateral, U(0.14, 0.28), 0, trunk_h + 0.3, bark));
      if (with_crowns) {
        const int leaves =
            Mat(Eigen::Vector3d(U(0.1, 0.2), U(0.35, 0.55), U(0.15, 0.3)), 0.35, Texture::kFoliage);
        o.shapes.push_back(
            Sphere(Eigen::Vector3d(0, lateral, trunk_h + 0.9 * crown_r), crown_r, leaves));
      }
      scene_->AddObject(o);
    }
  }

  // A car body and cabin centred at local lateral offset y.
  static void AddCarShapes(SceneObject* o, double y, int body, int cabin) {
    o->shapes.push_back(
        Box(Eigen::Vector3d(-2.2, y - 0.9, 0.25), Eigen::Vector3d(2.2, y + 0.9, 1.0), body));
    o->shapes.push_back(
        Box(Eigen::Vector3d(-1.2, y - 0.8, 1.0), Eigen::Vector3d(1.0, y + 0.8, 1.5), cabin));
  }

  void ParkedCars(double s_min, double s_max) {
    for (double s = s_min + U(0, 10); s < s_max; s += U(6, 25)) {
      if (U(0, 1) < 0.3) continue;
      SceneObject o = RoadsideObject(s, "parked_car");
      const int body = Mat(RandomColour(rng_, 0.1, 0.9), 0.5);
      const int cabin = Mat(Eigen::Vector3d(0.15, 0.12, 0.1), 0.1);
      AddCarShapes(&o, /*y=*/-3.0, body, cabin);  // in the parking strip
      scene_->AddObject(o);
    }
  }

  void MovingObjects(int count, double s_start) {
    bool have_leader = false;
    const double oncoming_speed = U(8, 14);
    double next_oncoming = s_start + U(15, 30);
    for (int k = 0; k < count; ++k) {
      SceneObject o;
      o.moving = true;
      o.object_class = ObjectClass::kMoving;
      if (k % 2 == 0) {
        const int body = Mat(RandomColour(rng_, 0.1, 0.9), 0.5);
        const int cabin = Mat(Eigen::Vector3d(0.15, 0.12, 0.1), 0.1);
        AddCarShapes(&o, /*y=*/0.0, body, cabin);
        if (!have_leader && U(0, 1) < 0.5) {  // ahead in the ego lane, pulling away
          have_leader = true;
          o.name = "car_leading";
          o.follows_ego = true;
          o.s0 = U(15, 35);
          o.speed = U(0.5, 2.5);
          o.lateral = 0.0;
        } else {  // oncoming lane, spaced so that cars never overlap
          o.name = "car_oncoming";
          o.s0 = next_oncoming;
          next_oncoming += U(15, 40);
          o.speed = -oncoming_speed;
          o.lateral = 3.6;
          o.yaw_offset = M_PI;
        }
      } else {
        const int cloth = Mat(RandomColour(rng_, 0.05, 0.8), 0.3);
        const int skin = Mat(Eigen::Vector3d(0.55, 0.65, 0.8), 0.3);
        // Standing on the sidewalk, in the walking lanes clear of poles and tree trunks.
        const double z0 = kSidewalkHeightM;
        o.shapes.push_back(
            Box(Eigen::Vector3d(-0.15, -0.2, z0), Eigen::Vector3d(0.15, 0.2, z0 + 1.45), cloth));
        o.shapes.push_back(Sphere(Eigen::Vector3d(0, 0, z0 + 1.62), 0.13, skin));
        o.name = "pedestrian";
        const bool right = U(0, 1) < 0.5, inner = U(0, 1) < 0.5;
        o.lateral =
            right ? (inner ? -U(5.3, 5.5) : -U(7.0, 8.0)) : (inner ? U(6.7, 6.9) : U(8.8, 9.5));
        o.s0 = s_start + U(-5, 50);
        const bool forward = U(0, 1) < 0.5;
        o.speed = (forward ? 1.0 : -1.0) * U(1.0, 1.6);
        o.yaw_offset = forward ? 0.0 : M_PI;
      }
      scene_->AddObject(o);
    }
  }

 private:
  Scene* scene_;
  std::mt19937_64* rng_;
};

Scene Scene::Build(SceneType type, int dynamic_objects, const SimRoad* road,
                   const SimTrajectory* trajectory, std::mt19937_64* rng) {
  Scene scene;
  scene.road_ = road;
  scene.trajectory_ = trajectory;
  Material asphalt;
  asphalt.albedo_bgr = Eigen::Vector3d(0.3, 0.3, 0.31);
  asphalt.reflectance = 0.15;
  asphalt.texture = Texture::kAsphalt;
  scene.ground_material_ = scene.AddMaterial(asphalt);

  SceneBuilder builder(&scene, rng);
  const double s_min = road->s_begin() + 1.0, s_max = road->s_end() - 1.0;
  switch (type) {
    case SceneType::kUrban:
      builder.Sidewalks(s_min, s_max);
      builder.LaneMarkings(s_min, s_max);
      builder.Buildings(s_min, s_max, /*right=*/true);
      builder.Buildings(s_min, s_max, /*right=*/false);
      builder.Poles(s_min, s_max, true, 15, 35, true);
      builder.Poles(s_min, s_max, false, 15, 35, true);
      builder.Trees(s_min, s_max, true, true);
      builder.Trees(s_min, s_max, false, true);
      builder.ParkedCars(s_min, s_max);
      break;
    case SceneType::kPoles:  // vertical structures only
      builder.Poles(s_min, s_max, true, 6, 14, false);
      builder.Poles(s_min, s_max, false, 6, 14, false);
      builder.Trees(s_min, s_max, true, false);
      builder.Trees(s_min, s_max, false, false);
      break;
    case SceneType::kOpen:  // almost nothing: a painted road
      builder.LaneMarkings(s_min, s_max);
      break;
  }
  builder.MovingObjects(dynamic_objects, 0.0);
  return scene;
}

Pose2 Scene::ObjectPose(int index, double t) const {
  const SceneObject& o = objects_[index];
  if (!o.moving) return {o.position, o.yaw};
  double s = o.s0 + o.speed * t;
  if (o.follows_ego) s += trajectory_->ArcLength(t);
  return {road_->At(s, o.lateral), road_->Heading(s) + o.yaw_offset};
}

AzimuthIndex Scene::BuildIndex(const Eigen::Vector2d& sensor_xy, double t_begin, double t_end,
                               double margin_m, double max_range_m) const {
  AzimuthIndex index;
  index.bins.resize(AzimuthIndex::kBins);
  const double t_mid = 0.5 * (t_begin + t_end);
  for (int i = 0; i < static_cast<int>(objects_.size()); ++i) {
    const SceneObject& o = objects_[i];
    const Pose2 pose = ObjectPose(i, t_mid);
    const Eigen::Vector2d local_centre = 0.5 * (o.box_min + o.box_max).head<2>();
    const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
    const Eigen::Vector2d centre =
        pose.position + Eigen::Vector2d(c * local_centre.x() - s * local_centre.y(),
                                        s * local_centre.x() + c * local_centre.y());
    double radius = 0.5 * (o.box_max - o.box_min).head<2>().norm() + margin_m;
    if (o.moving) {
      const double speed = std::abs(o.speed) + (o.follows_ego ? SimTrajectory::kMaxSpeedMps : 0);
      radius += speed * 0.5 * (t_end - t_begin);
    }
    const Eigen::Vector2d delta = centre - sensor_xy;
    const double distance = delta.norm();
    if (distance - radius > max_range_m) continue;
    if (distance <= radius * 1.05) {
      for (auto& bin : index.bins) bin.push_back(i);
      continue;
    }
    const double half = std::asin(std::min(1.0, radius / distance)) + 1e-3;
    const double azimuth = std::atan2(delta.y(), delta.x());
    const int b0 = index.Bin(azimuth - half);
    const int count = static_cast<int>(std::ceil(2 * half / (2 * M_PI) * AzimuthIndex::kBins)) + 1;
    for (int k = 0; k <= count && k < AzimuthIndex::kBins; ++k) {
      index.bins[(b0 + k) % AzimuthIndex::kBins].push_back(i);
    }
  }
  return index;
}

bool Scene::Intersect(const AzimuthIndex& index, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& dir, double t_s, double max_range_m,
                      RayHit* hit) const {
  double best = max_range_m;
  bool found = false;
  // Ground plane z = 0.
  if (dir.z() < -1e-9 && origin.z() > 0) {
    const double t = -origin.z() / dir.z();
    if (t < best) {
      best = t;
      hit->normal_world = Eigen::Vector3d::UnitZ();
      hit->material = ground_material_;
      hit->object = -1;
      found = true;
    }
  }
  const std::vector<int>& candidates = index.bins[index.Bin(std::atan2(dir.y(), dir.x()))];
  for (int i : candidates) {
    const SceneObject& o = objects_[i];
    const Pose2 pose = ObjectPose(i, t_s);
    const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
    const Eigen::Vector3d rel = origin - Eigen::Vector3d(pose.position.x(), pose.position.y(), 0);
    const Eigen::Vector3d o_local(c * rel.x() + s * rel.y(), -s * rel.x() + c * rel.y(), rel.z());
    const Eigen::Vector3d d_local(c * dir.x() + s * dir.y(), -s * dir.x() + c * dir.y(), dir.z());
    const Eigen::Vector3d inv_d = d_local.cwiseInverse();
    double t0, t1;
    int axis;
    if (!RayBox(o_local, inv_d, o.box_min, o.box_max, &t0, &t1, &axis) || t0 >= best) continue;
    for (const Shape& shape : o.shapes) {
      Eigen::Vector3d normal_local;
      if (IntersectShape(shape, o_local, d_local, inv_d, &best, &normal_local)) {
        hit->normal_world =
            Eigen::Vector3d(c * normal_local.x() - s * normal_local.y(),
                            s * normal_local.x() + c * normal_local.y(), normal_local.z());
        hit->material = shape.material;
        hit->object = i;
        found = true;
      }
    }
  }
  if (!found) return false;
  hit->range = best;
  hit->point_world = origin + best * dir;
  return true;
}

}  // namespace stcalib::sim
