// Collision queries: FCL finds the bodies a finger's path touches; the box geometry that the
// god-object is constrained to is exact and analytic.
#include "graspsim/engine/collision.hpp"

#include <algorithm>
#include <cmath>

#include <fcl/narrowphase/collision.h>
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
  for (int j = 0; j < 3; ++j) {
    if (std::abs(b[j]) > h[j]) return std::nullopt;   // b is outside: no contact now
  }
  const bool a_inside = std::abs(a.x()) <= h.x() && std::abs(a.y()) <= h.y() && std::abs(a.z()) <= h.z();
  if (a_inside) {
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
  // Slab method: the path enters the box when it has crossed into every slab; the last slab it
  // enters decides the face. Axes along which the path does not move cannot be entered.
  const Vec3 d = b - a;
  double t_enter = -kInfinity;
  int face = -1;
  for (int j = 0; j < 3; ++j) {
    if (d[j] == 0.0) continue;
    const bool rising = d[j] > 0.0;   // moving towards +j: enters through the -j face
    const double t = ((rising ? -h[j] : h[j]) - a[j]) / d[j];
    if (t > t_enter) { t_enter = t; face = 2 * j + (rising ? 1 : 0); }
  }
  // a outside and b inside means some axis moved and its slab was entered within [0, 1].
  t_enter = std::clamp(t_enter, 0.0, 1.0);
  Vec3 p = a + t_enter * d;
  const int axis = face / 2;
  p[axis] = (face % 2 == 0 ? 1.0 : -1.0) * h[axis];   // exactly on the face plane
  for (int j = 0; j < 3; ++j) {
    if (j != axis) p[j] = std::clamp(p[j], -h[j], h[j]);   // rounding at an edge stays on the face
  }
  return BoxEntry{face, p, t_enter};
}

struct CollisionWorld::Impl {
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> bodies;
  std::shared_ptr<fcl::Capsuled> path_shape;   // the finger path, resized per query
  std::unique_ptr<fcl::CollisionObjectd> path;
};

CollisionWorld::CollisionWorld(const Model& model) : impl_(std::make_unique<Impl>()) {
  for (const BodyParams& b : model.bodies) {
    const Vec3 size = 2.0 * b.half_extents;
    auto shape = std::make_shared<fcl::Boxd>(size.x(), size.y(), size.z());
    impl_->bodies.push_back(std::make_unique<fcl::CollisionObjectd>(shape));
  }
  impl_->path_shape = std::make_shared<fcl::Capsuled>(1e-6, 0.0);
  impl_->path = std::make_unique<fcl::CollisionObjectd>(impl_->path_shape);
}

CollisionWorld::~CollisionWorld() = default;
CollisionWorld::CollisionWorld(CollisionWorld&&) noexcept = default;
CollisionWorld& CollisionWorld::operator=(CollisionWorld&&) noexcept = default;

void CollisionWorld::update(const State& state) {
  for (std::size_t i = 0; i < impl_->bodies.size(); ++i) {
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.linear() = state.bodies[i].rotation;
    tf.translation() = state.bodies[i].position;
    impl_->bodies[i]->setTransform(tf);
    impl_->bodies[i]->computeAABB();
  }
}

void CollisionWorld::bodies_touching_segment(const Vec3& a, const Vec3& b, std::vector<int>& out) const {
  out.clear();
  // The path as a capsule of 1 um radius: a conservative filter; box_entry() then decides exactly.
  const Vec3 d = b - a;
  const double length = d.norm();
  impl_->path_shape->lz = length;
  impl_->path_shape->computeLocalAABB();
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  if (length > 0.0) tf.linear() = Quat::FromTwoVectors(Vec3::UnitZ(), d).toRotationMatrix();
  tf.translation() = 0.5 * (a + b);
  impl_->path->setTransform(tf);
  impl_->path->computeAABB();
  const fcl::CollisionRequestd request;   // yes/no, no contact points
  for (std::size_t i = 0; i < impl_->bodies.size(); ++i) {
    fcl::CollisionResultd result;
    if (fcl::collide(impl_->path.get(), impl_->bodies[i].get(), request, result) > 0)
      out.push_back(static_cast<int>(i));   // visited in index order: already sorted
  }
}

}  // namespace graspsim
