// The floor points of each shape kind (floor_points.hpp).
#include "graspsim/engine/floor_points.hpp"

#include <algorithm>
#include <cmath>

namespace graspsim {

Vec3 box_vertex(const Vec3& h, int k) {
  return Vec3((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z());
}

int floor_point_count(const Shape& s) {
  switch (s.kind) {
    case ShapeKind::kBox: return 8;
    case ShapeKind::kSphere: return 1;
    case ShapeKind::kCapsule: return 2;
    case ShapeKind::kCylinder: return 2 * kCylinderRimPoints;
    case ShapeKind::kConvex:
      return s.hull ? static_cast<int>(s.hull->vertices.size()) : (s.mesh ? static_cast<int>(s.mesh->vertices.size()) : 0);
    case ShapeKind::kMesh: return s.mesh ? static_cast<int>(s.mesh->vertices.size()) : 0;
  }
  return 0;
}

Vec3 floor_point(const Shape& s, const Mat3& rotation, int k, bool& rolling) {
  rolling = false;
  switch (s.kind) {
    case ShapeKind::kBox: return rotation * box_vertex(s.half_extents, k);
    case ShapeKind::kSphere:
      rolling = true;
      return Vec3(0.0, 0.0, -s.radius);
    case ShapeKind::kCapsule:
      rolling = true;
      return rotation * Vec3(0.0, 0.0, k == 0 ? -s.half_length : s.half_length) + Vec3(0.0, 0.0, -s.radius);
    case ShapeKind::kCylinder: {
      const int j = k % kCylinderRimPoints;
      const double angle = 2.0 * M_PI * j / kCylinderRimPoints;
      const double z = k < kCylinderRimPoints ? -s.half_length : s.half_length;
      return rotation * Vec3(s.radius * std::cos(angle), s.radius * std::sin(angle), z);
    }
    case ShapeKind::kConvex:
      return rotation * (s.hull ? s.hull->vertices[k] : s.mesh->vertices[k]);
    case ShapeKind::kMesh: return rotation * s.mesh->vertices[k];
  }
  return Vec3::Zero();
}

double floor_reach(const Shape& shape) {
  if (shape.kind == ShapeKind::kCapsule) return shape.half_length + shape.radius;
  double reach = 0.0;
  for (int k = 0; k < floor_point_count(shape); ++k) {
    bool rolling = false;
    reach = std::max(reach, floor_point(shape, Mat3::Identity(), k, rolling).norm());
  }
  return reach;
}

}  // namespace graspsim
