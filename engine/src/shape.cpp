// Shapes: the box as a convex polyhedron.
#include "graspsim/engine/shape.hpp"

namespace graspsim {

ConvexPolyhedron box_polyhedron(const Vec3& h) {
  ConvexPolyhedron p;
  for (int k = 0; k < 8; ++k) {
    p.vertices.emplace_back((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z());
  }
  // Face k: axis k / 2, sign + for even k. Its four vertices counter-clockwise seen from outside.
  const std::array<std::array<int, 4>, 6> quads{{
      {1, 3, 7, 5},   // +x
      {0, 4, 6, 2},   // -x
      {2, 6, 7, 3},   // +y
      {0, 1, 5, 4},   // -y
      {4, 5, 7, 6},   // +z
      {0, 2, 3, 1},   // -z
  }};
  for (int f = 0; f < 6; ++f) {
    PolyFace face;
    const int axis = f / 2;
    face.normal = Vec3::Zero();
    face.normal[axis] = (f % 2 == 0) ? 1.0 : -1.0;
    face.offset = h[axis];
    face.vertices.assign(quads[f].begin(), quads[f].end());
    p.faces.push_back(face);
  }
  // Neighbours: the other face sharing each edge (as the reversed edge).
  for (auto& face : p.faces) {
    const int n = static_cast<int>(face.vertices.size());
    for (int i = 0; i < n; ++i) {
      const int a = face.vertices[i], b = face.vertices[(i + 1) % n];
      int found = -1;
      for (int g = 0; g < 6 && found < 0; ++g) {
        const auto& vs = p.faces[g].vertices;
        for (int j = 0; j < 4; ++j) {
          if (vs[j] == b && vs[(j + 1) % 4] == a) { found = g; break; }
        }
      }
      face.neighbours.push_back(found);
    }
  }
  return p;
}

Shape box_shape(const Vec3& half_extents) {
  Shape s;
  s.kind = ShapeKind::kBox;
  s.half_extents = half_extents;
  s.hull = std::make_shared<const ConvexPolyhedron>(box_polyhedron(half_extents));
  return s;
}

}  // namespace graspsim
