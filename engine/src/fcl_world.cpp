// One FCL world of the bodies, shared by the fingers' path queries and body-body contact.
#include "fcl_world.hpp"

#include <cstdint>

#include "fcl_shape.hpp"

namespace graspsim::detail {

FclWorld::FclWorld(const Model& model) {
  std::vector<fcl::CollisionObjectd*> objects;
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    bodies.push_back(std::make_unique<fcl::CollisionObjectd>(fcl_geometry(model.bodies[i].shape)));
    bodies.back()->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(i + 1)));
    objects.push_back(bodies.back().get());
  }
  broadphase.registerObjects(objects);
  broadphase.setup();
}

void FclWorld::update(const State& state) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.linear() = state.bodies[i].rotation;
    tf.translation() = state.bodies[i].position;
    bodies[i]->setTransform(tf);
    bodies[i]->computeAABB();
  }
  broadphase.update();
}

}  // namespace graspsim::detail
