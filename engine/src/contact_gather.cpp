// The one gather of contact points (contact_gather.hpp): floor points and body pairs, with their
// anchors.
#include "graspsim/engine/contact_gather.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>

#include "fcl_world.hpp"
#include "graspsim/engine/contact_law.hpp"
#include "graspsim/engine/floor_points.hpp"
#include "narrowphase.hpp"

namespace graspsim {

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
// friction circle with the normal force k depth - c u_n (0 if it pulls).
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
  // fingers' rule for sticking again, on the point's velocity over the floor.
  p.u_t = Vec3(u.x(), u.y(), 0.0);
  p.viscous = pair.viscous * p.u_t.norm();
  vc.slipping = move_anchor(pair, std::max(0.0, p.f_n), p.viscous, p.x_t, p.u_t, vc.slipping, vc.anchor);
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

// The broadphase's callback: each pair of bodies whose boxes overlap, as (lower, higher) index.
bool add_pair(fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
  auto* out = static_cast<std::vector<std::pair<int, int>>*>(data);
  const int i = static_cast<int>(reinterpret_cast<std::intptr_t>(a->getUserData())) - 1;
  const int j = static_cast<int>(reinterpret_cast<std::intptr_t>(b->getUserData())) - 1;
  out->emplace_back(std::min(i, j), std::max(i, j));
  return false;   // keep going
}

}  // namespace

int floor_couplings(const Model& model, int b, const ContactPair& law, BodyState& bs, double h, double radius,
                    std::vector<Coupling>& out) {
  const BodyParams& bp = model.bodies[b];
  const double floor_z = model.floor.height;
  const double gravity_reach = h * h * model.gravity.norm();   // m: how far gravity alone carries a point in a step
  // A point counts while the step can close its height: no point of the body closes more than
  // h (max(0, -v_z) + |w| radius) + gravity_reach, the bound the full test takes from its own velocity.
  const VertexScreen screen(bp.shape, bs, floor_z,
                            h * (std::max(0.0, -bs.velocity.z()) + bs.angular_velocity.norm() * radius) + gravity_reach,
                            std::isfinite(radius) ? radius : 0.0);
  const bool screened = std::isfinite(radius);
  int touching = 0;
  const int points = static_cast<int>(bs.floor_contacts.size());
  for (int k = 0; k < points; ++k) {
    if (screened && screen.out_of_reach(k)) {
      bs.floor_contacts[k].active = false;
      continue;
    }
    FloorPoint p;
    if (!track_floor_point(bp, bs, law, floor_z, k, h, gravity_reach, p)) continue;
    VertexContact& vc = bs.floor_contacts[k];
    touching += p.depth > 0.0 ? 1 : 0;
    const PenaltyForce f = penalty_force(law, p.depth, p.u_n, vc.anchor - p.x_t, p.u_t);
    Coupling c;
    c.source = Coupling::Source::kFloor;
    c.slot = k;
    c.a = -1;
    c.b = b;
    c.point = p.x;
    c.arm = p.r;
    c.normal = Vec3::UnitZ();
    c.normal_force = f.normal;
    c.tangential_force = f.tangential;
    c.force = f.tangential + Vec3(0.0, 0.0, f.normal);
    c.depth = p.depth;
    c.k_n = c.k_t = law.stiffness;
    c.c_n = c.c_t = law.damping;
    c.mu = law.friction(vc.slipping);
    c.viscous = vc.slipping ? p.viscous : 0.0;
    c.slipping = vc.slipping;
    out.push_back(c);
    roll_on(bs, p, floor_z, vc);
  }
  return touching;
}

std::size_t pairs_room(std::size_t bodies) { return std::min(bodies * (bodies > 0 ? bodies - 1 : 0) / 2, 12 * bodies); }

std::size_t contact_room(const Model& model) {
  std::size_t points = model.fingers.size() + kMaxPairPoints * pairs_room(model.bodies.size());
  for (const BodyParams& bp : model.bodies) points += static_cast<std::size_t>(floor_point_count(bp.shape));
  return points;
}

struct ContactGather::Impl {
  Impl(const Model& model, std::shared_ptr<detail::FclWorld> w)
      : world(w ? std::move(w) : std::make_shared<detail::FclWorld>(model)), narrow(model, world) {
    for (const BodyParams& bp : model.bodies) {
      reach.push_back(floor_reach(bp.shape) * (1.0 + 1e-9) + 1e-12);
      floor_law.push_back(model.floor.enabled ? floor_pair(model, static_cast<int>(floor_law.size())) : ContactPair{});
    }
    floor_clear.assign(model.bodies.size(), 0);
    margin.assign(model.bodies.size(), 0.0);
    const std::size_t n = model.bodies.size();
    candidates.reserve(pairs_room(n));
    measured.reserve(pairs_room(n));
    next.reserve(pairs_room(n));
  }

