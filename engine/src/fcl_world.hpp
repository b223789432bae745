// The bodies as FCL objects in one dynamic AABB tree (private to the engine): what a free
// finger's path asks (CollisionWorld) and what the body-body broadphase and narrowphase ask
// (ContactGather), one set of objects for both.
#pragma once

#include <memory>
#include <vector>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/narrowphase/collision_object.h>

#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim::detail {

struct FclWorld {
  explicit FclWorld(const Model& model);

  // Moves the objects to the bodies' poses in `state` and refits the tree. Queries sort what
  // they find, so results never depend on the tree's shape, which follows its update history.
  // With `margin` (m, per body), each box is grown by it on every side: two bodies whose boxes
  // then overlap are within the sum of their margins (the implicit step's reach, contact_gather.hpp).
  void update(const State& state, const std::vector<double>* margin = nullptr);
  // The same with the poses the fast loops see at state.tick (local_model.hpp).
  void update_fast_loops(const Model& model, const State& state);

  std::vector<std::unique_ptr<fcl::CollisionObjectd>> bodies;   // user data: body index + 1
  fcl::DynamicAABBTreeCollisionManagerd broadphase;
};

}  // namespace graspsim::detail
