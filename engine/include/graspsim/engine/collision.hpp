// Collision queries: which bodies a finger's path touches (FCL), and the exact box geometry the
// god-object is constrained to (which face the path entered, where, and how deep).
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"
#include "graspsim/engine/surface.hpp"

namespace graspsim {

// A face plane of a box in the body frame: points x on the face satisfy normal . x = offset;
// normal points out of the box.
struct Face {
  Vec3 normal;     // 1, body frame
  double offset;   // m
};

// Face k of a box with half sizes h: 0..5 = +x, -x, +y, -y, +z, -z.
Face box_face(const Vec3& half_extents, int face);

// True when x (body frame) lies in the prism swept by face k along its normal, that is, its
// coordinates across the face are within the face's rectangle (edges included).
bool within_face(const Vec3& half_extents, int face, const Vec3& x);

// Where a finger path a -> b (body frame) enters a box.
struct BoxEntry {
  int face;       // entered face, 0..5
  Vec3 point;     // m, body frame: entry point on that face
  double t;       // 1: fraction of the path a -> b at entry (0 when a was already inside)
};

// Where the path a -> b first enters the box (surface included), else none. The face is the
// one the path crossed first: the one entered, not the nearest to b, which keeps a deep finger
// from pushing through to the far side; b may even lie beyond the box (a fast finger, a thin
// body) and the entered face is still found. When a is already inside (the body moved onto the
// finger, or the first tick), the face nearest to b is taken, if b is inside too.
std::optional<BoxEntry> box_entry(const Vec3& half_extents, const Vec3& a, const Vec3& b);

// FCL collision objects of the bodies, kept at the bodies' poses, in FCL's dynamic AABB tree.
namespace detail {
struct FclWorld;   // the bodies' FCL objects (engine/src/fcl_world.hpp)
}

class CollisionWorld {
 public:
  // With `world`, the bodies' FCL objects are that world's, shared (Simulation shares one with
  // its ContactGather); without, its own.
  explicit CollisionWorld(const Model& model, std::shared_ptr<detail::FclWorld> world = nullptr);
  ~CollisionWorld();
  CollisionWorld(CollisionWorld&&) noexcept;
  CollisionWorld& operator=(CollisionWorld&&) noexcept;

  // Moves the FCL objects to the bodies' poses as the fast loops see them at state.tick
  // (local_model.hpp: the physics poses under the paper's integrator).
  void update(const Model& model, const State& state);

  // Indices of the bodies whose bounding boxes the segment a -> b (world), swept by a sphere of
  // `radius` (m), touches, ascending, written into `out` (cleared first; no allocation once its
  // capacity suffices). A superset of the bodies the segment enters: box_entry() decides.
  void bodies_touching_segment(const Vec3& a, const Vec3& b, double radius, std::vector<int>& out) const;

  // Body b's shape with its surface queries' precomputed data (planes, neighbours).
  const SurfaceGeometry& surface(int body) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspsim
