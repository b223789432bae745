// Shapes of bodies, in the body frame (origin at the centre of mass, axes along the principal
// axes of inertia). Parameters only: the queries live in collision, finger_contact and
// object_contact.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "graspsim/engine/math.hpp"

namespace graspsim {

enum class ShapeKind {
  kBox,        // half_extents
  kSphere,     // radius
  kCylinder,   // radius, half_length along body z (flat caps at z = +-half_length)
  kCapsule,    // radius, half_length: the segment z in [-half_length, half_length] grown by radius
  kConvex,     // mesh (a convex triangle mesh) and hull (its faces, coplanar triangles merged)
  kMesh,       // mesh: a closed triangle mesh, not necessarily convex
};

// A closed triangle mesh.
struct TriangleMesh {
  std::vector<Vec3> vertices;                  // m, body frame
  std::vector<std::array<int, 3>> triangles;   // vertex indices, counter-clockwise seen from
                                               // outside (right-hand normal points out)
};

// One planar face of a convex polyhedron.
struct PolyFace {
  Vec3 normal;                   // 1, body frame, unit, pointing out
  double offset;                 // m: points x on the face plane satisfy normal . x = offset
  std::vector<int> vertices;     // indices into ConvexPolyhedron::vertices, counter-clockwise
                                 // seen from outside
  std::vector<int> neighbours;   // the face across edge i (vertices[i] -> vertices[i + 1])
};

// A convex polyhedron: the intersection of its faces' half-spaces normal . x <= offset.
struct ConvexPolyhedron {
  std::vector<Vec3> vertices;    // m, body frame
  std::vector<PolyFace> faces;
};

struct Shape {
  ShapeKind kind = ShapeKind::kBox;
  Vec3 half_extents{0.05, 0.05, 0.05};   // m: box half sizes along body x, y, z
  double radius = 0.0;                   // m: sphere, cylinder, capsule
  double half_length = 0.0;              // m: cylinder, capsule, along body z
  std::shared_ptr<const TriangleMesh> mesh;       // kConvex, kMesh
  std::shared_ptr<const ConvexPolyhedron> hull;   // kBox and kConvex: the faces
};

// A box of the given half sizes as a shape (its hull filled in).
Shape box_shape(const Vec3& half_extents);

// The box as a convex polyhedron. Faces in box_face() order (0..5 = +x, -x, +y, -y, +z, -z),
// vertices in box_vertex() order (x fastest, then y, then z; bit 0 = +x, 1 = +y, 2 = +z).
ConvexPolyhedron box_polyhedron(const Vec3& half_extents);

}  // namespace graspsim
