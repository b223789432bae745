// Shapes built by hand for the finger-contact tests: triangle meshes from voxels (a thin plate,
// an L-shaped solid, a cube with a notch), a convex prism (wedge), a tessellated sphere.
#pragma once

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <memory>
#include <vector>

#include "graspsim/engine/model.hpp"
#include "graspsim/engine/shape.hpp"
#include "test_shape_meshes.hpp"

namespace graspsim::test {

// A body that barely moves: 1e12 kg, so that 30 N move it by < 1e-11 m in 1 s (no gravity in the
// tests that use it); checks read its recorded pose.
inline BodyParams fixed_body(const std::string& name, const Shape& shape, const Material& material) {
  BodyParams b;
  b.name = name;
  b.shape = shape;
  b.mass = 1e12;
  b.inertia = box_inertia(b.mass, Vec3(0.05, 0.05, 0.05));
  b.material = material;
  return b;
}

// The closed surface of the union of grid cells (i, j, k), 0 <= i < n.x() etc., for which
// `filled` is true, each cell of size `cell` (m), the grid's low corner at `origin`: one quad
// (two triangles, counter-clockwise from outside) per cell face bordering an empty cell.
inline TriangleMesh voxel_mesh(const std::array<int, 3>& n, const Vec3& cell, const Vec3& origin,
                               const std::function<bool(int, int, int)>& filled) {
  TriangleMesh m;
  const auto id = [&](int i, int j, int k) { return i + (n[0] + 1) * (j + (n[1] + 1) * k); };
  for (int k = 0; k <= n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i)
        m.vertices.push_back(origin + Vec3(i * cell.x(), j * cell.y(), k * cell.z()));
  const auto in = [&](int i, int j, int k) {
    return i >= 0 && j >= 0 && k >= 0 && i < n[0] && j < n[1] && k < n[2] && filled(i, j, k);
  };
  // Corners of each face of a unit cell (bit 0 = +x, 1 = +y, 2 = +z), as in box_polyhedron.
  const std::array<std::array<int, 4>, 6> quads{{
      {1, 3, 7, 5}, {0, 4, 6, 2}, {2, 6, 7, 3}, {0, 1, 5, 4}, {4, 5, 7, 6}, {0, 2, 3, 1}}};
  const std::array<std::array<int, 3>, 6> dir{{{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}};
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        if (!in(i, j, k)) continue;
        for (int f = 0; f < 6; ++f) {
          if (in(i + dir[f][0], j + dir[f][1], k + dir[f][2])) continue;
          std::array<int, 4> v{};
          for (int c = 0; c < 4; ++c) {
            const int b = quads[f][c];
            v[c] = id(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
          }
          m.triangles.push_back({v[0], v[1], v[2]});
          m.triangles.push_back({v[0], v[2], v[3]});
        }
      }
  return m;
}

inline Shape mesh_shape(TriangleMesh mesh) {
  Shape s;
  s.kind = ShapeKind::kMesh;
  s.mesh = std::make_shared<const TriangleMesh>(std::move(mesh));
  return s;
}

// A convex polyhedron from its vertices and faces (corner lists counter-clockwise from
// outside): normals and offsets from the corners, neighbours across each edge.
inline ConvexPolyhedron polyhedron(std::vector<Vec3> vertices, const std::vector<std::vector<int>>& faces) {
  ConvexPolyhedron p;
  p.vertices = std::move(vertices);
  for (const auto& vs : faces) {
    PolyFace f;
    f.vertices = vs;
    const Vec3& a = p.vertices[vs[0]];
    f.normal = (p.vertices[vs[1]] - a).cross(p.vertices[vs[2]] - a).normalized();
    f.offset = f.normal.dot(a);
    p.faces.push_back(f);
  }
  for (auto& f : p.faces) {
    const int n = static_cast<int>(f.vertices.size());
    for (int i = 0; i < n; ++i) {
      const int a = f.vertices[i], b = f.vertices[(i + 1) % n];
      int found = -1;
      for (std::size_t g = 0; g < p.faces.size() && found < 0; ++g) {
        const auto& vs = p.faces[g].vertices;
        for (std::size_t j = 0; j < vs.size(); ++j)
          if (vs[j] == b && vs[(j + 1) % vs.size()] == a) { found = static_cast<int>(g); break; }
      }
      f.neighbours.push_back(found);
    }
  }
  return p;
}

// Its faces fanned into triangles.
inline TriangleMesh triangulate(const ConvexPolyhedron& p) {
  TriangleMesh m;
  m.vertices = p.vertices;
  for (const auto& f : p.faces)
    for (std::size_t i = 1; i + 1 < f.vertices.size(); ++i)
      m.triangles.push_back({f.vertices[0], f.vertices[i], f.vertices[i + 1]});
  return m;
}

inline Shape convex_shape(const ConvexPolyhedron& p) {
  Shape s;
  s.kind = ShapeKind::kConvex;
  s.hull = std::make_shared<const ConvexPolyhedron>(p);
  s.mesh = std::make_shared<const TriangleMesh>(triangulate(p));
  return s;
}

// A roof-shaped prism along y (half length `half_y`): bottom z = 0 from x = -w to w, two slopes
// meeting at the ridge x = 0, z = height, a convex edge whose normals turn by 2 atan(height / w).
inline ConvexPolyhedron wedge(double w, double height, double half_y) {
  std::vector<Vec3> v{
      {-w, -half_y, 0.0}, {w, -half_y, 0.0}, {0.0, -half_y, height},
      {-w, half_y, 0.0},  {w, half_y, 0.0},  {0.0, half_y, height}};
  return polyhedron(v, {{0, 3, 4, 1},        // bottom, -z
                        {0, 1, 2},           // front, -y
                        {3, 5, 4},           // back, +y
                        {1, 4, 5, 2},        // right slope
                        {0, 2, 5, 3}});      // left slope
}

// icosphere(R, levels): test_shape_meshes.hpp (one definition: two inline functions of the same
// name in one namespace break the one-definition rule, and the linker keeps either).

}  // namespace graspsim::test