  void floor_points(const Model& model, State& state, double h, std::vector<Coupling>& out, std::vector<int>& count);
  int floor_of_body(const Model& model, int b, BodyState& bs, double h, std::vector<Coupling>& out);
  void pair_contacts(const Model& model, State& state, double h, std::vector<Coupling>& out, std::vector<int>& count);
  void wake_reached(const Model& model, State& state);
  int gather_pair(const Model& model, State& state, int a, int b, const PairContact* before, double h,
                  std::vector<Coupling>& out);

  std::shared_ptr<detail::FclWorld> world;
  detail::Narrowphase narrow;
  std::vector<double> reach;              // m, per body: farthest floor point from the centre of mass (a hair over)
  std::vector<ContactPair> floor_law;     // per body: its law with the floor (constant)
  std::vector<std::uint8_t> floor_clear;  // per body: 1 when none of its floor points is active
  std::vector<double> margin;             // m, per body: how far it can travel towards another in a step
  std::vector<std::pair<int, int>> candidates;   // pairs whose grown boxes overlap, sorted
  std::vector<std::pair<int, int>> measured;     // pairs whose boxes overlap now (spring_energy), sorted
  std::vector<PairContact> next;          // State::pairs being built
  std::array<ManifoldPoint, kMaxPairPoints> found{};
};

ContactGather::ContactGather(const Model& model, std::shared_ptr<detail::FclWorld> world)
    : impl_(std::make_unique<Impl>(model, std::move(world))) {}
ContactGather::~ContactGather() = default;
ContactGather::ContactGather(ContactGather&&) noexcept = default;
ContactGather& ContactGather::operator=(ContactGather&&) noexcept = default;

void ContactGather::gather(const Model& model, State& state, double h, std::vector<Coupling>& out,
                           std::vector<int>& floor_points, std::vector<int>& body_points) {
  std::fill(floor_points.begin(), floor_points.end(), 0);
  std::fill(body_points.begin(), body_points.end(), 0);
  // Pairs first: a sleeper a moving body reaches wakes there, and then has its floor points.
  impl_->pair_contacts(model, state, h, out, body_points);
  if (model.floor.enabled) impl_->floor_points(model, state, h, out, floor_points);
}

// ---- the floor ----

void ContactGather::Impl::floor_points(const Model& model, State& state, double h, std::vector<Coupling>& out,
                                       std::vector<int>& count) {
  const double g = model.gravity.norm();   // m/s^2
  for (std::size_t b = 0; b < model.bodies.size(); ++b) {
    BodyState& bs = state.bodies[b];
    if (bs.asleep) continue;
    // How far the body's lowest point can travel towards the floor in this step (0: the paper's).
    const double approach = h * (std::max(0.0, -bs.velocity.z()) + bs.angular_velocity.norm() * reach[b] + h * g);
    if (bs.position.z() - reach[b] - approach > model.floor.height) {
      // No floor point can reach the floor: what the point test would give (nothing, every
      // point inactive), without visiting the points (2,562 on the profile's mesh).
      if (!floor_clear[b]) {
        for (VertexContact& vc : bs.floor_contacts) vc.active = false;
        floor_clear[b] = 1;
      }
      continue;
    }
    const int touching = floor_of_body(model, static_cast<int>(b), bs, h, out);
    count[b] = touching;
  }
}

// Body b's floor points: each within reach a coupling (the law unclamped, anchors moved); returns
// how many are under the floor now.
int ContactGather::Impl::floor_of_body(const Model& model, int b, BodyState& bs, double h, std::vector<Coupling>& out) {
  const std::size_t before = out.size();
  const int touching = floor_couplings(model, b, floor_law[b], bs, h, h > 0.0 ? reach[b] : 0.0, out);
  floor_clear[b] = out.size() == before ? 1 : 0;
  return touching;
}

// ---- body against body ----

// Sleep: a sleeping body whose box a moving body's box overlaps wakes first (a body landing on
// it, pushing it). Moving: an awake body over a sleep threshold; a body just woken is at rest,
// so one pass decides.
void ContactGather::Impl::wake_reached(const Model& model, State& state) {
  const auto moving = [&](const BodyState& s) {
    return !s.asleep && (s.velocity.norm() > model.sleep.linear_speed ||
                         s.angular_velocity.norm() > model.sleep.angular_speed);
  };
  for (const auto& [a, b] : candidates) {
    BodyState& sa = state.bodies[a];
    BodyState& sb = state.bodies[b];
    if (sa.asleep && moving(sb)) wake(sa);
    if (sb.asleep && moving(sa)) wake(sb);
  }
}

