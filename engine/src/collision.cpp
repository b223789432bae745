// Collision queries: FCL finds the bodies a finger's path touches; the box geometry that the
// god-object is constrained to is exact and analytic.
#include "graspsim/engine/collision.hpp"

#include "fcl_shape.hpp"
#include "fcl_world.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>

namespace graspsim {

Face box_face(const Vec3& h, int face) {
  const int axis = face / 2;
  const double sign = (face % 2 == 0) ? 1.0 : -1.0;
  Vec3 n = Vec3::Zero();
  n[axis] = sign;
  return Face{n, h[axis]};
}

bool within_face(const Vec3& h, int face, const Vec3& x) {
  const int axis = face / 2;
  for (int j = 0; j < 3; ++j) {
    if (j != axis && std::abs(x[j]) > h[j]) return false;
  }
  return true;
}

std::optional<BoxEntry> box_entry(const Vec3& h, const Vec3& a, const Vec3& b) {
  const auto inside = [&h](const Vec3& x) {
    return std::abs(x.x()) <= h.x() && std::abs(x.y()) <= h.y() && std::abs(x.z()) <= h.z();
  };
  if (inside(a)) {
    if (!inside(b)) return std::nullopt;   // started inside and left: nothing was entered
    // No path from outside to follow: take the face nearest to b (least depth; ties go to the
    // lower face index, so the choice is deterministic).
    int best = 0;
    double best_depth = kInfinity;
    for (int face = 0; face < 6; ++face) {
      const Face f = box_face(h, face);
      const double depth = f.offset - f.normal.dot(b);
      if (depth < best_depth) { best_depth = depth; best = face; }
    }
    Vec3 p = b;
    p[best / 2] = box_face(h, best).normal[best / 2] * h[best / 2];
    return BoxEntry{best, p, 0.0};
  }
  // Slab clipping of the path a + t (b - a), t in [0, 1]: it is inside the box while inside all
  // three slabs; it enters at the largest slab entry, through that slab's face, if that comes
  // before the smallest slab exit. b itself may lie beyond the box (a fast finger, a thin body):
  // the face is still the one entered, so the finger cannot tunnel through.
  const Vec3 d = b - a;
  double t_enter = -kInfinity, t_exit = kInfinity;
  int face = -1;
  for (int j = 0; j < 3; ++j) {
    if (d[j] == 0.0) {
      if (std::abs(a[j]) > h[j]) return std::nullopt;   // parallel to and outside this slab
      continue;
    }
    const bool rising = d[j] > 0.0;   // moving towards +j: enters through the -j face
    const double t_near = ((rising ? -h[j] : h[j]) - a[j]) / d[j];
    const double t_far = ((rising ? h[j] : -h[j]) - a[j]) / d[j];
    if (t_near > t_enter) {   // strict: a tie (entering through an edge) keeps the lower axis
      t_enter = t_near;
      face = 2 * j + (rising ? 1 : 0);
    }
    t_exit = std::min(t_exit, t_far);
  }
  // a is outside, so some slab is entered at t > 0; the path must reach it (t <= 1) and be in
  // all slabs at once (t_enter <= t_exit), and ahead of a, not behind it (t_exit >= 0: a finger
  // moving away from a face it has just left crosses the box only on the line behind it).
  if (face < 0 || t_enter > t_exit || t_enter > 1.0 || t_exit < 0.0) return std::nullopt;
  Vec3 p = a + t_enter * d;
  const int axis = face / 2;
  p[axis] = (face % 2 == 0 ? 1.0 : -1.0) * h[axis];   // exactly on the face plane
  for (int j = 0; j < 3; ++j) {
    if (j != axis) p[j] = std::clamp(p[j], -h[j], h[j]);   // rounding at an edge stays on the face
  }
  return BoxEntry{face, p, t_enter};
}

struct CollisionWorld::Impl {
  std::shared_ptr<detail::FclWorld> world;     // the bodies' FCL objects, shared with the contact gather (ContactGather)
  std::shared_ptr<fcl::Capsuled> path_shape;   // the finger path, resized per query
  std::unique_ptr<fcl::CollisionObjectd> path;
  std::vector<SurfaceGeometry> surfaces;   // same order as the bodies
};

CollisionWorld::CollisionWorld(const Model& model, std::shared_ptr<detail::FclWorld> world)
    : impl_(std::make_unique<Impl>()) {
  impl_->world = world ? std::move(world) : std::make_shared<detail::FclWorld>(model);
  for (const BodyParams& body : model.bodies) impl_->surfaces.emplace_back(body.shape);
  impl_->path_shape = std::make_shared<fcl::Capsuled>(1e-6, 0.0);
  impl_->path = std::make_unique<fcl::CollisionObjectd>(impl_->path_shape);
}

CollisionWorld::~CollisionWorld() = default;
CollisionWorld::CollisionWorld(CollisionWorld&&) noexcept = default;
CollisionWorld& CollisionWorld::operator=(CollisionWorld&&) noexcept = default;

void CollisionWorld::update(const Model& model, const State& state) { impl_->world->update_fast_loops(model, state); }

const SurfaceGeometry& CollisionWorld::surface(int body) const { return impl_->surfaces[body]; }

namespace {
// Broadphase callback: every body whose box AABB overlaps the path's is a candidate.
bool add_candidate(fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
  auto* out = static_cast<std::vector<int>*>(data);
  const fcl::CollisionObjectd* body = a->getUserData() ? a : b;   // the path has none
  out->push_back(static_cast<int>(reinterpret_cast<std::intptr_t>(body->getUserData())) - 1);
  return false;   // keep going
}
}  // namespace

void CollisionWorld::bodies_touching_segment(const Vec3& a, const Vec3& b, double radius,
                                             std::vector<int>& out) const {
  out.clear();
  // FCL's AABB tree finds the bodies whose bounding boxes the path's touch: a conservative
  // filter, allocation-free. box_entry() then decides exactly, so no GJK narrowphase is run.
  const Vec3 d = b - a;
  const double length = d.norm();
  impl_->path_shape->lz = length;
  impl_->path_shape->radius = radius + 1e-6;
  impl_->path_shape->computeLocalAABB();
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  if (length > 0.0) tf.linear() = Quat::FromTwoVectors(Vec3::UnitZ(), d).toRotationMatrix();
  tf.translation() = 0.5 * (a + b);
  impl_->path->setTransform(tf);
  impl_->path->computeAABB();
  impl_->world->broadphase.collide(impl_->path.get(), &out, add_candidate);
  // The tree's order depends on how it was built: sort, so that results never do.
  std::sort(out.begin(), out.end());
}

}  // namespace graspsim
