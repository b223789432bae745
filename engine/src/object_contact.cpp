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

int floor_contact(const Model& model, int body, BodyState& bs, Wrench& out) {
  out = Wrench{};
  const BodyParams& bp = model.bodies[body];
  const ContactPair pair = contact_pair(bp.material, model.floor.material);
  const double floor_z = model.floor.height;
  int touching = 0;
  const int count = static_cast<int>(bs.floor_contacts.size());
  for (int k = 0; k < count; ++k) {
    VertexContact& vc = bs.floor_contacts[k];
    bool rolling = false;
    const Vec3 r = floor_point(bp.shape, bs.rotation, k, rolling);   // m: from centre of mass
    const Vec3 x = bs.position + r;
    const double depth = floor_z - x.z();
    if (depth <= 0.0) {
      vc.active = false;
      continue;
    }
    ++touching;
    const Vec3 u = bs.velocity + bs.angular_velocity.cross(r);   // m/s: velocity of the material there
    const double f_n = std::max(0.0, pair.stiffness * depth - pair.damping * u.z());
    // A vertex is its own material point; a rolling point's is the one under it last step.
    const Vec3 x_m = (rolling && vc.active) ? Vec3(bs.position + bs.rotation * vc.material) : x;
    const Vec3 x_t(x_m.x(), x_m.y(), floor_z);
    if (!vc.active) {
      vc.active = true;
      vc.slipping = false;
      vc.anchor = x_t;
    }
    // Static coefficient while stuck, kinetic (plus viscous c |u_t|) while slipping, with the
    // fingers' rule for sticking again (stick_slip_step), on the point's velocity over the floor.
    const Vec3 u_t(u.x(), u.y(), 0.0);   // m/s
    const double viscous = pair.viscous * u_t.norm();   // N, while slipping
    vc.slipping = stick_slip_step(x_t, pair.mu * f_n / pair.stiffness,
                                  (pair.friction(true) * f_n + viscous) / pair.stiffness, u_t,
                                  vc.slipping, vc.anchor);
    const double mu = pair.friction(vc.slipping);
    const double limit_viscous = vc.slipping ? viscous : 0.0;
    Vec3 f_t = pair.stiffness * (vc.anchor - x_t) - pair.damping * Vec3(u.x(), u.y(), 0.0);
    const double limit = mu * f_n + limit_viscous;
    const double f_t_norm = f_t.norm();
    if (f_t_norm > limit) f_t *= limit / f_t_norm;
    const Vec3 f(f_t.x(), f_t.y(), f_n);
    out.force += f;
    out.torque += r.cross(f);
    if (rolling) {   // carry the stretch over to the new lowest point and its material
      vc.anchor = Vec3(x.x(), x.y(), floor_z) + (vc.anchor - x_t);
      vc.material = bs.rotation.transpose() * r;
    }
  }
  return touching;
}

// ---- body against body ----

namespace {

std::uint64_t combine(std::uint64_t h, std::uint64_t v) {
  return h ^ (v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
}

bool polyhedral(const Shape& s) { return s.kind == ShapeKind::kBox || (s.kind == ShapeKind::kConvex && s.hull); }

// A pair of bodies that can touch: both rigid means no finite penalty law.
bool collides(const ContactPair& p) { return std::isfinite(p.stiffness) && std::isfinite(p.damping); }

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
    std::unique_ptr<fcl::CollisionObjectd> object;   // user data: body index + 1
    std::shared_ptr<const ConvexPolyhedron> hull;    // polyhedral shapes
    HullEdges edges;
  };
  std::vector<Body> bodies;
  fcl::DynamicAABBTreeCollisionManagerd broadphase;
  std::vector<std::pair<int, int>> candidates;       // capacity n (n - 1) / 2
  std::vector<std::uint8_t> touched;                 // per pair: a candidate this step
  ManifoldScratch scratch;
  std::array<ManifoldPoint, kMaxPairPoints> found{};
  std::array<PairPointContact, kMaxPairPoints> next{};
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;

