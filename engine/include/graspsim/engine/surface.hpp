// Surface queries for finger contact, per shape, in the body frame, for a pad of radius r
// (r = 0: a point finger). A pad touches where its centre (the HIP) enters the shape grown by r.
//
//  - ENTRY: where a finger path a -> b first enters the grown shape, and through which feature
//    (the one entered, not the one nearest to b: no push-through, b may lie beyond a thin body).
//  - TRACK: given the contact's features (its constraint set), its last surface point and normal,
//    and the new HIP: the frictionless god-object SP, the contact normal, the depth and the new
//    features, or "contact ended" (the HIP left the body: the frictionless god-object's rule).
//  - PROJECT: a point near the surface (the friction god-object after a step along the chord)
//    moved back onto the surface by the same walk, starting from SP.
//
// Box: the exact slab rules (faces offset by r, edges square, contact ends off a face's edge).
// Sphere, capsule, cylinder: analytic closest points, the exact Minkowski sum with the pad.
// Convex polyhedra and triangle meshes: a god-object walk over constraint planes with history
// (Zilles & Salisbury 1995, Ruspini et al. 1997). See engine/README.md, "Finger contact".
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/shape.hpp"

namespace graspsim {

inline constexpr int kMaxFeatures = 3;   // constraint planes held at once (a corner)

// The features a contact is held by. Box: face 0..5. Sphere: 0. Capsule: 0 side, 1 top cap,
// 2 bottom cap. Cylinder: 0 side, 1 top cap, 2 bottom cap, 3 top rim, 4 bottom rim (rims exist
// only for a pad, r > 0). Convex polyhedron: hull face indices. Mesh: triangle indices.
struct Features {
  int count = 0;                          // 1..3 in contact
  std::array<int, kMaxFeatures> ids{};    // feature ids (see above), the first count valid
};

// A shape with what its queries need precomputed (plane equations, edge normals, neighbours,
// face rings), so that no query allocates.
class SurfaceGeometry {
 public:
  explicit SurfaceGeometry(const Shape& shape);
  const Shape& shape() const { return shape_; }

  // Polygonal faces (kConvex, kMesh), flattened.
  struct PolyFace {
    Vec3 normal;       // 1, unit, out
    double offset;     // m: normal . x = offset on the face
    int first;         // index of its first corner in corners_ (and edges)
    int count;         // corners
    int ring_first;    // its ring (faces sharing a corner with it, itself excluded) in ring_
    int ring_count;
  };
  int face_count() const { return static_cast<int>(faces_.size()); }
  const PolyFace& face(int i) const { return faces_[i]; }
  const Vec3& corner(int i) const { return corners_[i]; }          // m
  const Vec3& edge_normal(int i) const { return edge_normals_[i]; }  // 1: in-plane, inward, unit
  int neighbour(int i) const { return neighbours_[i]; }   // face across edge i (corner i -> i+1), -1 open
  int ring(int i) const { return ring_[i]; }

  // A bounding-volume tree over the faces (kConvex, kMesh): axis-aligned boxes of the faces'
  // corners, split at the median centroid along the longest axis, a few faces per leaf. A face's
  // entry region for a pad of radius r (its polygon grown in-plane by r + slack, offset by r) lies
  // within its box grown by kappa (r + slack) + r, kappa = max over its corners of
  // 1 / sin(angle / 2) (an offset polygon's corner moves that far); `kappa` is the largest in the
  // node. Degenerate faces (no plane) are left out: no path crosses them.
  struct BvhNode {
    Vec3 lo, hi;     // m, body frame: box of the corners below the node
    double kappa;    // 1: the largest corner factor below the node
    int first;       // leaf: first index into bvh_faces(); inner: index of the left child
    int count;       // leaf: faces; inner: 0 (the right child follows the left's subtree)
    int right;       // inner: index of the right child
  };
  const std::vector<BvhNode>& bvh() const { return bvh_; }
  int bvh_face(int i) const { return bvh_faces_[i]; }

 private:
  Shape shape_;
  std::vector<PolyFace> faces_;
  std::vector<Vec3> corners_;
  std::vector<Vec3> edge_normals_;
  std::vector<int> neighbours_;
  std::vector<int> ring_;
  std::vector<BvhNode> bvh_;
  std::vector<int> bvh_faces_;
  int build_bvh(int first, int count, const std::vector<Vec3>& centroids);
};

struct SurfaceEntry {
  Vec3 point;          // m: SP at entry, on the grown surface (the pad centre's surface)
  Vec3 normal;         // 1: contact normal there, unit, out
  double t;            // 1: fraction of the path a -> b at entry (0 when a was already inside)
  Features features;
};

// Where the path a -> b (body frame) first enters the shape grown by r, else none.
std::optional<SurfaceEntry> surface_entry(const SurfaceGeometry& g, double r, const Vec3& a,
                                          const Vec3& b);

struct SurfaceTrack {
  Vec3 point;          // m: SP, the frictionless god-object, on the grown surface
  Vec3 normal;         // 1: contact normal, unit, out: (SP - HIP) / depth when held by 2-3 planes
  double depth;        // m: |SP - HIP| (> 0)
  Features features;   // the constraint set holding SP
};

// Tracks a contact held by `features` with last surface point `sp` and normal `normal` to the
// new HIP `hip`. Returns false when the contact ended (the HIP left the grown body).
bool surface_track(const SurfaceGeometry& g, double r, const Features& features, const Vec3& sp,
                   const Vec3& normal, const Vec3& hip, SurfaceTrack& out);

// Moves `target` (a point near the surface, e.g. the friction god-object moved along the chord
// towards SP) onto the grown surface, walking from the contact's SP and features and never
// leaving the surface: the nearest surface point reached from SP. Box: target unchanged (it
// stays on the contacted face's plane).
Vec3 surface_project(const SurfaceGeometry& g, double r, const SurfaceTrack& at, const Vec3& target);

}  // namespace graspsim
