// Shapes: the box as a convex polyhedron, the analytic solids, mesh checks, faces of convex
// meshes, mass properties and principal frames.
#include "graspsim/engine/shape.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <utility>

#include <Eigen/Eigenvalues>

#include "graspsim/engine/model.hpp"

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

// ---------------------------------------------------------------------------------------------
// The analytic solids.

namespace {

Shape round_shape(ShapeKind kind, double radius, double half_length) {
  Shape s;
  s.kind = kind;
  s.radius = radius;
  s.half_length = half_length;
  const double z = kind == ShapeKind::kSphere ? radius
                 : kind == ShapeKind::kCapsule ? half_length + radius : half_length;
  s.half_extents = Vec3(radius, radius, z);
  return s;
}

std::string str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string point_str(const Vec3& v) { return "(" + str(v.x()) + ", " + str(v.y()) + ", " + str(v.z()) + ")"; }

// "3 -> 7 at (0, 0, 0) -> (1, 0, 0)": indices count from 0; the positions find it in a file.
std::string edge_str(const TriangleMesh& m, int a, int b) {
  return std::to_string(a) + " -> " + std::to_string(b) + " at " + point_str(m.vertices[a]) + " -> " +
         point_str(m.vertices[b]);
}

// The length of the diagonal of the mesh's bounding box (m), the scale of its tolerances.
double mesh_size(const TriangleMesh& m) {
  if (m.vertices.empty()) return 0.0;
  Vec3 lo = m.vertices.front(), hi = lo;
  for (const Vec3& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  return (hi - lo).norm();
}

Vec3 vertex_mean(const TriangleMesh& m) {
  Vec3 sum = Vec3::Zero();
  for (const Vec3& v : m.vertices) sum += v;
  return m.vertices.empty() ? sum : Vec3(sum / static_cast<double>(m.vertices.size()));
}

// Directed edge a -> b of every triangle, to the triangle that runs it. Requires a checked mesh.
std::map<std::pair<int, int>, int> directed_edges(const TriangleMesh& m) {
  std::map<std::pair<int, int>, int> edges;
  for (int t = 0; t < static_cast<int>(m.triangles.size()); ++t) {
    const auto& tri = m.triangles[t];
    for (int i = 0; i < 3; ++i) edges.emplace(std::make_pair(tri[i], tri[(i + 1) % 3]), t);
  }
  return edges;
}

// Volume integrals of 1, x, y, z, x^2, y^2, z^2, xy, yz, zx over the solid, with the vertices
// taken relative to `origin` (Eberly, "Polyhedral Mass Properties (Revisited)", 2002: the
// divergence theorem turns each into a sum over the triangles of polynomials in their vertices;
// exact for a closed, outward-oriented mesh).
std::array<double, 10> volume_integrals(const TriangleMesh& m, const Vec3& origin) {
  const auto sub = [](double w0, double w1, double w2, double& f1, double& f2, double& f3,
                      double& g0, double& g1, double& g2) {
    const double t0 = w0 + w1;
    f1 = t0 + w2;
    const double t1 = w0 * w0;
    const double t2 = t1 + w1 * t0;
    f2 = t2 + w2 * f1;
    f3 = w0 * t1 + w1 * t2 + w2 * f2;
    g0 = f2 + w0 * (f1 + w0);
    g1 = f2 + w1 * (f1 + w1);
    g2 = f2 + w2 * (f1 + w2);
  };
  std::array<double, 10> in{};
  for (const auto& tri : m.triangles) {
    const Vec3 p0 = m.vertices[tri[0]] - origin, p1 = m.vertices[tri[1]] - origin,
               p2 = m.vertices[tri[2]] - origin;
    const Vec3 d = (p1 - p0).cross(p2 - p0);
    double f1x, f2x, f3x, g0x, g1x, g2x, f1y, f2y, f3y, g0y, g1y, g2y, f1z, f2z, f3z, g0z, g1z, g2z;
    sub(p0.x(), p1.x(), p2.x(), f1x, f2x, f3x, g0x, g1x, g2x);
    sub(p0.y(), p1.y(), p2.y(), f1y, f2y, f3y, g0y, g1y, g2y);
    sub(p0.z(), p1.z(), p2.z(), f1z, f2z, f3z, g0z, g1z, g2z);
    in[0] += d.x() * f1x;
    in[1] += d.x() * f2x;
    in[2] += d.y() * f2y;
    in[3] += d.z() * f2z;
    in[4] += d.x() * f3x;
    in[5] += d.y() * f3y;
    in[6] += d.z() * f3z;
    in[7] += d.x() * (p0.y() * g0x + p1.y() * g1x + p2.y() * g2x);
    in[8] += d.y() * (p0.z() * g0y + p1.z() * g1y + p2.z() * g2y);
    in[9] += d.z() * (p0.x() * g0z + p1.x() * g1z + p2.x() * g2z);
  }
  const double mult[10] = {1.0 / 6, 1.0 / 24, 1.0 / 24, 1.0 / 24, 1.0 / 60,
                           1.0 / 60, 1.0 / 60, 1.0 / 120, 1.0 / 120, 1.0 / 120};
  for (int i = 0; i < 10; ++i) in[i] *= mult[i];
  return in;
}

Vec3 largest_abs(const TriangleMesh& m) {
  Vec3 h = Vec3::Zero();
  for (const Vec3& v : m.vertices) h = h.cwiseMax(v.cwiseAbs());
  return h;
}

}  // namespace

Shape sphere_shape(double radius) { return round_shape(ShapeKind::kSphere, radius, 0.0); }
Shape cylinder_shape(double radius, double half_length) {
  return round_shape(ShapeKind::kCylinder, radius, half_length);
}
Shape capsule_shape(double radius, double half_length) {
  return round_shape(ShapeKind::kCapsule, radius, half_length);
}

// ---------------------------------------------------------------------------------------------
// Meshes.

void check_closed_mesh(const TriangleMesh& m) {
  const int nv = static_cast<int>(m.vertices.size());
  const int nt = static_cast<int>(m.triangles.size());
  if (nt < 4) {
    throw MeshError("a closed mesh needs at least 4 triangles (got " + std::to_string(nt) + ")", -1);
  }
  for (int t = 0; t < nt; ++t) {
    const auto& tri = m.triangles[t];
    for (int i = 0; i < 3; ++i) {
      if (tri[i] < 0 || tri[i] >= nv) {
        throw MeshError("triangle " + std::to_string(t) + ": vertex index " + std::to_string(tri[i]) +
                        " is out of range (the mesh has " + std::to_string(nv) + " vertices)", t);
      }
      if (!m.vertices[tri[i]].allFinite()) {
        throw MeshError("triangle " + std::to_string(t) + ": vertex " + std::to_string(tri[i]) +
                        " is not finite", t);
      }
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) {
      throw MeshError("triangle " + std::to_string(t) + " uses one vertex twice (" +
                      std::to_string(tri[0]) + ", " + std::to_string(tri[1]) + ", " +
                      std::to_string(tri[2]) + ")", t);
    }
  }
  std::map<std::pair<int, int>, int> edges;
  for (int t = 0; t < nt; ++t) {
    const auto& tri = m.triangles[t];
    for (int i = 0; i < 3; ++i) {
      const int a = tri[i], b = tri[(i + 1) % 3];
      const auto [it, fresh] = edges.emplace(std::make_pair(a, b), t);
      if (!fresh) {
        throw MeshError("triangle " + std::to_string(t) + ": edge " + edge_str(m, a, b) +
                        " runs the same way as in triangle " + std::to_string(it->second) +
                        ": the triangles are not consistently oriented (or more than two share "
                        "the edge)", t);
      }
    }
  }
  for (const auto& [edge, t] : edges) {
    if (edges.find({edge.second, edge.first}) == edges.end()) {
      throw MeshError("triangle " + std::to_string(t) + ": edge " + edge_str(m, edge.first, edge.second) +
                      " has no neighbouring triangle: the mesh is not closed", t);
    }
  }
  const double size = mesh_size(m);
  const double volume = volume_integrals(m, vertex_mean(m))[0];
  if (!(volume > 1e-12 * size * size * size)) {
    throw MeshError(volume < 0.0 ? "the mesh is inside out (volume " + str(volume) + " m^3): its "
                                   "triangles must be counter-clockwise seen from outside"
                                 : "the mesh encloses no volume", -1);
  }
}

TriangleMesh without_unused_vertices(const TriangleMesh& m) {
  std::vector<int> index(m.vertices.size(), -1);
  for (const auto& tri : m.triangles) {
    for (int v : tri) {
      if (v >= 0 && v < static_cast<int>(index.size())) index[v] = 0;
    }
  }
  TriangleMesh out;
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    if (index[i] < 0) continue;
    index[i] = static_cast<int>(out.vertices.size());
    out.vertices.push_back(m.vertices[i]);
  }
  out.triangles = m.triangles;
  for (auto& tri : out.triangles) {
    for (int& v : tri) {
      if (v >= 0 && v < static_cast<int>(index.size())) v = index[v];
    }
  }
  return out;
}

