// The scale scenes in Bullet 3.24 (Debian's libbullet-dev, single precision: the `bullet`
// pkg-config module a new user gets; `bullet-float64` is the double one), set up as Bullet's
// hello-world example does:
//  - btDiscreteDynamicsWorld with btDefaultCollisionConfiguration, btCollisionDispatcher,
//    btDbvtBroadphase and btSequentialImpulseConstraintSolver, the solver's defaults (10
//    iterations, warm starting 0.85; a contact's penetration corrected through its velocity
//    with ERP 0.2 down to 4 cm deep, by split impulse past that);
//  - each box a btBoxShape of half extent 5 cm with its default collision margin: 0.04 m cut to
//    a tenth of the smallest half extent by the shape's setSafeMargin, so 5 mm, inside the
//    extents (the box is its full size); mass 1 kg, inertia from the shape (m s^2 / 6);
//  - the floor a static btStaticPlaneShape z = 0;
//  - friction 0.6 for every contact: Bullet multiplies the two objects' frictions, so each
//    object, floor included, has sqrt(0.6); restitution 0 (the product of the default 0);
//  - deactivation disabled on every box (DISABLE_DEACTIVATION), so resting boxes are stepped
//    and the step's real work is timed; --sleep leaves Bullet's default deactivation on.
// A step is stepSimulation(dt, 1, dt): exactly one internal step of dt (the default fixed step
// is 1/60 s, and stepSimulation(dt) alone would interpolate instead of stepping).
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "peers.hpp"

namespace graspsim::bench::peers {
namespace {

class BulletWorld final : public World {
 public:
  explicit BulletWorld(const Scene& scene)
      : dt_(scene.dt),
        dispatcher_(&configuration_),
        world_(&dispatcher_, &broadphase_, &solver_, &configuration_),
        box_(btVector3(0.5 * scale::kSide, 0.5 * scale::kSide, 0.5 * scale::kSide)),
        plane_(btVector3(0, 0, 1), 0) {
    const btScalar friction = std::sqrt(scale::kMu);   // squared by Bullet's pair rule
    world_.setGravity(btVector3(0, 0, -scale::kGravity));
    btRigidBody::btRigidBodyConstructionInfo floor_info(0, nullptr, &plane_);
    floor_info.m_friction = friction;
    floor_ = std::make_unique<btRigidBody>(floor_info);
    world_.addRigidBody(floor_.get());
    btVector3 inertia;
    box_.calculateLocalInertia(scale::kMass, inertia);
    for (const scale::BoxPose& pose : scene.boxes) {
      btTransform start(btQuaternion(btVector3(0, 0, 1), pose.yaw), btVector3(pose.x, pose.y, pose.z));
      motions_.push_back(std::make_unique<btDefaultMotionState>(start));
      btRigidBody::btRigidBodyConstructionInfo info(scale::kMass, motions_.back().get(), &box_, inertia);
      info.m_friction = friction;
      info.m_restitution = 0;
      bodies_.push_back(std::make_unique<btRigidBody>(info));
      if (!scene.sleep) bodies_.back()->setActivationState(DISABLE_DEACTIVATION);
      world_.addRigidBody(bodies_.back().get());
    }
  }

  ~BulletWorld() override {
    for (auto& body : bodies_) world_.removeRigidBody(body.get());
    world_.removeRigidBody(floor_.get());
  }

  void step() override {
    world_.stepSimulation(dt_, 1, dt_);
    most_manifolds_ = std::max(most_manifolds_, dispatcher_.getNumManifolds());
  }

  std::string notes() const override {
    return "margin " + std::to_string(box_.getMargin()) + " iterations " +
           std::to_string(const_cast<btDiscreteDynamicsWorld&>(world_).getSolverInfo().m_numIterations) +
           " most contact manifolds " + std::to_string(most_manifolds_);
  }

  void read(std::vector<BoxState>& out) const override {
    out.resize(bodies_.size());
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      const btVector3& p = bodies_[i]->getCenterOfMassPosition();
      const btVector3& v = bodies_[i]->getLinearVelocity();
      const btVector3& w = bodies_[i]->getAngularVelocity();
      for (int k = 0; k < 3; ++k) {
        out[i].p[k] = p[k];
        out[i].v[k] = v[k];
        out[i].w[k] = w[k];
      }
    }
  }

 private:
  btScalar dt_;   // s
  btDefaultCollisionConfiguration configuration_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  btDiscreteDynamicsWorld world_;
  btBoxShape box_;              // shared by every box
  btStaticPlaneShape plane_;
  std::unique_ptr<btRigidBody> floor_;
  std::vector<std::unique_ptr<btDefaultMotionState>> motions_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;   // in Scene::boxes' order
  int most_manifolds_ = 0;                              // contact manifolds after a step, the most so far
};

}  // namespace

std::unique_ptr<World> make_bullet_world(const Scene& scene) { return std::make_unique<BulletWorld>(scene); }

}  // namespace graspsim::bench::peers
