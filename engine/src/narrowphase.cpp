// The contact points of two bodies by the kinds of their shapes (narrowphase.hpp).
#include "narrowphase.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "graspsim/engine/floor_points.hpp"

namespace graspsim::detail {

namespace {

// The point of triangle (a, b, c) closest to p (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// A cylinder as the 12-sided prism of its floor points (floor_point: rim vertex j of the lower
// cap is k = j, of the upper k = 12 + j), so that it rests on a box or a convex body on a face
// of points, as on the floor, and not on FCL's one point.
ConvexPolyhedron cylinder_prism(const Shape& s) {
  constexpr int n = kCylinderRimPoints;
  TriangleMesh mesh;
  bool rolling = false;
  for (int k = 0; k < 2 * n; ++k) mesh.vertices.push_back(floor_point(s, Mat3::Identity(), k, rolling));
  for (int i = 1; i + 1 < n; ++i) {
    mesh.triangles.push_back({n, n + i, n + i + 1});   // top, counter-clockwise seen from above
    mesh.triangles.push_back({0, i + 1, i});           // bottom, seen from below
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    mesh.triangles.push_back({i, j, n + j});
    mesh.triangles.push_back({i, n + j, n + i});
  }
  return convex_polyhedron(mesh);
}

void place(fcl::CollisionObjectd& object, const BodyState& bs) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = bs.rotation;
  tf.translation() = bs.position;
  object.setTransform(tf);
}

}  // namespace

// Rows and columns: kPolyhedron, kSphere, kMesh, kOther.
const std::array<std::array<Narrowphase::Method, Narrowphase::kKinds>, Narrowphase::kKinds> Narrowphase::kMethods = {{
    {Method::kManifold, Method::kFcl, Method::kFcl, Method::kFcl},
    {Method::kFcl, Method::kFcl, Method::kSphereMesh, Method::kFcl},
    {Method::kFcl, Method::kMeshSphere, Method::kNone, Method::kFcl},
    {Method::kFcl, Method::kFcl, Method::kFcl, Method::kFcl},
}};

Narrowphase::Narrowphase(const Model& model, std::shared_ptr<FclWorld> world) : world_(std::move(world)) {
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const Shape& shape = model.bodies[i].shape;
    Body body;
    body.object = world_->bodies[i].get();
    if (shape.kind == ShapeKind::kBox) {
      body.hull = std::make_shared<const ConvexPolyhedron>(box_polyhedron(shape.half_extents));
    } else if (shape.kind == ShapeKind::kCylinder) {
      body.hull = std::make_shared<const ConvexPolyhedron>(cylinder_prism(shape));
    } else if (shape.kind == ShapeKind::kConvex && shape.hull) {
      body.hull = shape.hull;
    }
    if (body.hull) {
      body.kind = Kind::kPolyhedron;
      body.edges = hull_edges(*body.hull);
    } else if (shape.kind == ShapeKind::kSphere) {
      body.kind = Kind::kSphere;
      body.sphere_radius = shape.radius;
    } else if (shape.kind == ShapeKind::kMesh) {
      body.kind = Kind::kMesh;
      body.mesh = shape.mesh;
      for (const auto& t : shape.mesh->triangles) {
        const Vec3& p0 = shape.mesh->vertices[static_cast<std::size_t>(t[0])];
        const Vec3 nrm = (shape.mesh->vertices[static_cast<std::size_t>(t[1])] - p0)
                             .cross(shape.mesh->vertices[static_cast<std::size_t>(t[2])] - p0);
        body.triangle_normals.push_back(nrm.normalized());
      }
    }
    bodies_.push_back(std::move(body));
  }
  for (const Body& body : bodies_) {
    if (body.hull) scratch_.reserve_for(body.edges, body.edges);
  }
  request_.num_max_contacts = kMaxPairPoints;
  request_.enable_contact = true;
  distance_request_.enable_nearest_points = true;
}

bool Narrowphase::can_touch(int a, int b) const {
  return kMethods[static_cast<int>(bodies_[a].kind)][static_cast<int>(bodies_[b].kind)] != Method::kNone;
}

int Narrowphase::find(const State& state, int a, int b, double margin, bool placed, ManifoldPoint* out) {
  const BodyState& sa = state.bodies[a];
  const BodyState& sb = state.bodies[b];
  switch (kMethods[static_cast<int>(bodies_[a].kind)][static_cast<int>(bodies_[b].kind)]) {
    case Method::kNone: return 0;
    case Method::kManifold:
      return manifold(bodies_[a].edges, sa.position, sa.rotation, bodies_[b].edges, sb.position, sb.rotation, scratch_,
                      out, kMaxPairPoints, margin);
    case Method::kSphereMesh: return sphere_mesh(sb, b, sa.position, bodies_[a].sphere_radius, true, margin, out);
    case Method::kMeshSphere: return sphere_mesh(sa, a, sb.position, bodies_[b].sphere_radius, false, margin, out);
    case Method::kFcl:
      if (!placed) {
        place(*bodies_[a].object, sa);
        place(*bodies_[b].object, sb);
      }
      return fcl_points(state, a, b, margin, out);
  }
  return 0;
}

// FCL's contacts of a and b, or, short of touching and within the margin, the nearest points of
// the two (one point, depth minus their distance).
int Narrowphase::fcl_points(const State& state, int a, int b, double margin, ManifoldPoint* out) {
  const BodyState& sa = state.bodies[a];
  const BodyState& sb = state.bodies[b];
  const bool mesh_a = bodies_[a].mesh != nullptr, mesh_b = bodies_[b].mesh != nullptr;
  result_.clear();
  fcl::collide(bodies_[a].object, bodies_[b].object, request_, result_);
  const int n = std::min(static_cast<int>(result_.numContacts()), kMaxPairPoints);
  if (n == 0) {
    if (!(margin > 0.0)) return 0;
    distance_result_.clear();
    const double d = fcl::distance(bodies_[a].object, bodies_[b].object, distance_request_, distance_result_);
    if (!(d > 0.0) || d >= margin) return 0;
    const Vec3 pa = distance_result_.nearest_points[0], pb = distance_result_.nearest_points[1];
    const bool swapped = distance_result_.o1 != bodies_[a].object->collisionGeometry().get();
    const Vec3 from_a = swapped ? Vec3(pa - pb) : Vec3(pb - pa);
    if (!(from_a.norm() > 0.0)) return 0;
    out[0].point = 0.5 * (pa + pb);
    out[0].normal = from_a.normalized();
    out[0].depth = -d;
    out[0].key = combine_key(combine_key(7, static_cast<std::uint64_t>(std::max<std::intptr_t>(distance_result_.b1, 0))),
                             static_cast<std::uint64_t>(std::max<std::intptr_t>(distance_result_.b2, 0)));
    return 1;
  }
  const fcl::CollisionGeometryd* geometry_a = bodies_[a].object->collisionGeometry().get();
  for (int i = 0; i < n; ++i) {
    const fcl::Contactd& c = result_.getContact(static_cast<std::size_t>(i));
    out[i].point = c.pos;
    // FCL's sign conventions differ by pair kind and argument order (FCL 0.7: a mesh's contacts
    // point from the mesh outwards whichever comes first, a box's against a mesh inwards, and
    // the depth of sphere-triangle contacts is negative), so the sense is set here: against a
    // mesh, along the touched triangle's outward normal (meshes are closed and oriented); between
    // two convex shapes, along the line between their centres of mass, which lie on either side
    // of the contact plane unless one is thinner than the overlap.
    Vec3 nrm = c.normal.normalized();
    double side = 0.0;   // > 0 when nrm points from a towards b (1 when along the triangle's)
    if (mesh_a || mesh_b) {
      const int m = mesh_a ? a : b;
      const BodyState& sm = state.bodies[m];
      const std::intptr_t tri = (c.o1 == bodies_[m].object->collisionGeometry().get()) ? c.b1 : c.b2;
      const Vec3 outward = sm.rotation * bodies_[m].triangle_normals[static_cast<std::size_t>(tri)];
      side = mesh_a ? nrm.dot(outward) : -nrm.dot(outward);
    }
    if (std::abs(side) < 0.5) {   // not mesh, or a triangle that FCL's normal crosses edge on
      side = nrm.dot(sb.position - sa.position);
    }
    if (side < 0.0) nrm = -nrm;
    out[i].normal = nrm;
    out[i].depth = std::abs(c.penetration_depth);
    const bool swapped = c.o1 != geometry_a;   // FCL may report the pair as (b, a)
    const std::uint64_t fa = static_cast<std::uint64_t>(swapped ? c.b2 : c.b1);
    const std::uint64_t fb = static_cast<std::uint64_t>(swapped ? c.b1 : c.b2);
    out[i].key = combine_key(combine_key(4, fa), fb);
  }
  return finish(n, margin, out);
}

// FCL's contacts in `out[0, n)` in a fixed order: FCL's order is its traversal's, so sort by
// key, then position, then rank equal keys. Returns the count kept (depth > -margin, at the front).
int Narrowphase::finish(int n, double margin, ManifoldPoint* out) {
  std::sort(out, out + n, [](const ManifoldPoint& p, const ManifoldPoint& q) {
    if (p.key != q.key) return p.key < q.key;
    for (int d = 0; d < 3; ++d) {
      if (p.point[d] != q.point[d]) return p.point[d] < q.point[d];
    }
    return p.depth < q.depth;
  });
  std::uint64_t rank = 0;
  for (int i = 0; i < n; ++i) {
    rank = (i > 0 && out[i].key == out[i - 1].key) ? rank + 1 : 0;
    out[i].key = combine_key(out[i].key, rank);
  }
  int kept = 0;
  for (int i = 0; i < n; ++i) {
    if (out[i].depth > -margin) out[kept++] = out[i];
  }
  return kept;
}

// Sphere (centre c, radius r, world) against mesh body m: for each triangle, its closest point
// q to the centre (Ericson, Real-Time Collision Detection 5.1.5); a point where |c - q| < r +
// margin, normal (c - q) / |c - q| out of the mesh, depth r - |c - q|. A centre on or behind a
// triangle's plane (sunk deeper than r) counts only over the triangle itself: normal the
// triangle's, depth r + its distance behind. Triangles that share the closest point (an edge or
// vertex, or a flat face cut into triangles) give it once, the first triangle's key.
int Narrowphase::sphere_mesh(const BodyState& sm, int m, const Vec3& centre_world, double r, bool mesh_is_b,
                             double margin, ManifoldPoint* out) {
  const Body& body = bodies_[m];
  const Mat3& rot = sm.rotation;
  const Vec3& pos = sm.position;
  const Vec3 c = rot.transpose() * (centre_world - pos);   // m, mesh frame
  const TriangleMesh& mesh = *body.mesh;
  const double reach = r + margin;   // m
  int n = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3& p0 = mesh.vertices[static_cast<std::size_t>(tri[0])];
    const Vec3& tn = body.triangle_normals[t];
    const double plane = tn.dot(c - p0);   // m: signed distance of the centre from the plane
    if (plane >= reach || plane <= -r) continue;
    const Vec3 q = closest_on_triangle(c, p0, mesh.vertices[static_cast<std::size_t>(tri[1])],
                                       mesh.vertices[static_cast<std::size_t>(tri[2])]);
    const Vec3 d = c - q;
    const double dist = d.norm();
    if (dist >= reach) continue;
    Vec3 nrm;
    double depth;
    if (plane > 0.0 && dist > 1e-12 * r) {
      nrm = d / dist;
      depth = r - dist;
    } else if ((d - plane * tn).squaredNorm() <= 1e-18 * r * r) {   // centre over the face, behind it
      nrm = tn;
      depth = r - plane;
    } else {   // behind the plane and beside the triangle: the neighbouring face's contact
      continue;
    }
    bool seen = false;
    for (int i = 0; i < n; ++i) {
      if ((scratch_q_[i] - q).squaredNorm() <= 1e-24) {
        seen = true;
        break;
      }
    }
    if (seen) continue;
    int slot = n;
    if (n < kMaxPairPoints) {
      ++n;
    } else {   // full: replace the shallowest if this one is deeper
      slot = 0;
      for (int i = 1; i < n; ++i) {
        if (out[i].depth < out[slot].depth) slot = i;
      }
      if (depth <= out[slot].depth) continue;
    }
    scratch_q_[slot] = q;
    out[slot].point = pos + rot * (0.5 * (q + c - r * nrm));   // midway between the surfaces
    out[slot].normal = mesh_is_b ? Vec3(-(rot * nrm)) : Vec3(rot * nrm);
    out[slot].depth = depth;
    out[slot].key = combine_key(5, static_cast<std::uint64_t>(t));
  }
  return n;
}

}  // namespace graspsim::detail