ConvexPolyhedron convex_polyhedron(const TriangleMesh& mesh) {
  check_closed_mesh(mesh);
  const TriangleMesh& m = mesh;
  const int nt = static_cast<int>(m.triangles.size());
  const double tol = 1e-6 * mesh_size(m);
  std::vector<char> used(m.vertices.size(), 0);
  for (const auto& tri : m.triangles) used[tri[0]] = used[tri[1]] = used[tri[2]] = 1;

  // Triangle planes, and convexity: no used vertex outside any triangle's plane.
  std::vector<Vec3> area(nt), normal(nt);
  for (int t = 0; t < nt; ++t) {
    const auto& tri = m.triangles[t];
    area[t] = (m.vertices[tri[1]] - m.vertices[tri[0]]).cross(m.vertices[tri[2]] - m.vertices[tri[0]]);
    const double twice = area[t].norm();
    if (!(twice > 1e-12 * tol * tol)) {
      throw MeshError("triangle " + std::to_string(t) + " has no area (its vertices are on one line)", t);
    }
    normal[t] = area[t] / twice;
    const double offset = normal[t].dot(m.vertices[tri[0]]);
    for (std::size_t v = 0; v < m.vertices.size(); ++v) {
      const double out = used[v] ? normal[t].dot(m.vertices[v]) - offset : 0.0;
      if (out > tol) {
        throw MeshError("the mesh is not convex: vertex " + std::to_string(v) + " " + point_str(m.vertices[v]) + " lies " + str(out) +
                        " m outside the plane of triangle " + std::to_string(t), t);
      }
    }
  }

  // Faces: triangles reached across edges that lie in the plane of the face's first triangle.
  const auto edges = directed_edges(m);
  const auto across = [&](int a, int b) { return edges.at({b, a}); };   // triangle beyond a -> b
  std::vector<int> face_of(nt, -1);
  int faces = 0;
  for (int seed = 0; seed < nt; ++seed) {
    if (face_of[seed] >= 0) continue;
    const int f = faces++;
    face_of[seed] = f;
    const Vec3 n = normal[seed];
    const double d = n.dot(m.vertices[m.triangles[seed][0]]);
    std::vector<int> queue{seed};
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const auto& tri = m.triangles[queue[q]];
      for (int i = 0; i < 3; ++i) {
        const int w = across(tri[i], tri[(i + 1) % 3]);
        if (face_of[w] >= 0 || !(n.dot(normal[w]) > 0.0)) continue;
        bool planar = true;
        for (int v : m.triangles[w]) planar = planar && std::abs(n.dot(m.vertices[v]) - d) <= tol;
        if (!planar) continue;
        face_of[w] = f;
        queue.push_back(w);
      }
    }
  }

  // Each face's boundary: the edges of its triangles whose neighbour lies in another face,
  // chained a -> b (they run counter-clockwise seen from outside, as the triangles do).
  ConvexPolyhedron p;
  std::vector<std::vector<int>> polygon(faces);
  std::vector<Vec3> face_area(faces, Vec3::Zero());
  std::vector<std::map<int, int>> next(faces);
  for (int t = 0; t < nt; ++t) {
    const int f = face_of[t];
    face_area[f] += area[t];
    const auto& tri = m.triangles[t];
    for (int i = 0; i < 3; ++i) {
      const int a = tri[i], b = tri[(i + 1) % 3];
      if (face_of[across(a, b)] == f) continue;
      if (!next[f].emplace(a, b).second) {
        throw MeshError("the face of triangle " + std::to_string(t) + " is not a simple polygon "
                        "(its boundary passes vertex " + std::to_string(a) + " twice)", t);
      }
    }
  }
  for (int f = 0; f < faces; ++f) {
    const int start = next[f].begin()->first;
    int v = start;
    do {
      polygon[f].push_back(v);
      v = next[f].at(v);
    } while (v != start && polygon[f].size() <= next[f].size());
    if (v != start || polygon[f].size() != next[f].size()) {
      int t = 0;
      while (face_of[t] != f) ++t;
      throw MeshError("the face of triangle " + std::to_string(t) + " is not a simple polygon "
                      "(its boundary is not one loop)", t);
    }
  }

  // Vertices on some face boundary, renumbered in mesh order.
  std::vector<int> index(m.vertices.size(), -1);
  for (const auto& poly : polygon) {
    for (int v : poly) index[v] = 0;
  }
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    if (index[v] < 0) continue;
    index[v] = static_cast<int>(p.vertices.size());
    p.vertices.push_back(m.vertices[v]);
  }
  for (int f = 0; f < faces; ++f) {
    PolyFace face;
    face.normal = face_area[f].normalized();
    face.offset = -std::numeric_limits<double>::infinity();
    const int n = static_cast<int>(polygon[f].size());
    for (int i = 0; i < n; ++i) {
      const int a = polygon[f][i], b = polygon[f][(i + 1) % n];
      face.offset = std::max(face.offset, face.normal.dot(m.vertices[a]));
      face.vertices.push_back(index[a]);
      face.neighbours.push_back(face_of[across(a, b)]);
    }
    p.faces.push_back(std::move(face));
  }
  return p;
}

