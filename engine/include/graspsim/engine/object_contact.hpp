// Object contact: the paper's penalty "rotate down" contact of a body with the floor (section
// 4), one force per penetrating floor point, with damping so that energy is lost, and friction by
// a stick anchor per point (the friction circle of section 2, applied to object contact); and the
// same penalty law between bodies, point by point over a contact manifold (manifold.hpp).
#pragma once

#include <memory>
#include <vector>

#include "graspsim/engine/coupling.hpp"
#include "graspsim/engine/manifold.hpp"
#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

namespace detail {
struct FclWorld;   // the bodies' FCL objects (engine/src/fcl_world.hpp)
}

struct Wrench {
  Vec3 force{0.0, 0.0, 0.0};    // N, world
  Vec3 torque{0.0, 0.0, 0.0};   // N m, world, about the body's centre of mass
};

// The eight corners of a box in its body frame, in a fixed order (x fastest, then y, then z).
Vec3 box_vertex(const Vec3& half_extents, int k);

// Floor points per shape kind: box 8 corners; convex hull and mesh their vertices; sphere its
// lowest point; capsule the lowest points of its two end spheres; cylinder 12 points on each cap's
// rim (a 12-sided prism: caps of every orientation rest on them, exactly when lying flat).
inline constexpr int kCylinderRimPoints = 12;
int floor_point_count(const Shape& shape);

// m: how far from its centre of mass a body reaches the floor in any orientation: its farthest
// floor point (a rolling point is at radius r from a centre point; the capsule's at L + r).
double floor_reach(const Shape& shape);

// Floor point k of a body turned by `rotation`, as an offset (m, world) from its centre of mass.
// `rolling` says the point is not a fixed material point but the lowest point of a round surface
// (sphere, capsule end), which the body rolls over.
Vec3 floor_point(const Shape& shape, const Mat3& rotation, int k, bool& rolling);

// Floor wrench on body b at its current state, updating its points' friction anchors.
// For each floor point at depth d > 0 below the floor, whose material moves at u:
//   normal      f_n = max(0, k d - c u_n)                      (no pull)
//   friction    anchor a kept while |a - x_t| <= mu f_n / k, else moved onto that circle;
//               f_t = k (a - x_t) - c u_t, scaled down to |f_t| <= mu f_n
// where x_t is the material point projected on the floor and (k, c, mu) = contact_pair(body,
// floor). A rolling point's material point is the one under it at the last step; after the step
// the anchor is carried over to the new lowest point with the same stretch a - x_t, so a ball
// rolling without slip feels no friction and one that slides does.
// Returns the number of points in contact. With `points`, each point in contact is also appended
// to it with the force it gave (ContactRecord: a = kFloor, b = body).
int floor_contact(const Model& model, int body, BodyState& bs, Wrench& out,
                  std::vector<ContactRecord>* points = nullptr);

// The floor points of body b for the implicit step, appended to `out` as couplings (world side
// a = -1): the same law and anchors as floor_contact, but unclamped (the step's active set
// clamps), and a point also counts while it is above the floor by less than it can close in one
// step of length h, h (max(0, -u_n) + h |g|), so that a body arriving on the floor, or placed on
// it with no load yet, is stopped by the step that would carry it in. Updates the points' anchors
// as floor_contact does. `pair` is floor_pair(model, body); `radius` (m) is at least the body's
// floor_reach: how far its points are from its centre of mass. Returns how many were appended.
int floor_couplings(const Model& model, int body, const ContactPair& pair, BodyState& bs, double h, double radius,
                    std::vector<Coupling>& out);

// Body-body contact. Keeps its own FCL objects of the bodies (a dynamic AABB tree) for the
// broadphase. Pairs of polyhedra (box, convex) get a clipped manifold (manifold.hpp); every other
// pair (sphere, capsule, cylinder, mesh) gets FCL's contacts (collide with contacts; for meshes
// its BVH triangle contacts), sorted by position. Each point gets the floor's law: penalty
// f_n = max(0, k d - c u_n) with the two materials in series, friction by anchors that are a
// material point of each body (stick_slip_step), equal and opposite on the two bodies at the same
// point. A pair whose materials are both rigid (infinite stiffness or damping) does not collide
// (stability_warnings() says so).
class BodyContacts {
 public:
  // With `world`, the bodies' FCL objects are that world's, shared (Simulation shares one with
  // CollisionWorld); without, its own.
  explicit BodyContacts(const Model& model, std::shared_ptr<detail::FclWorld> world = nullptr);
  ~BodyContacts();
  BodyContacts(BodyContacts&&) noexcept;
  BodyContacts& operator=(BodyContacts&&) noexcept;

  // Adds every body-body contact wrench at the current state to `wrenches[b]` and the number of
  // contact points of b to `points[b]` (both sized to the bodies, not cleared), and updates the
  // pairs' friction anchors in `state.pairs`. Allocation-free for pairs of polyhedra. With
  // `records`, each point of a pair with an awake body is also appended to it with its force on
  // b (no allocation once it has held the most points of the run).
  void step(const Model& model, State& state, std::vector<Wrench>& wrenches, std::vector<int>& points,
            std::vector<ContactRecord>* records = nullptr);

  // The same contact points and anchors for the implicit step: each point appended to `out` as a
  // coupling (a < b, the normal from a towards b, the law unclamped), nothing summed.
  void couplings(const Model& model, State& state, std::vector<Coupling>& out, std::vector<int>& points);

  // The contact points of bodies a < b at `state` (no friction update), into `out` (capacity
  // kMaxPairPoints). For tests and energy accounting.
  int points(const Model& model, const State& state, int a, int b, ManifoldPoint* out);

 private:
  void run(const Model& model, State& state, std::vector<Wrench>* wrenches, std::vector<int>& points,
           std::vector<Coupling>* out, std::vector<ContactRecord>* records);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspsim
