// Penalty object contact: the floor, point by point (paper, section 4), and body against body.
#include "graspsim/engine/object_contact.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <utility>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>

#include "fcl_shape.hpp"
#include "fcl_world.hpp"
#include "graspsim/engine/finger_contact.hpp"

namespace graspsim {

Vec3 box_vertex(const Vec3& h, int k) {
  return Vec3((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z());
}

int floor_point_count(const Shape& s) {
  switch (s.kind) {
    case ShapeKind::kBox: return 8;
    case ShapeKind::kSphere: return 1;
    case ShapeKind::kCapsule: return 2;
    case ShapeKind::kCylinder: return 2 * kCylinderRimPoints;
    case ShapeKind::kConvex:
      return s.hull ? static_cast<int>(s.hull->vertices.size()) : (s.mesh ? static_cast<int>(s.mesh->vertices.size()) : 0);
    case ShapeKind::kMesh: return s.mesh ? static_cast<int>(s.mesh->vertices.size()) : 0;
  }
  return 0;
}

Vec3 floor_point(const Shape& s, const Mat3& rotation, int k, bool& rolling) {
  rolling = false;
  switch (s.kind) {
    case ShapeKind::kBox: return rotation * box_vertex(s.half_extents, k);
    case ShapeKind::kSphere:
      rolling = true;
      return Vec3(0.0, 0.0, -s.radius);
    case ShapeKind::kCapsule:
      rolling = true;
      return rotation * Vec3(0.0, 0.0, k == 0 ? -s.half_length : s.half_length) + Vec3(0.0, 0.0, -s.radius);
    case ShapeKind::kCylinder: {
      const int j = k % kCylinderRimPoints;
      const double angle = 2.0 * M_PI * j / kCylinderRimPoints;
      const double z = k < kCylinderRimPoints ? -s.half_length : s.half_length;
      return rotation * Vec3(s.radius * std::cos(angle), s.radius * std::sin(angle), z);
    }
    case ShapeKind::kConvex:
      return rotation * (s.hull ? s.hull->vertices[k] : s.mesh->vertices[k]);
    case ShapeKind::kMesh: return rotation * s.mesh->vertices[k];
  }
  return Vec3::Zero();
}

double floor_reach(const Shape& shape) {
  if (shape.kind == ShapeKind::kCapsule) return shape.half_length + shape.radius;
  double reach = 0.0;
  for (int k = 0; k < floor_point_count(shape); ++k) {
    bool rolling = false;
    reach = std::max(reach, floor_point(shape, Mat3::Identity(), k, rolling).norm());
  }
  return reach;
}

namespace {

// One floor point of a body at this step, as the penalty law sees it (paper, section 4).
struct FloorPoint {
  Vec3 r;          // m, world: from the centre of mass
  Vec3 x;          // m, world: the point
  Vec3 x_t;        // m, world: its material point projected on the floor
  Vec3 u_t;        // m/s, world: its material's velocity along the floor
  double u_n;      // m/s: its velocity along the floor's normal (> 0 leaving)
  double depth;    // m: under the floor (< 0 above)
  double f_n;      // N: k depth - c u_n, not clamped
  double viscous;  // N: c_v |u_t|, the viscous friction while slipping
  bool rolling;    // the lowest point of a round surface, not a material point
};

// Floor point k of body `bp` in state `bs`, and its friction anchor updated: false (the point
// made inactive) when it is above the floor by its approach over a step h or more, h max(0, -u_n)
// + `reach` (0 for the paper's step: in contact only while under the floor). The anchor is kept
// while the point stays active, started at the point when it becomes so, and moved onto the
// friction circle by stick_slip_step with the normal force k depth - c u_n (0 if it pulls).
bool track_floor_point(const BodyParams& bp, BodyState& bs, const ContactPair& pair, double floor_z, int k,
                       double h, double reach, FloorPoint& p) {
  VertexContact& vc = bs.floor_contacts[k];
  p.r = floor_point(bp.shape, bs.rotation, k, p.rolling);
  p.x = bs.position + p.r;
  p.depth = floor_z - p.x.z();
  const Vec3 u = bs.velocity + bs.angular_velocity.cross(p.r);   // m/s: velocity of the material there
  if (p.depth <= -(h * std::max(0.0, -u.z()) + reach)) {
    vc.active = false;
    return false;
  }
  p.u_n = u.z();
  p.f_n = pair.stiffness * p.depth - pair.damping * p.u_n;
  // A vertex is its own material point; a rolling point's is the one under it last step.
  const Vec3 x_m = (p.rolling && vc.active) ? Vec3(bs.position + bs.rotation * vc.material) : p.x;
  p.x_t = Vec3(x_m.x(), x_m.y(), floor_z);
  if (!vc.active) {
    vc.active = true;
    vc.slipping = false;
    vc.anchor = p.x_t;
  }
  // Static coefficient while stuck, kinetic (plus viscous c |u_t|) while slipping, with the
  // fingers' rule for sticking again (stick_slip_step), on the point's velocity over the floor.
  p.u_t = Vec3(u.x(), u.y(), 0.0);
  p.viscous = pair.viscous * p.u_t.norm();
  const double pushing = std::max(0.0, p.f_n);   // N
  vc.slipping = stick_slip_step(p.x_t, pair.mu * pushing / pair.stiffness,
                                (pair.friction(true) * pushing + p.viscous) / pair.stiffness, p.u_t, vc.slipping,
                                vc.anchor);
  return true;
}

// After the point's force: a rolling point's stretch carried over to the new lowest point and
// its material.
void roll_on(BodyState& bs, const FloorPoint& p, double floor_z, VertexContact& vc) {
  if (!p.rolling) return;
  vc.anchor = Vec3(p.x.x(), p.x.y(), floor_z) + (vc.anchor - p.x_t);
  vc.material = bs.rotation.transpose() * p.r;
}

// A body's floor vertices screened by height alone (box, hull, mesh; other shapes are never
// screened): a vertex higher above the floor than `reach`, its height from one row of R, is one
// the full test (track_floor_point) would find out of reach, and inactive. Meshes and hulls have
// thousands of vertices, most far above the floor; a box has four upper corners. 1e-12 m per
// metre of the numbers involved is added to `reach`, more than the few ulps by which that height
// can differ from the full product's.
class VertexScreen {
 public:
  VertexScreen(const Shape& shape, const BodyState& bs, double floor_z, double reach, double radius)
      : row_z_(bs.rotation.row(2).transpose()), centre_z_(bs.position.z()), floor_z_(floor_z),
        reach_(reach + 1e-12 * (1.0 + std::abs(bs.position.z()) + std::abs(floor_z) + radius)),
        half_(shape.half_extents), box_(shape.kind == ShapeKind::kBox) {
    if (shape.kind == ShapeKind::kMesh && shape.mesh) vertices_ = &shape.mesh->vertices;
    if (shape.kind == ShapeKind::kConvex)
      vertices_ = shape.hull ? &shape.hull->vertices : (shape.mesh ? &shape.mesh->vertices : nullptr);
  }
  bool out_of_reach(int k) const {
    if (!vertices_ && !box_) return false;
    const Vec3 local = vertices_ ? (*vertices_)[k] : box_vertex(half_, k);
    return centre_z_ + row_z_.dot(local) - floor_z_ > reach_;
  }

 private:
  Vec3 row_z_;
  double centre_z_, floor_z_, reach_;   // m
  Vec3 half_;                           // m: a box's half sizes
  bool box_;
  const std::vector<Vec3>* vertices_ = nullptr;
};

}  // namespace

int floor_contact(const Model& model, int body, BodyState& bs, Wrench& out, std::vector<ContactRecord>* points) {
  out = Wrench{};
  const BodyParams& bp = model.bodies[body];
  const ContactPair pair = floor_pair(model, body);
  const double floor_z = model.floor.height;
  int touching = 0;
  const int count = static_cast<int>(bs.floor_contacts.size());
  // A point is in contact only while under the floor (reach 0).
  const VertexScreen screen(bp.shape, bs, floor_z, 0.0, 0.0);
  for (int k = 0; k < count; ++k) {
    VertexContact& vc = bs.floor_contacts[k];
    if (screen.out_of_reach(k)) {
      vc.active = false;
      continue;
    }
    FloorPoint p;
    if (!track_floor_point(bp, bs, pair, floor_z, k, 0.0, 0.0, p)) continue;
    ++touching;
    const double f_n = std::max(0.0, p.f_n);
    Vec3 f_t = pair.stiffness * (vc.anchor - p.x_t) - pair.damping * p.u_t;
    clamp_to_cone(pair.friction(vc.slipping) * f_n + (vc.slipping ? p.viscous : 0.0), f_t);
    const Vec3 f(f_t.x(), f_t.y(), f_n);
    out.force += f;
    out.torque += p.r.cross(f);
    if (points != nullptr) points->push_back(ContactRecord{kFloor, body, p.x, Vec3::UnitZ(), f});
    roll_on(bs, p, floor_z, vc);
  }
  return touching;
}

int floor_couplings(const Model& model, int body, const ContactPair& pair, BodyState& bs, double h, double radius,
                    std::vector<Coupling>& out) {
  const BodyParams& bp = model.bodies[body];
  const double floor_z = model.floor.height;
  const double reach = h * h * model.gravity.norm();   // m: how far gravity alone carries a point in a step
  int appended = 0;
  const int count = static_cast<int>(bs.floor_contacts.size());
  // A point counts while the step can close its height: no point of the body closes more than
  // h (max(0, -v_z) + |w| radius) + reach, the bound the full test takes from its own velocity.
  const VertexScreen screen(bp.shape, bs, floor_z,
                            h * (std::max(0.0, -bs.velocity.z()) + bs.angular_velocity.norm() * radius) + reach,
                            radius);
  for (int k = 0; k < count; ++k) {
    if (screen.out_of_reach(k)) {
      bs.floor_contacts[k].active = false;
      continue;
    }
    FloorPoint p;
    if (!track_floor_point(bp, bs, pair, floor_z, k, h, reach, p)) continue;
    VertexContact& vc = bs.floor_contacts[k];
    Coupling c;
    c.source = Coupling::Source::kFloor;
    c.slot = k;
    c.a = -1;
    c.b = body;
    c.point = p.x;
    c.normal = Vec3::UnitZ();
    c.force = pair.stiffness * (vc.anchor - p.x_t) - pair.damping * p.u_t + Vec3(0.0, 0.0, p.f_n);
    c.k_n = c.k_t = pair.stiffness;
    c.c_n = c.c_t = pair.damping;
    c.mu = pair.friction(vc.slipping);
    c.viscous = vc.slipping ? p.viscous : 0.0;
    out.push_back(c);
    ++appended;
    roll_on(bs, p, floor_z, vc);
  }
  return appended;
}

// ---- body against body ----

namespace {

std::uint64_t combine(std::uint64_t h, std::uint64_t v) {
  return h ^ (v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
}

// Wakes both bodies of pair index pi among n bodies (pair_index's inverse, by walking rows).
void wake_pair(State& state, int pi, int n) {
  int a = 0;
  while (pi >= n - a - 1) {
    pi -= n - a - 1;
    ++a;
  }
  wake(state.bodies[a]);
  wake(state.bodies[a + 1 + pi]);
}

bool polyhedral(const Shape& s) { return s.kind == ShapeKind::kBox || (s.kind == ShapeKind::kConvex && s.hull); }

// A pair of bodies that can touch: both rigid means no finite penalty law, no stiffness no force.
bool collides(const ContactPair& p) {
  return std::isfinite(p.stiffness) && std::isfinite(p.damping) && p.stiffness > 0.0;
}

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

bool add_pair(fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
  auto* out = static_cast<std::vector<std::pair<int, int>>*>(data);
  const int i = static_cast<int>(reinterpret_cast<std::intptr_t>(a->getUserData())) - 1;
  const int j = static_cast<int>(reinterpret_cast<std::intptr_t>(b->getUserData())) - 1;
  if (out->size() < out->capacity()) out->emplace_back(std::min(i, j), std::max(i, j));
  return false;   // keep going
}

}  // namespace

struct BodyContacts::Impl {
  struct Body {
    fcl::CollisionObjectd* object = nullptr;         // the world's (user data: body index + 1)
    std::shared_ptr<const ConvexPolyhedron> hull;    // polyhedral shapes
    HullEdges edges;
    std::shared_ptr<const TriangleMesh> mesh;        // kMesh
    std::vector<Vec3> triangle_normals;              // 1, body frame, outward: kMesh
    double sphere_radius = 0.0;                      // m: kSphere, else 0
  };
  std::shared_ptr<detail::FclWorld> world;           // the bodies' FCL objects, shared with CollisionWorld
  std::vector<Body> bodies;
  std::vector<std::pair<int, int>> candidates;       // capacity n (n - 1) / 2
  std::vector<std::uint8_t> touched;                 // per pair: a candidate this step
  ManifoldScratch scratch;
  std::array<ManifoldPoint, kMaxPairPoints> found{};
  std::array<PairPointContact, kMaxPairPoints> next{};
  std::array<Vec3, kMaxPairPoints> scratch_q{};      // m, mesh frame: sphere_mesh's closest points
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;

  void update(const State& state) { world->update(state); }

  // The contact points of a < b into `found`, normals from a towards b, depths > 0.
  int find(const State& state, int a, int b) {
    const BodyState& sa = state.bodies[a];
    const BodyState& sb = state.bodies[b];
    if (bodies[a].hull && bodies[b].hull) {
      return manifold(bodies[a].edges, sa.position, sa.rotation, bodies[b].edges, sb.position, sb.rotation,
                      scratch, found.data(), kMaxPairPoints);
    }
    const bool mesh_a = bodies[a].mesh != nullptr, mesh_b = bodies[b].mesh != nullptr;
    if (mesh_a && mesh_b) return 0;   // no method yet: stability_warnings() says so
    if (mesh_a && bodies[b].sphere_radius > 0.0) return sphere_mesh(a, sb.position, bodies[b].sphere_radius, false);
    if (mesh_b && bodies[a].sphere_radius > 0.0) return sphere_mesh(b, sa.position, bodies[a].sphere_radius, true);
    result.clear();
    fcl::collide(bodies[a].object, bodies[b].object, request, result);
    const int n = std::min(static_cast<int>(result.numContacts()), kMaxPairPoints);
    const fcl::CollisionGeometryd* geometry_a = bodies[a].object->collisionGeometry().get();
    for (int i = 0; i < n; ++i) {
      const fcl::Contactd& c = result.getContact(static_cast<std::size_t>(i));
      found[i].point = c.pos;
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
        const std::intptr_t tri = (c.o1 == bodies[m].object->collisionGeometry().get()) ? c.b1 : c.b2;
        const Vec3 outward = sm.rotation * bodies[m].triangle_normals[static_cast<std::size_t>(tri)];
        side = mesh_a ? nrm.dot(outward) : -nrm.dot(outward);
      }
      if (std::abs(side) < 0.5) {   // not mesh, or a triangle that FCL's normal crosses edge on
        side = nrm.dot(sb.position - sa.position);
      }
      if (side < 0.0) nrm = -nrm;
      found[i].normal = nrm;
      found[i].depth = std::abs(c.penetration_depth);
      const bool swapped = c.o1 != geometry_a;   // FCL may report the pair as (b, a)
      const std::uint64_t fa = static_cast<std::uint64_t>(swapped ? c.b2 : c.b1);
      const std::uint64_t fb = static_cast<std::uint64_t>(swapped ? c.b1 : c.b2);
      found[i].key = combine(combine(4, fa), fb);
    }
    return finish(n);
  }

  // FCL's contacts in `found[0, n)` in a fixed order: FCL's order is its traversal's, so sort by
  // key, then position, then rank equal keys. Returns the count kept (depth > 0, at the front).
  int finish(int n) {
    std::sort(found.begin(), found.begin() + n, [](const ManifoldPoint& p, const ManifoldPoint& q) {
      if (p.key != q.key) return p.key < q.key;
      for (int d = 0; d < 3; ++d) {
        if (p.point[d] != q.point[d]) return p.point[d] < q.point[d];
      }
      return p.depth < q.depth;
    });
    std::uint64_t rank = 0;
    for (int i = 0; i < n; ++i) {
      rank = (i > 0 && found[i].key == found[i - 1].key) ? rank + 1 : 0;
      found[i].key = combine(found[i].key, rank);
    }
    int kept = 0;
    for (int i = 0; i < n; ++i) {
      if (found[i].depth > 0.0) found[kept++] = found[i];
    }
    return kept;
  }

  // Sphere (centre c, radius r, world) against mesh body m: for each triangle, its closest point
  // q to the centre (Ericson, Real-Time Collision Detection 5.1.5); a contact where |c - q| < r,
  // normal (c - q) / |c - q| out of the mesh, depth r - |c - q|. A centre on or behind a
  // triangle's plane (sunk deeper than r) counts only over the triangle itself: normal the
  // triangle's, depth r + its distance behind. Triangles that share the closest point (an edge or
  // vertex, or a flat face cut into triangles) give it once, the first triangle's key.
  int sphere_mesh(int m, const Vec3& centre_world, double r, bool mesh_is_b) {
    const Body& body = bodies[m];
    const fcl::Transform3d& tf = body.object->getTransform();
    const Mat3 rot = tf.linear();
    const Vec3 pos = tf.translation();
    const Vec3 c = rot.transpose() * (centre_world - pos);   // m, mesh frame
    const TriangleMesh& mesh = *body.mesh;
    int n = 0;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& tri = mesh.triangles[t];
      const Vec3& p0 = mesh.vertices[static_cast<std::size_t>(tri[0])];
      const Vec3& tn = body.triangle_normals[t];
      const double plane = tn.dot(c - p0);   // m: signed distance of the centre from the plane
      if (plane >= r || plane <= -r) continue;
      const Vec3 q = closest_on_triangle(c, p0, mesh.vertices[static_cast<std::size_t>(tri[1])],
                                         mesh.vertices[static_cast<std::size_t>(tri[2])]);
      const Vec3 d = c - q;
      const double dist = d.norm();
      if (dist >= r) continue;
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
        if ((scratch_q[i] - q).squaredNorm() <= 1e-24) {
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
          if (found[i].depth < found[slot].depth) slot = i;
        }
        if (depth <= found[slot].depth) continue;
      }
      scratch_q[slot] = q;
      found[slot].point = pos + rot * (0.5 * (q + c - r * nrm));   // midway between the surfaces
      found[slot].normal = mesh_is_b ? Vec3(-(rot * nrm)) : Vec3(rot * nrm);
      found[slot].depth = depth;
      found[slot].key = combine(5, static_cast<std::uint64_t>(t));
    }
    return n;
  }
};

BodyContacts::BodyContacts(const Model& model, std::shared_ptr<detail::FclWorld> world)
    : impl_(std::make_unique<Impl>()) {
  const int n = static_cast<int>(model.bodies.size());
  impl_->world = world ? std::move(world) : std::make_shared<detail::FclWorld>(model);
  for (int i = 0; i < n; ++i) {
    const Shape& shape = model.bodies[i].shape;
    Impl::Body body;
    body.object = impl_->world->bodies[static_cast<std::size_t>(i)].get();
    if (shape.kind == ShapeKind::kBox) {
      body.hull = std::make_shared<const ConvexPolyhedron>(box_polyhedron(shape.half_extents));
    } else if (shape.kind == ShapeKind::kCylinder) {
      body.hull = std::make_shared<const ConvexPolyhedron>(cylinder_prism(shape));
    } else if (polyhedral(shape)) {
      body.hull = shape.hull;
    }
    if (body.hull) body.edges = hull_edges(*body.hull);
    if (shape.kind == ShapeKind::kSphere) body.sphere_radius = shape.radius;
    if (shape.kind == ShapeKind::kMesh) {
      body.mesh = shape.mesh;
      for (const auto& t : shape.mesh->triangles) {
        const Vec3& p0 = shape.mesh->vertices[static_cast<std::size_t>(t[0])];
        const Vec3 nrm = (shape.mesh->vertices[static_cast<std::size_t>(t[1])] - p0)
                             .cross(shape.mesh->vertices[static_cast<std::size_t>(t[2])] - p0);
        body.triangle_normals.push_back(nrm.normalized());
      }
    }
    impl_->bodies.push_back(std::move(body));
  }
  for (const Impl::Body& body : impl_->bodies) {
    if (body.hull) impl_->scratch.reserve_for(body.edges, body.edges);
  }
  const std::size_t pairs = static_cast<std::size_t>(n) * static_cast<std::size_t>(n > 0 ? n - 1 : 0) / 2;
  impl_->candidates.reserve(pairs);
  impl_->touched.assign(pairs, 0);
  impl_->request.num_max_contacts = kMaxPairPoints;
  impl_->request.enable_contact = true;
}

BodyContacts::~BodyContacts() = default;
BodyContacts::BodyContacts(BodyContacts&&) noexcept = default;
BodyContacts& BodyContacts::operator=(BodyContacts&&) noexcept = default;

int BodyContacts::points(const Model& model, const State& state, int a, int b, ManifoldPoint* out) {
  if (!collides(body_pair(model, a, b))) return 0;
  impl_->update(state);
  const int n = impl_->find(state, a, b);
  std::copy(impl_->found.begin(), impl_->found.begin() + n, out);
  return n;
}

void BodyContacts::step(const Model& model, State& state, std::vector<Wrench>& wrenches, std::vector<int>& points,
                        std::vector<ContactRecord>* records) {
  run(model, state, &wrenches, points, nullptr, records);
}

void BodyContacts::couplings(const Model& model, State& state, std::vector<Coupling>& out, std::vector<int>& points) {
  run(model, state, nullptr, points, &out, nullptr);
}

void BodyContacts::run(const Model& model, State& state, std::vector<Wrench>* wrenches, std::vector<int>& points,
                       std::vector<Coupling>* out, std::vector<ContactRecord>* records) {
  Impl& im = *impl_;
  const int nb = static_cast<int>(model.bodies.size());
  if (nb < 2) return;
  im.update(state);
  im.candidates.clear();
  im.world->broadphase.collide(&im.candidates, add_pair);
  // The tree's order depends on how it was built: sort, so that results never do.
  std::sort(im.candidates.begin(), im.candidates.end());

  // Sleep: a sleeping body whose box a moving body's box overlaps wakes first (a body landing on
  // it, pushing it). Moving: an awake body over a sleep threshold; a body just woken is at rest,
  // so one pass decides.
  if (model.sleep.enabled) {
    const auto moving = [&](const BodyState& s) {
      return !s.asleep && (s.velocity.norm() > model.sleep.linear_speed ||
                           s.angular_velocity.norm() > model.sleep.angular_speed);
    };
    for (const auto& [a, b] : im.candidates) {
      BodyState& sa = state.bodies[a];
      BodyState& sb = state.bodies[b];
      if (sa.asleep && moving(sb)) wake(sa);
      if (sb.asleep && moving(sa)) wake(sb);
    }
  }

  for (const auto& [a, b] : im.candidates) {
    const ContactPair cp = body_pair(model, a, b);
    if (!collides(cp)) continue;
    const std::size_t pi = pair_index(a, b, nb);
    im.touched[pi] = 1;
    PairContact& pc = state.pairs[pi];
    if (state.bodies[a].asleep && state.bodies[b].asleep) {   // both at rest: the contact stands
      points[a] += pc.count;
      points[b] += pc.count;
      continue;
    }
    const int n = im.find(state, a, b);
    if (n == 0 && pc.count > 0) {   // a support gone: a sleeper on it wakes, stepped from now
      wake(state.bodies[a]);
      wake(state.bodies[b]);
    }
    BodyState& sa = state.bodies[a];
    BodyState& sb = state.bodies[b];
    for (int i = 0; i < n; ++i) {
      const ManifoldPoint& mp = im.found[i];
      const Vec3& nrm = mp.normal;
      const Vec3 ra = mp.point - sa.position, rb = mp.point - sb.position;   // m
      const Vec3 v_rel = (sb.velocity + sb.angular_velocity.cross(rb)) - (sa.velocity + sa.angular_velocity.cross(ra));
      const double vn = v_rel.dot(nrm);   // m/s: > 0 separating
      const Vec3 v_t = v_rel - vn * nrm;   // m/s: B's material sliding over A's
      const double f_n = std::max(0.0, cp.stiffness * mp.depth - cp.damping * vn);
      // The anchors: this feature's from the last step, else both stuck here now.
      PairPointContact pp;
      pp.key = mp.key;
      Vec3 anchor_a = mp.point, anchor_b = mp.point;   // m, world
      for (int j = 0; j < pc.count; ++j) {
        if (pc.points[j].key == mp.key) {
          pp = pc.points[j];
          anchor_a = sa.position + sa.rotation * pp.anchor_a;
          anchor_b = sb.position + sb.rotation * pp.anchor_b;
          break;
        }
      }
      // Onto the contact plane through the point.
      anchor_a -= (anchor_a - mp.point).dot(nrm) * nrm;
      anchor_b -= (anchor_b - mp.point).dot(nrm) * nrm;
      const double viscous = cp.viscous * v_t.norm();   // N, while slipping
      pp.slipping = stick_slip_step(anchor_b, cp.mu * f_n / cp.stiffness,
                                    (cp.friction(true) * f_n + viscous) / cp.stiffness, v_t, pp.slipping, anchor_a);
      const Vec3 stretch = anchor_a - anchor_b;   // m: pulls B's material towards A's anchor
      ++points[a];
      ++points[b];
      // Keep the stretch, re-based at this point (the point may move over the bodies).
      pp.anchor_b = sb.rotation.transpose() * (mp.point - sb.position);
      pp.anchor_a = sa.rotation.transpose() * (mp.point + stretch - sa.position);
      im.next[i] = pp;
      if (out != nullptr) {   // the implicit step: the law unclamped, solved with the bodies
        Coupling c;
        c.source = Coupling::Source::kBody;
        c.slot = i;
        c.a = a;
        c.b = b;
        c.point = mp.point;
        c.normal = nrm;
        c.force = (cp.stiffness * mp.depth - cp.damping * vn) * nrm + cp.stiffness * stretch - cp.damping * v_t;
        c.k_n = c.k_t = cp.stiffness;
        c.c_n = c.c_t = cp.damping;
        c.mu = cp.friction(pp.slipping);
        c.viscous = pp.slipping ? viscous : 0.0;
        out->push_back(c);
        continue;
      }
      Vec3 f_t = cp.stiffness * stretch - cp.damping * v_t;
      clamp_to_cone(cp.friction(pp.slipping) * f_n + (pp.slipping ? viscous : 0.0), f_t);
      const Vec3 f = f_n * nrm + f_t;   // N on B; -f on A, at the same point
      (*wrenches)[b].force += f;
      (*wrenches)[b].torque += rb.cross(f);
      (*wrenches)[a].force -= f;
      (*wrenches)[a].torque -= ra.cross(f);
      if (records != nullptr) records->push_back(ContactRecord{a, b, mp.point, nrm, f});
    }
    std::copy(im.next.begin(), im.next.begin() + n, pc.points.begin());
    pc.count = n;
  }
  // Pairs no longer near each other lose their anchors.
  // A sleeper among them wakes: its support moved away.
  for (std::size_t pi = 0; pi < im.touched.size(); ++pi) {
    if (!im.touched[pi] && state.pairs[pi].count > 0) {
      state.pairs[pi].count = 0;
      if (model.sleep.enabled) wake_pair(state, static_cast<int>(pi), nb);
    }
    im.touched[pi] = 0;
  }
}

}  // namespace graspsim
