// Triangle meshes built in C++ for the shape tests: a box, an icosphere, a prism, an L-shaped
// block, and rigid motions of them.
#pragma once

#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "graspsim/engine/shape.hpp"

namespace graspsim::test {

// Box of half sizes h: vertices in box_vertex() order, each box_polyhedron() face split in two.
inline TriangleMesh box_mesh(const Vec3& h) {
  const ConvexPolyhedron p = box_polyhedron(h);
  TriangleMesh m;
  m.vertices = p.vertices;
  for (const PolyFace& f : p.faces) {
    const auto& v = f.vertices;
    m.triangles.push_back({v[0], v[1], v[2]});
    m.triangles.push_back({v[0], v[2], v[3]});
  }
  return m;
}

// x -> rotation * x + shift for every vertex.
inline TriangleMesh moved(TriangleMesh m, const Mat3& rotation, const Vec3& shift) {
  for (Vec3& v : m.vertices) v = rotation * v + shift;
  return m;
}

// An icosahedron subdivided `level` times (20 * 4^level triangles), vertices on the sphere of
// radius r: an inscribed polyhedron whose edges halve with each level.
inline TriangleMesh icosphere(double r, int level) { return icosphere_mesh(r, level); }

// A prism over a simple polygon (counter-clockwise in xy, seen from +z), z in [-hz, hz]; each cap
// a fan from the polygon's vertex `fan` (which must see every other vertex).
inline TriangleMesh prism(const std::vector<Vec3>& polygon, double hz, int fan = 0) {
  const int n = static_cast<int>(polygon.size());
  TriangleMesh m;
  for (const Vec3& p : polygon) m.vertices.emplace_back(p.x(), p.y(), -hz);
  for (const Vec3& p : polygon) m.vertices.emplace_back(p.x(), p.y(), hz);
  for (int k = 1; k + 1 < n; ++k) {
    const int a = fan, b = (fan + k) % n, c = (fan + k + 1) % n;
    m.triangles.push_back({n + a, n + b, n + c});   // top, counter-clockwise from +z
    m.triangles.push_back({a, c, b});               // bottom, reversed
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.triangles.push_back({i, j, n + j});
    m.triangles.push_back({i, n + j, n + i});
  }
  return m;
}

// A regular n-gon of circumradius r in the xy plane, counter-clockwise.
inline std::vector<Vec3> regular_polygon(int n, double r) {
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * 3.14159265358979323846 * i / n;
    p.emplace_back(r * std::cos(a), r * std::sin(a), 0.0);
  }
  return p;
}

// The L: the square [0, 2a]^2 less its corner [a, 2a]^2, as a prism of half height hz; it is the
// union of the boxes [0, 2a] x [0, a] and [0, a] x [a, 2a]. Fan from the reflex corner (a, a).
inline TriangleMesh l_block(double a, double hz) {
  return prism({{0, 0, 0}, {2 * a, 0, 0}, {2 * a, a, 0}, {a, a, 0}, {a, 2 * a, 0}, {0, 2 * a, 0}}, hz, 3);
}

}  // namespace graspsim::test