void ContactGather::Impl::pair_contacts(const Model& model, State& state, double h, std::vector<Coupling>& out,
                                        std::vector<int>& count) {
  const int nb = static_cast<int>(model.bodies.size());
  if (nb < 2) return;
  const double g = model.gravity.norm();   // m/s^2
  for (int b = 0; b < nb; ++b) {   // half of a pair's reach each, so two boxes overlap within it
    const BodyState& bs = state.bodies[b];
    margin[b] = h * (bs.velocity.norm() + bs.angular_velocity.norm() * reach[b] + h * g);
  }
  world->update(state, h > 0.0 ? &margin : nullptr);
  candidates.clear();
  world->broadphase.collide(&candidates, add_pair);
  // The tree's order depends on how it was built: sort, so that results never do.
  std::sort(candidates.begin(), candidates.end());
  if (model.sleep.enabled) wake_reached(model, state);

  next.clear();
  std::size_t before = 0;   // walks state.pairs (sorted) beside the candidates (sorted)
  for (const auto& [a, b] : candidates) {
    const PairContact* last = nullptr;
    while (before < state.pairs.size() && std::make_pair(state.pairs[before].a, state.pairs[before].b) < std::make_pair(a, b)) {
      // A pair no longer near: its support went away, so a sleeper on it wakes.
      if (model.sleep.enabled) {
        wake(state.bodies[state.pairs[before].a]);
        wake(state.bodies[state.pairs[before].b]);
      }
      ++before;
    }
    if (before < state.pairs.size() && state.pairs[before].a == a && state.pairs[before].b == b) last = &state.pairs[before++];
    if (!collides(body_pair(model, a, b)) || !narrow.can_touch(a, b)) continue;
    if (state.bodies[a].asleep && state.bodies[b].asleep) {   // both at rest: the contact stands
      if (last != nullptr) {
        next.push_back(*last);
        count[a] += last->count;
        count[b] += last->count;
      }
      continue;
    }
    const int n = gather_pair(model, state, a, b, last, h, out);
    for (int i = 0; i < n; ++i) {
      const int touching = found[i].depth > 0.0 ? 1 : 0;
      count[a] += touching;
      count[b] += touching;
    }
  }
  for (; before < state.pairs.size(); ++before) {
    if (!model.sleep.enabled) break;
    wake(state.bodies[state.pairs[before].a]);
    wake(state.bodies[state.pairs[before].b]);
  }
  std::swap(state.pairs, next);
}

