// Shapes of bodies, in the body frame (origin at the centre of mass, axes along the principal
// axes of inertia). Parameters only: the queries live in collision, finger_contact and
// the contact gather (contact_gather.hpp, floor_points.hpp, narrowphase).
#pragma once

#include <array>
#include <memory>
#include <stdexcept>
#include <string>
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
  Vec3 half_extents{0.05, 0.05, 0.05};   // m: box half sizes along body x, y, z; other kinds:
                                         //    the largest |x|, |y|, |z| of the shape (a box
                                         //    about the origin that holds it), set by *_shape()
  double radius = 0.0;                   // m: sphere, cylinder, capsule
  double half_length = 0.0;              // m: cylinder, capsule, along body z
  std::shared_ptr<const TriangleMesh> mesh;       // kConvex, kMesh
  std::shared_ptr<const ConvexPolyhedron> hull;   // kBox and kConvex: the faces
};

// A box of the given half sizes as a shape (its hull filled in).
Shape box_shape(const Vec3& half_extents);

// The analytic solids, about the origin, axis along z.
Shape sphere_shape(double radius);
Shape cylinder_shape(double radius, double half_length);
Shape capsule_shape(double radius, double half_length);

// A bad triangle mesh: what is wrong, and the triangle it concerns (index into
// TriangleMesh::triangles, -1 when it concerns the whole mesh) so a file reader can name the
// line that made it.
class MeshError : public std::invalid_argument {
 public:
  MeshError(const std::string& what, int triangle) : std::invalid_argument(what), triangle_(triangle) {}
  int triangle() const { return triangle_; }

 private:
  int triangle_;
};

// Checks that the mesh bounds a solid: at least 4 triangles, indices in range, three distinct
// vertices per triangle, finite coordinates, every edge shared by exactly two triangles that run
// it in opposite directions (closed, consistently oriented, manifold), and a positive volume
// (counter-clockwise seen from outside). Throws MeshError naming the triangle or edge.
void check_closed_mesh(const TriangleMesh& mesh);

// The mesh without the vertices no triangle uses (indices renumbered, order kept).
TriangleMesh without_unused_vertices(const TriangleMesh& mesh);

// An icosahedron subdivided `level` times (20 * 4^level triangles, counter-clockwise seen from
// outside), every vertex on the sphere of `radius` (m): an inscribed polyhedron whose edges
// halve with each level. For tests, benchmarks and test scenes (5,120 triangles at level 4).
TriangleMesh icosphere_mesh(double radius, int level);

// The faces of a closed convex mesh: adjacent triangles in one plane merged into one face
// (within 1e-6 of the mesh's size, so files written with 6 to 7 digits pass), each face's
// vertices counter-clockwise seen from outside, its unit normal the area-weighted mean of its
// triangles' and its offset the largest normal . x of its vertices, neighbours across every
// edge. Vertices that lie on no face's boundary are dropped (indices renumbered in mesh order);
// a vertex in the middle of an edge stays, in both faces. Throws MeshError if the mesh is not
// closed and consistently oriented (check_closed_mesh) or not convex (a vertex farther than the
// tolerance outside a triangle's plane).
ConvexPolyhedron convex_polyhedron(const TriangleMesh& mesh);

// Shapes from meshes already in the body frame. Both check the mesh and drop unused vertices.
// convex_shape: a convex mesh, with its hull (throws as convex_polyhedron does).
// mesh_shape: a closed, consistently oriented mesh, convex or not (throws as check_closed_mesh).
Shape convex_shape(TriangleMesh mesh);
Shape mesh_shape(TriangleMesh mesh);

// Mass, centre of mass and inertia of a solid of uniform density.
struct MassProperties {
  double mass = 0.0;                 // kg
  Vec3 centre = Vec3::Zero();        // m: centre of mass, in the shape's frame
  Mat3 inertia = Mat3::Zero();       // kg m^2: inertia tensor about the centre of mass, shape axes
};

// Analytic for box, sphere, cylinder and capsule; exact polyhedral integrals (Eberly,
// "Polyhedral Mass Properties", the divergence theorem per triangle) for convex and mesh.
// density in kg/m^3.
MassProperties mass_properties(const Shape& shape, double density);
MassProperties mass_properties(const TriangleMesh& mesh, double density);

// The principal frame of a body: x_frame = centre + rotation * x_body, with the body frame at
// the centre of mass and along the principal axes. moments = diagonal of rotation^T I rotation.
// Axes are assigned closest to the frame's own axes: each principal axis goes to the frame axis
// it is most nearly parallel to, pointing the same way (rotation has a positive diagonal where
// it can while staying a proper rotation); equal moments (within 1e-9 relative) leave the frame's
// axes where they are, so an axis-aligned symmetric mesh is not rotated.
struct PrincipalFrame {
  Vec3 centre = Vec3::Zero();            // m: centre of mass in the original frame
  Mat3 rotation = Mat3::Identity();      // 1: columns = the body axes in the original frame
  Vec3 moments = Vec3::Zero();           // kg m^2: principal moments about body x, y, z
};
PrincipalFrame principal_frame(const MassProperties& properties);

// The mesh moved into its principal frame (x_body = rotation^T (x - centre)); `frame` receives
// the transform (at density 1 if `density` is not given). Throws as check_closed_mesh.
TriangleMesh to_principal_frame(const TriangleMesh& mesh, PrincipalFrame& frame, double density = 1.0);

// The box as a convex polyhedron. Faces in box_face() order (0..5 = +x, -x, +y, -y, +z, -z),
// vertices in box_vertex() order (x fastest, then y, then z; bit 0 = +x, 1 = +y, 2 = +z).
ConvexPolyhedron box_polyhedron(const Vec3& half_extents);

}  // namespace graspsim
