// The scale scenes in ODE 0.16 (Debian's libode-dev, double precision), as a new user sets them
// up from ODE's manual and demos:
//  - dWorldQuickStep, 20 iterations (ODE's default, set explicitly), SOR 1.3 (default);
//  - world ERP 0.2 and CFM 1e-10 (the double build's defaults, not set), no contact softness,
//    no bounce;
//  - dHashSpace with its default levels (dSimpleSpace tests every pair: quadratic in n);
//  - dCollide with at most 4 contacts per pair (box-box and box-plane);
//  - friction dContactApprox1 with mu = 0.6: the friction pyramid, each direction limited by
//    mu times that contact's normal force. Plain mu (no Approx1) would make mu a constant force
//    limit in N, 0.6 N against a 9.81 N weight;
//  - auto-disable off (ODE's default, set explicitly): every body is stepped at every step.
// The floor is a dPlane z = 0. A step is dSpaceCollide, dWorldQuickStep and emptying the
// contact group: what a user's loop does each step, all of it timed.
#include <ode/ode.h>

#include <algorithm>
#include <cstdarg>
#include <cstdio>

#include "peers.hpp"

namespace graspsim::bench::peers {
namespace {

constexpr int kMaxContacts = 4;   // 1: per pair of geoms

// ODE's error and debug handlers abort the process by default; a run that hits one fails.
void ode_error(int errnum, const char* msg, va_list ap) {
  char text[200];
  std::vsnprintf(text, sizeof text, msg, ap);
  fail_run("ode error " + std::to_string(errnum) + ": " + text);
}

int g_messages = 0;   // ODE's messages (warnings) during the run
void ode_message(int, const char*, va_list) { ++g_messages; }

class OdeWorld final : public World {
 public:
  explicit OdeWorld(const Scene& scene) : dt_(scene.dt) {
    dSetErrorHandler(ode_error);
    dSetDebugHandler(ode_error);
    dSetMessageHandler(ode_message);
    dInitODE2(0);
    world_ = dWorldCreate();
    dWorldSetGravity(world_, 0.0, 0.0, -scale::kGravity);
    dWorldSetQuickStepNumIterations(world_, 20);
    dWorldSetAutoDisableFlag(world_, 0);
    space_ = dHashSpaceCreate(nullptr);
    contacts_ = dJointGroupCreate(0);
    dCreatePlane(space_, 0.0, 0.0, 1.0, 0.0);
    for (const scale::BoxPose& pose : scene.boxes) {
      dBodyID body = dBodyCreate(world_);
      dMass mass;
      dMassSetBoxTotal(&mass, scale::kMass, scale::kSide, scale::kSide, scale::kSide);
      dBodySetMass(body, &mass);
      dBodySetPosition(body, pose.x, pose.y, pose.z);
      dMatrix3 r;
      dRFromAxisAndAngle(r, 0.0, 0.0, 1.0, pose.yaw);
      dBodySetRotation(body, r);
      dGeomID geom = dCreateBox(space_, scale::kSide, scale::kSide, scale::kSide);
      dGeomSetBody(geom, body);
      bodies_.push_back(body);
    }
  }

  ~OdeWorld() override {
    dJointGroupDestroy(contacts_);
    dSpaceDestroy(space_);   // destroys its geoms
    dWorldDestroy(world_);   // and its bodies
    dCloseODE();
  }

  void step() override {
    dSpaceCollide(space_, this, &OdeWorld::near);
    dWorldQuickStep(world_, dt_);
    dJointGroupEmpty(contacts_);
    most_contacts_ = std::max(most_contacts_, step_contacts_);
    step_contacts_ = 0;
  }

  void read(std::vector<BoxState>& out) const override {
    out.resize(bodies_.size());
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      const dReal* p = dBodyGetPosition(bodies_[i]);
      const dReal* v = dBodyGetLinearVel(bodies_[i]);
      const dReal* w = dBodyGetAngularVel(bodies_[i]);
      for (int k = 0; k < 3; ++k) {
        out[i].p[k] = p[k];
        out[i].v[k] = v[k];
        out[i].w[k] = w[k];
      }
    }
  }

  std::string notes() const override {
    char text[160];
    std::snprintf(text, sizeof text, "ERP %g CFM %g iterations %d SOR %g, most contacts in a step %d",
                  dWorldGetERP(world_), dWorldGetCFM(world_), dWorldGetQuickStepNumIterations(world_),
                  dWorldGetQuickStepW(world_), most_contacts_);
    return text;
  }

  std::string trouble() const override {
    return g_messages ? "ode: " + std::to_string(g_messages) + " messages" : std::string();
  }

 private:
  // Every pair of geoms whose bounding boxes overlap: up to 4 contacts, each a contact joint.
  static void near(void* data, dGeomID a, dGeomID b) {
    auto* self = static_cast<OdeWorld*>(data);
    dBodyID body_a = dGeomGetBody(a), body_b = dGeomGetBody(b);
    dContact contact[kMaxContacts] = {};
    const int count = dCollide(a, b, kMaxContacts, &contact[0].geom, sizeof(dContact));
    for (int i = 0; i < count; ++i) {
      contact[i].surface.mode = dContactApprox1;
      contact[i].surface.mu = scale::kMu;
      dJointID joint = dJointCreateContact(self->world_, self->contacts_, &contact[i]);
      dJointAttach(joint, body_a, body_b);
    }
    self->step_contacts_ += count;
  }

  double dt_;                     // s
  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contacts_ = nullptr;
  std::vector<dBodyID> bodies_;   // in Scene::boxes' order
  int step_contacts_ = 0;         // contact joints made in this step
  int most_contacts_ = 0;         // the most in one step so far
};

}  // namespace

std::unique_ptr<World> make_ode_world(const Scene& scene) { return std::make_unique<OdeWorld>(scene); }

}  // namespace graspsim::bench::peers