// The points of a < b (`last`: their contact at the last step, or nullptr): each a coupling, its
// anchors kept by feature key from the last step (else both stuck where it is now) and moved by
// the friction circle; the pair appended to `next` when it has points. Returns the points found.
int ContactGather::Impl::gather_pair(const Model& model, State& state, int a, int b, const PairContact* last,
                                     double h, std::vector<Coupling>& out) {
  const BodyState& sa = state.bodies[a];
  const BodyState& sb = state.bodies[b];
  // m: h (|v_a| + |v_b| + |w_a| r_a + |w_b| r_b) + 2 h^2 |g|, the two bodies' margins together
  const double pair_margin = h > 0.0 ? margin[a] + margin[b] : 0.0;
  const int n = narrow.find(state, a, b, pair_margin, true, found.data());
  if (n == 0) {
    if (last != nullptr) {   // a support gone: a sleeper on it wakes, stepped from now
      wake(state.bodies[a]);
      wake(state.bodies[b]);
    }
    return 0;
  }
  const ContactPair law = body_pair(model, a, b);
  PairContact pc;
  pc.a = a;
  pc.b = b;
  pc.count = n;
  const int pair_index = static_cast<int>(next.size());
  for (int i = 0; i < n; ++i) {
    const ManifoldPoint& mp = found[i];
    const Vec3& nrm = mp.normal;
    const Vec3 ra = mp.point - sa.position, rb = mp.point - sb.position;   // m
    const Vec3 v_rel = (sb.velocity + sb.angular_velocity.cross(rb)) - (sa.velocity + sa.angular_velocity.cross(ra));
    const double vn = v_rel.dot(nrm);   // m/s: > 0 separating
    const Vec3 v_t = v_rel - vn * nrm;   // m/s: B's material sliding over A's
    const double f_n = std::max(0.0, law.stiffness * mp.depth - law.damping * vn);
    // The anchors: this feature's from the last step, else both stuck here now.
    PairPointContact pp;
    pp.key = mp.key;
    Vec3 anchor_a = mp.point, anchor_b = mp.point;   // m, world
    for (int j = 0; last != nullptr && j < last->count; ++j) {
      if (last->points[j].key == mp.key) {
        pp = last->points[j];
        anchor_a = sa.position + sa.rotation * pp.anchor_a;
        anchor_b = sb.position + sb.rotation * pp.anchor_b;
        break;
      }
    }
    // Onto the contact plane through the point.
    anchor_a -= (anchor_a - mp.point).dot(nrm) * nrm;
    anchor_b -= (anchor_b - mp.point).dot(nrm) * nrm;
    const double viscous = law.viscous * v_t.norm();   // N, while slipping
    pp.slipping = move_anchor(law, f_n, viscous, anchor_b, v_t, pp.slipping, anchor_a);
    const Vec3 stretch = anchor_a - anchor_b;   // m: pulls B's material towards A's anchor
    // Keep the stretch, re-based at this point (the point may move over the bodies).
    pp.anchor_b = sb.rotation.transpose() * (mp.point - sb.position);
    pp.anchor_a = sa.rotation.transpose() * (mp.point + stretch - sa.position);
    pc.points[i] = pp;
    const PenaltyForce f = penalty_force(law, mp.depth, vn, stretch, v_t);
    Coupling c;
    c.source = Coupling::Source::kBody;
    c.slot = i;
    c.pair = pair_index;
    c.a = a;
    c.b = b;
    c.point = mp.point;
    c.arm = rb;
    c.normal = nrm;
    c.normal_force = f.normal;
    c.tangential_force = f.tangential;
    c.force = f.normal * nrm + f.tangential;
    c.depth = mp.depth;
    c.k_n = c.k_t = law.stiffness;
    c.c_n = c.c_t = law.damping;
    c.mu = law.friction(pp.slipping);
    c.viscous = pp.slipping ? viscous : 0.0;
    c.slipping = pp.slipping;
    out.push_back(c);
  }
  next.push_back(pc);
  return n;
}

// ---- read only ----

void ContactGather::last_contacts(const Model& model, const State& state, std::vector<Coupling>& out) {
  if (model.floor.enabled) {
    for (std::size_t b = 0; b < state.bodies.size(); ++b) {
      const BodyState& bs = state.bodies[b];
      const ContactPair& law = impl_->floor_law[b];
      for (std::size_t k = 0; k < bs.floor_contacts.size(); ++k) {
        const VertexContact& vc = bs.floor_contacts[k];
        if (!vc.active) continue;
        bool rolling = false;
        Coupling c;
        c.source = Coupling::Source::kFloor;
        c.slot = static_cast<int>(k);
        c.b = static_cast<int>(b);
        c.arm = floor_point(model.bodies[b].shape, bs.rotation, static_cast<int>(k), rolling);
        c.point = bs.position + c.arm;
        c.normal = Vec3::UnitZ();
        c.k_n = c.k_t = law.stiffness;
        c.c_n = c.c_t = law.damping;
        c.slipping = vc.slipping;
        out.push_back(c);
      }
    }
  }
  for (std::size_t p = 0; p < state.pairs.size(); ++p) {
    const PairContact& pc = state.pairs[p];
    const ContactPair law = body_pair(model, pc.a, pc.b);
    if (!collides(law)) continue;
    ManifoldPoint* points = impl_->found.data();
    const int n = impl_->narrow.find(state, pc.a, pc.b, 0.0, false, points);
    for (int i = 0; i < n; ++i) {
      Coupling c;
      c.source = Coupling::Source::kBody;
      c.slot = i;
      c.pair = static_cast<int>(p);
      c.a = pc.a;
      c.b = pc.b;
      c.point = points[i].point;
      c.arm = points[i].point - state.bodies[pc.b].position;
      c.normal = points[i].normal;
      c.depth = points[i].depth;
      c.k_n = c.k_t = law.stiffness;
      c.c_n = c.c_t = law.damping;
      for (int j = 0; j < pc.count; ++j) {
        if (pc.points[j].key == points[i].key) c.slipping = pc.points[j].slipping;
      }
      out.push_back(c);
    }
  }
}

namespace {

// J: the anchor spring's energy of a point pushed with `pushing` (N) whose stretch is s (m),
// after the anchor rule: within the static circle it stays, beyond it the anchor moves onto the
// kinetic circle (move_anchor).
double anchor_energy(const ContactPair& law, double pushing, double viscous, const Vec3& s) {
  const double k = law.stiffness;
  const double r_static = law.mu * pushing / k, r_kinetic = (law.friction(true) * pushing + viscous) / k;   // m
  const double r2 = s.squaredNorm();
  return 0.5 * k * (r2 <= r_static * r_static ? r2 : r_kinetic * r_kinetic);
}

}  // namespace

double ContactGather::spring_energy(const Model& model, const State& state, std::vector<double>* per_body) {
  double total = 0.0;
  const auto add = [&](int b, double e) {
    total += e;
    if (per_body != nullptr) (*per_body)[b] += e;
  };
  for (std::size_t b = 0; model.floor.enabled && b < state.bodies.size(); ++b) {
    const BodyState& bs = state.bodies[b];
    const BodyParams& bp = model.bodies[b];
    const ContactPair& law = impl_->floor_law[b];
    for (std::size_t k = 0; k < bs.floor_contacts.size(); ++k) {
      const VertexContact& vc = bs.floor_contacts[k];
      bool rolling = false;
      const Vec3 r = floor_point(bp.shape, bs.rotation, static_cast<int>(k), rolling);
      const Vec3 x = bs.position + r;
      const double depth = model.floor.height - x.z();
      if (!(depth > 0.0)) continue;
      const Vec3 u = bs.velocity + bs.angular_velocity.cross(r);
      const double pushing = std::max(0.0, law.stiffness * depth - law.damping * u.z());
      double e = 0.5 * law.stiffness * depth * depth;
      if (vc.active) {
        const Vec3 x_m = rolling ? Vec3(bs.position + bs.rotation * vc.material) : x;
        const Vec3 stretch = vc.anchor - Vec3(x_m.x(), x_m.y(), model.floor.height);
        e += anchor_energy(law, pushing, law.viscous * std::hypot(u.x(), u.y()), stretch);
      }
      add(static_cast<int>(b), e);
    }
  }
  // Every pair that overlaps now, not only those the last gather kept: a scene built overlapping
  // holds its springs' energy before the first step. The broadphase is placed at this state
  // without margins; whoever asks it next places it again (the gather at the next step, the
  // fingers' queries after any physics step).
  if (model.bodies.size() < 2) return total;
  Impl& im = *impl_;
  im.world->update(state, nullptr);
  im.measured.clear();
  im.world->broadphase.collide(&im.measured, add_pair);
  std::sort(im.measured.begin(), im.measured.end());
  ManifoldPoint* points = im.found.data();
  static const PairContact kNoAnchors{};   // a pair no gather has kept yet
  for (const auto& [a, b] : im.measured) {
    const ContactPair law = body_pair(model, a, b);
    if (!collides(law) || !im.narrow.can_touch(a, b)) continue;
    const PairContact* kept = find_pair(state, a, b);
    const PairContact& pc = kept != nullptr ? *kept : kNoAnchors;
    const BodyState& sa = state.bodies[a];
    const BodyState& sb = state.bodies[b];
    const int n = im.narrow.find(state, a, b, 0.0, false, points);
    for (int i = 0; i < n; ++i) {
      const ManifoldPoint& mp = points[i];
      if (!(mp.depth > 0.0)) continue;
      const Vec3 ra = mp.point - sa.position, rb = mp.point - sb.position;
      const Vec3 v_rel = (sb.velocity + sb.angular_velocity.cross(rb)) - (sa.velocity + sa.angular_velocity.cross(ra));
      const double vn = v_rel.dot(mp.normal);
      double e = 0.5 * law.stiffness * mp.depth * mp.depth;
      for (int j = 0; j < pc.count; ++j) {
        if (pc.points[j].key != mp.key) continue;
        Vec3 stretch = (sa.position + sa.rotation * pc.points[j].anchor_a) - (sb.position + sb.rotation * pc.points[j].anchor_b);
        stretch -= stretch.dot(mp.normal) * mp.normal;
        const double pushing = std::max(0.0, law.stiffness * mp.depth - law.damping * vn);
        e += anchor_energy(law, pushing, law.viscous * (v_rel - vn * mp.normal).norm(), stretch);
        break;
      }
      add(a, 0.5 * e);
      add(b, 0.5 * e);
    }
  }
  return total;
}

int ContactGather::pair_points(const Model& model, const State& state, int a, int b, ManifoldPoint* out, double margin) {
  if (!collides(body_pair(model, a, b))) return 0;
  return impl_->narrow.find(state, a, b, margin, false, out);
}

}  // namespace graspsim
