// One FCL world of the bodies, shared by the fingers' path queries and body-body contact.
#include "fcl_world.hpp"

#include <cstdint>

#include "fcl_shape.hpp"
#include "graspsim/engine/local_model.hpp"

namespace graspsim::detail {

namespace {

// FCL keeps an object's box protected; a grown box is set through a derived type, the object
// created as one (FclWorld's constructor), so the cast is to its own type.
struct GrowableObject : fcl::CollisionObjectd {
  using fcl::CollisionObjectd::CollisionObjectd;
  void grow(double m) {
    aabb.min_ -= Vec3::Constant(m);
    aabb.max_ += Vec3::Constant(m);
  }
};

void place(fcl::CollisionObjectd& object, const Mat3& rotation, const Vec3& position, double margin = 0.0) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = rotation;
  tf.translation() = position;
  object.setTransform(tf);
  object.computeAABB();
  if (margin > 0.0) static_cast<GrowableObject&>(object).grow(margin);
}

}  // namespace

FclWorld::FclWorld(const Model& model) {
  std::vector<fcl::CollisionObjectd*> objects;
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    bodies.push_back(std::make_unique<GrowableObject>(fcl_geometry(model.bodies[i].shape)));
    bodies.back()->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(i + 1)));
    objects.push_back(bodies.back().get());
  }
  broadphase.registerObjects(objects);
  broadphase.setup();
}


void FclWorld::update(const State& state, const std::vector<double>* margin) {
  for (std::size_t i = 0; i < bodies.size(); ++i)
    place(*bodies[i], state.bodies[i].rotation, state.bodies[i].position, margin ? (*margin)[i] : 0.0);
  broadphase.update();
}

void FclWorld::update_fast_loops(const Model& model, const State& state) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Pose pose = fast_loop_pose(model, state.bodies[i], state.tick);
    place(*bodies[i], pose.rotation, pose.position);
  }
  broadphase.update();
}

}  // namespace graspsim::detail
