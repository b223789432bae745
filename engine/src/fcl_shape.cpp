// FCL geometry of each shape kind.
#include "fcl_shape.hpp"

#include <stdexcept>
#include <vector>

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>

namespace graspsim::detail {

std::shared_ptr<fcl::CollisionGeometryd> fcl_geometry(const Shape& s) {
  switch (s.kind) {
    case ShapeKind::kBox: {
      const Vec3 size = 2.0 * s.half_extents;
      return std::make_shared<fcl::Boxd>(size.x(), size.y(), size.z());
    }
    case ShapeKind::kSphere:
      return std::make_shared<fcl::Sphered>(s.radius);
    case ShapeKind::kCylinder:
      return std::make_shared<fcl::Cylinderd>(s.radius, 2.0 * s.half_length);
    case ShapeKind::kCapsule:
      return std::make_shared<fcl::Capsuled>(s.radius, 2.0 * s.half_length);
    case ShapeKind::kConvex: {
      if (!s.hull) throw std::invalid_argument("convex shape without its hull");
      auto vertices = std::make_shared<std::vector<fcl::Vector3d>>(s.hull->vertices.begin(),
                                                                   s.hull->vertices.end());
      auto faces = std::make_shared<std::vector<int>>();
      for (const PolyFace& f : s.hull->faces) {   // FCL's encoding: n, i_0, ..., i_{n-1}, ...
        faces->push_back(static_cast<int>(f.vertices.size()));
        faces->insert(faces->end(), f.vertices.begin(), f.vertices.end());
      }
      return std::make_shared<fcl::Convexd>(vertices, static_cast<int>(s.hull->faces.size()), faces);
    }
    case ShapeKind::kMesh: {
      if (!s.mesh) throw std::invalid_argument("mesh shape without its triangles");
      auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
      std::vector<fcl::Vector3d> vertices(s.mesh->vertices.begin(), s.mesh->vertices.end());
      std::vector<fcl::Triangle> triangles;
      triangles.reserve(s.mesh->triangles.size());
      for (const auto& t : s.mesh->triangles) triangles.emplace_back(t[0], t[1], t[2]);
      model->beginModel();
      model->addSubModel(vertices, triangles);
      model->endModel();
      return model;
    }
  }
  throw std::invalid_argument("unknown shape kind");
}

}  // namespace graspsim::detail
