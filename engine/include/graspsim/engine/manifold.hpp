// Contact manifolds between two convex polyhedra (box, convex hull): the separating-axis test
// over face normals and edge-edge directions, then, for a face contact, the incident face
// clipped against the reference face's side planes (Sutherland-Hodgman, as Box2D and Bullet do),
// so that a cube on a thin beam gets the four points where the two overlap, with a depth each.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/shape.hpp"

namespace graspsim {

// One contact point between bodies A and B.
struct ManifoldPoint {
  Vec3 point{0.0, 0.0, 0.0};    // m, world: midway between the two surfaces
  Vec3 normal{0.0, 0.0, 1.0};   // 1, world, unit: from A towards B (the force on B is along it)
  double depth = 0.0;           // m: > 0, overlap along the normal
  std::uint64_t key = 0;        // feature id: the same features give the same key at every step,
                                // whichever body's face is the reference (a feature of A and one of
                                // B: A's vertex in B's face, B's vertex in A's face, or two edges)
};

// A convex polyhedron with its edges listed once (a < b), for the edge-edge axes.
struct HullEdges {
  const ConvexPolyhedron* hull = nullptr;
  std::vector<std::array<int, 4>> edges;   // vertex indices a < b, then the two faces that meet
                                           // there (for the Gauss-map test)
  int max_face_vertices = 0;
};
HullEdges hull_edges(const ConvexPolyhedron& hull);

// Buffers for manifold(); sized once (reserve_for) so that the query allocates nothing.
struct ManifoldScratch {
  struct ClipVertex {
    Vec3 x;               // m, world
    std::uint64_t key;    // feature id of the point
    std::uint64_t edge;   // feature id of the polygon's edge from this vertex to the next: an
                          // incident edge, or a reference side plane the polygon was cut along
  };
  std::vector<Vec3> world_a, world_b;          // m: vertices of A and B in world
  std::vector<ClipVertex> polygon, clipped;    // Sutherland-Hodgman buffers
  void reserve_for(const HullEdges& a, const HullEdges& b);
};

inline constexpr int kMaxManifoldPoints = 16;

// The contact points of A and B at poses (x, R) (centre of mass, body to world), deepest first
// when more than `capacity` were found (ties by key), else in clipping order. Returns the count
// written to `out` (0 when separated). A face contact's reference face is the face (of A or B)
// with the least penetration, A preferred unless B's is clearly less (Box2D's 0.98 relative
// tolerance, so that the choice seldom flickers on a resting stack; when it does, the points'
// keys, which name features of A and B and not the reference, stay); an edge-edge contact gives
// one point, at the middle of the two edges' closest points, used only when its axis separates
// clearly more than any face axis and the closest points lie within both edges. Only edge pairs
// that form a face of the Minkowski difference are tested (Gregorius' Gauss-map test): an edge
// lying on the other body's face is a face contact, never an edge contact that flickers with it.
int manifold(const HullEdges& a, const Vec3& xa, const Mat3& ra, const HullEdges& b, const Vec3& xb,
             const Mat3& rb, ManifoldScratch& scratch, ManifoldPoint* out, int capacity, double margin = 0.0);

}  // namespace graspsim