Shape convex_shape(TriangleMesh mesh) {
  mesh = without_unused_vertices(mesh);
  Shape s;
  s.kind = ShapeKind::kConvex;
  s.hull = std::make_shared<const ConvexPolyhedron>(convex_polyhedron(mesh));
  s.half_extents = largest_abs(mesh);
  s.mesh = std::make_shared<const TriangleMesh>(std::move(mesh));
  return s;
}

Shape mesh_shape(TriangleMesh mesh) {
  mesh = without_unused_vertices(mesh);
  check_closed_mesh(mesh);
  Shape s;
  s.kind = ShapeKind::kMesh;
  s.half_extents = largest_abs(mesh);
  s.mesh = std::make_shared<const TriangleMesh>(std::move(mesh));
  return s;
}

// ---------------------------------------------------------------------------------------------
// Mass properties.

MassProperties mass_properties(const TriangleMesh& m, double density) {
  // Two passes, to keep the round-off of the parallel-axis shift small: the volume and first
  // moments about the vertices' mean, then the second moments about the centre so found.
  const Vec3 mean = vertex_mean(m);
  const auto first = volume_integrals(m, mean);
  const double volume = first[0];
  MassProperties out;
  out.mass = density * volume;
  out.centre = mean + Vec3(first[1], first[2], first[3]) / volume;
  const auto in = volume_integrals(m, out.centre);
  const Vec3 c = Vec3(in[1], in[2], in[3]) / volume;   // ~0: the centre's own round-off
  Mat3& j = out.inertia;
  j(0, 0) = in[5] + in[6] - volume * (c.y() * c.y() + c.z() * c.z());
  j(1, 1) = in[4] + in[6] - volume * (c.z() * c.z() + c.x() * c.x());
  j(2, 2) = in[4] + in[5] - volume * (c.x() * c.x() + c.y() * c.y());
  j(0, 1) = j(1, 0) = -(in[7] - volume * c.x() * c.y());
  j(1, 2) = j(2, 1) = -(in[8] - volume * c.y() * c.z());
  j(0, 2) = j(2, 0) = -(in[9] - volume * c.z() * c.x());
  j *= density;
  return out;
}