  void update(const State& state) {
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      fcl::Transform3d tf = fcl::Transform3d::Identity();
      tf.linear() = state.bodies[i].rotation;
      tf.translation() = state.bodies[i].position;
      bodies[i].object->setTransform(tf);
      bodies[i].object->computeAABB();
    }
    broadphase.update();
  }

  // The contact points of a < b into `found`.
  int find(const State& state, int a, int b) {
    const BodyState& sa = state.bodies[a];
    const BodyState& sb = state.bodies[b];
    if (bodies[a].hull && bodies[b].hull) {
      return manifold(bodies[a].edges, sa.position, sa.rotation, bodies[b].edges, sb.position, sb.rotation,
                      scratch, found.data(), kMaxPairPoints);
    }
    result.clear();
    fcl::collide(bodies[a].object.get(), bodies[b].object.get(), request, result);
    const int n = std::min(static_cast<int>(result.numContacts()), kMaxPairPoints);
    for (int i = 0; i < n; ++i) {
      const fcl::Contactd& c = result.getContact(static_cast<std::size_t>(i));
      found[i].point = c.pos;
      found[i].normal = c.normal.normalized();   // FCL: from o1 (a) to o2 (b)
      found[i].depth = c.penetration_depth;
      found[i].key = combine(combine(4, static_cast<std::uint64_t>(c.b1)), static_cast<std::uint64_t>(c.b2));
    }
    // FCL's order is its traversal's: sort by key, then position, then rank equal keys.
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
};

BodyContacts::BodyContacts(const Model& model) : impl_(std::make_unique<Impl>()) {
  const int n = static_cast<int>(model.bodies.size());
  std::vector<fcl::CollisionObjectd*> objects;
  for (int i = 0; i < n; ++i) {
    const Shape& shape = model.bodies[i].shape;
    Impl::Body body;
    body.object = std::make_unique<fcl::CollisionObjectd>(detail::fcl_geometry(shape));
    body.object->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(i + 1)));
    if (shape.kind == ShapeKind::kBox) {
      body.hull = std::make_shared<const ConvexPolyhedron>(box_polyhedron(shape.half_extents));
    } else if (polyhedral(shape)) {
      body.hull = shape.hull;
    }
    if (body.hull) body.edges = hull_edges(*body.hull);
    objects.push_back(body.object.get());
    impl_->bodies.push_back(std::move(body));
  }
  for (const Impl::Body& body : impl_->bodies) {
    if (body.hull) impl_->scratch.reserve_for(body.edges, body.edges);
  }
  impl_->broadphase.registerObjects(objects);
  impl_->broadphase.setup();
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
  if (!collides(contact_pair(model.bodies[a].material, model.bodies[b].material))) return 0;
  impl_->update(state);
  const int n = impl_->find(state, a, b);
  std::copy(impl_->found.begin(), impl_->found.begin() + n, out);
  return n;
}

void BodyContacts::step(const Model& model, State& state, std::vector<Wrench>& wrenches, std::vector<int>& points) {
  Impl& im = *impl_;
  const int nb = static_cast<int>(model.bodies.size());
  if (nb < 2) return;
  im.update(state);
  im.candidates.clear();
  im.broadphase.collide(&im.candidates, add_pair);
  // The tree's order depends on how it was built: sort, so that results never do.
  std::sort(im.candidates.begin(), im.candidates.end());

  for (const auto& [a, b] : im.candidates) {
    const ContactPair cp = contact_pair(model.bodies[a].material, model.bodies[b].material);
    if (!collides(cp)) continue;
    const std::size_t pi = pair_index(a, b, nb);
    im.touched[pi] = 1;
    PairContact& pc = state.pairs[pi];
    const int n = im.find(state, a, b);
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
      Vec3 f_t = cp.stiffness * stretch - cp.damping * v_t;
      const double limit = cp.friction(pp.slipping) * f_n + (pp.slipping ? viscous : 0.0);
      const double f_t_norm = f_t.norm();
      if (f_t_norm > limit) f_t *= limit / f_t_norm;
      const Vec3 f = f_n * nrm + f_t;   // N on B; -f on A, at the same point
      wrenches[b].force += f;
      wrenches[b].torque += rb.cross(f);
      wrenches[a].force -= f;
      wrenches[a].torque -= ra.cross(f);
      ++points[a];
      ++points[b];
      // Keep the stretch, re-based at this point (the point may move over the bodies).
      pp.anchor_b = sb.rotation.transpose() * (mp.point - sb.position);
      pp.anchor_a = sa.rotation.transpose() * (mp.point + stretch - sa.position);
      im.next[i] = pp;
    }
    std::copy(im.next.begin(), im.next.begin() + n, pc.points.begin());
    pc.count = n;
  }
  // Pairs no longer near each other lose their anchors.
  for (std::size_t pi = 0; pi < im.touched.size(); ++pi) {
    if (!im.touched[pi]) state.pairs[pi].count = 0;
    im.touched[pi] = 0;
  }
}

}  // namespace graspsim
