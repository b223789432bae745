// The contact points of two bodies, chosen by the kinds of their shapes (private to the engine).
//
// One method per pair of contact kinds, in a table (kMethods):
//   polyhedron-polyhedron   our manifold (manifold.hpp): separating axes, clipped faces; a box,
//                           a convex hull, and a cylinder as the 12-sided prism of its floor points
//   sphere-mesh             our closest point per triangle (Ericson 5.1.5)
//   mesh-mesh               none: FCL's triangle contacts push apart bodies 0.06-0.5 mm apart
//                           and add energy; stability_warnings() says such a pair passes through
//   any other               FCL's collide with contacts (meshes: its BVH triangle contacts), sorted;
//                           short of touching, FCL's distance gives the one nearest pair of points
// Every method takes a margin: points up to `margin` apart are returned too, with a negative depth
// (the implicit step's points that the step may reach, contact_gather.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include "fcl_world.hpp"
#include "graspsim/engine/manifold.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim::detail {

// A feature key from small integers (boost::hash_combine's rule): the same features give the same
// key at every step and on every machine.
inline std::uint64_t combine_key(std::uint64_t h, std::uint64_t v) {
  return h ^ (v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
}

class Narrowphase {
 public:
  // The bodies' FCL objects come from `world` (their transforms are set by FclWorld::update or by
  // place() here before an FCL method runs).
  Narrowphase(const Model& model, std::shared_ptr<FclWorld> world);

  // The points of bodies a < b at `state` closer than `margin` (m, >= 0), normals from a towards
  // b, depth > -margin, in a fixed order with feature keys; at most kMaxPairPoints. Returns the
  // count written to `out`. `placed`: the FCL objects already stand at `state`'s poses.
  int find(const State& state, int a, int b, double margin, bool placed, ManifoldPoint* out);

  // Whether a and b have a method at all (mesh against mesh has none).
  bool can_touch(int a, int b) const;

 private:
  enum class Kind : std::uint8_t { kPolyhedron, kSphere, kMesh, kOther };
  enum class Method : std::uint8_t { kNone, kManifold, kSphereMesh, kMeshSphere, kFcl };
  static constexpr int kKinds = 4;
  static const std::array<std::array<Method, kKinds>, kKinds> kMethods;

  struct Body {
    Kind kind = Kind::kOther;
    fcl::CollisionObjectd* object = nullptr;          // the world's (user data: body index + 1)
    std::shared_ptr<const ConvexPolyhedron> hull;     // kPolyhedron
    HullEdges edges;
    std::shared_ptr<const TriangleMesh> mesh;         // kMesh
    std::vector<Vec3> triangle_normals;               // 1, body frame, outward: kMesh
    double sphere_radius = 0.0;                       // m: kSphere
  };

  int fcl_points(const State& state, int a, int b, double margin, ManifoldPoint* out);
  int sphere_mesh(const BodyState& sm, int m, const Vec3& centre_world, double r, bool mesh_is_b, double margin,
                  ManifoldPoint* out);
  int finish(int n, double margin, ManifoldPoint* out);

  std::shared_ptr<FclWorld> world_;
  std::vector<Body> bodies_;
  ManifoldScratch scratch_;
  std::array<Vec3, kMaxPairPoints> scratch_q_{};   // m, mesh frame: sphere_mesh's closest points
  fcl::CollisionRequestd request_;
  fcl::CollisionResultd result_;
  fcl::DistanceRequestd distance_request_;
  fcl::DistanceResultd distance_result_;
};

}  // namespace graspsim::detail