MassProperties mass_properties(const Shape& s, double density) {
  constexpr double kPi = 3.14159265358979323846;
  MassProperties out;
  const double r = s.radius, r2 = r * r;
  switch (s.kind) {
    case ShapeKind::kBox: {
      const Vec3& h = s.half_extents;
      out.mass = density * 8.0 * h.x() * h.y() * h.z();
      out.inertia = box_inertia(out.mass, h).asDiagonal();
      return out;
    }
    case ShapeKind::kSphere:
      out.mass = density * 4.0 / 3.0 * kPi * r2 * r;
      out.inertia = Mat3::Identity() * (0.4 * out.mass * r2);
      return out;
    case ShapeKind::kCylinder: {
      // Solid cylinder of length L = 2 half_length: J_z = m r^2 / 2, J_x = m (3 r^2 + L^2) / 12.
      const double length = 2.0 * s.half_length;
      out.mass = density * kPi * r2 * length;
      const double jx = out.mass * (3.0 * r2 + length * length) / 12.0;
      out.inertia = Vec3(jx, jx, 0.5 * out.mass * r2).asDiagonal();
      return out;
    }
    case ShapeKind::kCapsule: {
      // A cylinder of length L = 2 half_length and two hemispheres of mass m_h = rho 2/3 pi r^3.
      // A hemisphere about any axis through the centre of its flat face: 2/5 m_h r^2 (half a
      // sphere); its centre of mass lies 3r/8 from that face, so about its own centre (transverse)
      // 2/5 m_h r^2 - m_h (3r/8)^2 = 83/320 m_h r^2, and about the capsule's centre that plus
      // m_h (half_length + 3r/8)^2.
      const double length = 2.0 * s.half_length;
      const double m_c = density * kPi * r2 * length;
      const double m_h = density * 2.0 / 3.0 * kPi * r2 * r;
      const double arm = s.half_length + 3.0 * r / 8.0;
      out.mass = m_c + 2.0 * m_h;
      const double jz = 0.5 * m_c * r2 + 2.0 * 0.4 * m_h * r2;
      const double jx = m_c * (3.0 * r2 + length * length) / 12.0 +
                        2.0 * (83.0 / 320.0 * m_h * r2 + m_h * arm * arm);
      out.inertia = Vec3(jx, jx, jz).asDiagonal();
      return out;
    }
    case ShapeKind::kConvex:
    case ShapeKind::kMesh:
      if (!s.mesh) throw std::invalid_argument("mass_properties: a mesh shape without its mesh");
      return mass_properties(*s.mesh, density);
  }
  throw std::invalid_argument("mass_properties: unknown shape kind");
}

PrincipalFrame principal_frame(const MassProperties& mp) {
  const Eigen::SelfAdjointEigenSolver<Mat3> solver(mp.inertia);
  const Vec3 lambda = solver.eigenvalues();   // ascending
  const Mat3 v = solver.eigenvectors();
  const double tol = 1e-9 * lambda.cwiseAbs().maxCoeff();
  const bool low_pair = lambda[1] - lambda[0] <= tol, high_pair = lambda[2] - lambda[1] <= tol;
  PrincipalFrame out;
  out.centre = mp.centre;
  Mat3& r = out.rotation;
  if (low_pair && high_pair) {
    r.setIdentity();   // every axis is principal: keep the frame's
  } else if (low_pair || high_pair) {
    // One distinct axis a (symmetry axis), to the frame axis k it is closest to; the frame's
    // next axis projected onto the plane of the equal pair; the third completes a right hand.
    Vec3 a = v.col(low_pair ? 2 : 0);
    int k = 0;
    for (int i = 1; i < 3; ++i) {
      if (std::abs(a[i]) > std::abs(a[k])) k = i;
    }
    if (a[k] < 0.0) a = -a;
    Vec3 u = Vec3::Unit((k + 1) % 3) - a * a[(k + 1) % 3];
    u.normalize();
    r.col(k) = a;
    r.col((k + 1) % 3) = u;
    r.col((k + 2) % 3) = a.cross(u);
  } else {
    // Distinct moments: the assignment of eigenvectors to frame axes with the largest sum of
    // |cosines| (first in a fixed order on ties), each pointing along its axis.
    static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int best = 0;
    double best_sum = -1.0;
    for (int p = 0; p < 6; ++p) {
      double sum = 0.0;
      for (int j = 0; j < 3; ++j) sum += std::abs(v(perms[p][j], j));
      if (sum > best_sum) {
        best_sum = sum;
        best = p;
      }
    }
    for (int j = 0; j < 3; ++j) {
      const int axis = perms[best][j];
      r.col(axis) = v(axis, j) < 0.0 ? Vec3(-v.col(j)) : Vec3(v.col(j));
    }
    if (r.determinant() < 0.0) {   // flip the axis that is least aligned with its frame axis
      int worst = 0;
      for (int i = 1; i < 3; ++i) {
        if (std::abs(r(i, i)) < std::abs(r(worst, worst))) worst = i;
      }
      r.col(worst) = -r.col(worst);
    }
  }
  out.moments = (r.transpose() * mp.inertia * r).diagonal();
  return out;
}

TriangleMesh to_principal_frame(const TriangleMesh& mesh, PrincipalFrame& frame, double density) {
  check_closed_mesh(mesh);
  frame = principal_frame(mass_properties(mesh, density));
  TriangleMesh out = mesh;
  for (Vec3& x : out.vertices) x = frame.rotation.transpose() * (x - frame.centre);
  return out;
}

TriangleMesh icosphere_mesh(double r, int level) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleMesh m;
  m.vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (Vec3& v : m.vertices) v = v.normalized() * r;
  for (int k = 0; k < level; ++k) {
    std::map<std::pair<int, int>, int> mid;
    const auto middle = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized() * r);
      const int i = static_cast<int>(m.vertices.size()) - 1;
      mid.emplace(key, i);
      return i;
    };
    std::vector<std::array<int, 3>> finer;
    for (const auto& tri : m.triangles) {
      const int a = middle(tri[0], tri[1]), b = middle(tri[1], tri[2]), c = middle(tri[2], tri[0]);
      finer.push_back({tri[0], a, c});
      finer.push_back({tri[1], b, a});
      finer.push_back({tri[2], c, b});
      finer.push_back({a, b, c});
    }
    m.triangles = finer;
  }
  return m;
}

}  // namespace graspsim
