// Model: everything constant during a run (MuJoCo's mjModel). Stages take `const Model&`.
// SI units throughout; each field says its unit.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/shape.hpp"

namespace graspsim {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A body faster than this has left any range a grasping scene reaches: the explicit integration
// has diverged (an unstable penalty contact launches bodies at km/s in one step before their
// state overflows). The step flags it so that the run stops instead of finishing and "passing".
inline constexpr double kDivergedSpeed = 1e3;          // m/s
inline constexpr double kDivergedAngularSpeed = 1e4;   // rad/s

// Loop rates. Each must divide `servo`; the scheduler runs on the servo tick.
struct Rates {
  int servo = 3000;   // Hz: device read and force render
  int haptic = 500;   // Hz: finger contact (friction cone)
  int physics = 50;   // Hz: object contacts and rigid-body integration
};

// Surface material. A contact between two surfaces combines them (see contact_pair()).
struct Material {
  double mu = 0.5;                // 1: static friction coefficient (friction-circle radius / depth
                                  //    while sticking)
  double stiffness = kInfinity;   // N/m: penalty stiffness of the surface layer (per contact point)
  double damping = kInfinity;     // N s/m: damping of the surface layer (per contact point)
  double mu_kinetic = -1.0;       // 1: kinetic friction coefficient while slipping, <= mu;
                                  //    < 0 means equal to mu (no static peak)
  double viscous = 0.0;           // N s/m: viscous friction while slipping, added as c v_slip
};

// The kinetic coefficient a material slips with (mu when mu_kinetic is unset).
inline double kinetic_mu(const Material& m) { return m.mu_kinetic < 0.0 ? m.mu : m.mu_kinetic; }

// The parameters of one contact between two materials: the surface layers act as springs and
// dampers in series (1/k = 1/k_a + 1/k_b), friction coefficients are the lower of the two, and
// viscous friction the higher, so an unset side (infinite stiffness, damping or mu; zero
// viscous) leaves the other one in charge.
struct ContactPair {
  double mu;           // 1: static
  double mu_kinetic;   // 1: while slipping
  double stiffness;    // N/m
  double damping;      // N s/m
  double viscous;      // N s/m: while slipping
  // The friction coefficient of a contact that is slipping or not.
  double friction(bool slipping) const { return slipping ? mu_kinetic : mu; }
};
ContactPair contact_pair(const Material& a, const Material& b);

// The contact law the implicit integrator gives a contact whose materials leave stiffness or
// damping unset (infinite on both sides), from the mass m it moves (a body's on the floor, the
// reduced mass m_a m_b / (m_a + m_b) of two bodies) and the physics rate f (engine/README.md,
// "Default contact"):
//   k = m (4 pi f)^2 per point   the contact's natural period is half a physics step, so a body
//                                resting on one point sinks g / (4 pi f)^2 (25 um at 50 Hz,
//                                0.03 um at 3 kHz) and on four points a quarter of that; its
//                                friction anchors give as little under a sideways load
//   c = 2 sqrt(k m)              critical damping of that spring
// Stiffer than any explicit step could take (h^2 k / m = 4 pi^2 > 4 at every rate): the implicit
// step's damping of modes it cannot resolve keeps it quiet. A value set on either side is kept.
// Under the paper's integrator nothing is filled in.
ContactPair with_default_law(const ContactPair& pair, double mass, int physics_rate);

struct BodyParams {
  std::string name;
  Shape shape = box_shape(Vec3(0.05, 0.05, 0.05));   // in the body frame
  double mass = 1.0;                            // kg
  Vec3 inertia{1.0, 1.0, 1.0};                  // kg m^2: principal moments Jp (body axes)
  Material material;
  // Initial conditions (constant inputs; the State starts from them).
  Vec3 position{0.0, 0.0, 0.0};                 // m: centre of mass in world
  Quat orientation = Quat::Identity();          // 1: body to world rotation
  Vec3 velocity{0.0, 0.0, 0.0};                 // m/s
  Vec3 angular_velocity{0.0, 0.0, 0.0};         // rad/s, world frame
};

struct FingerParams {
  std::string name;
  double stiffness = 500.0;   // N/m: virtual coupling between HIP and god-object (finger pad)
  double damping = 0.0;       // N s/m: damping of that coupling on the GO-HIP relative velocity
                              //        (0 is the paper's pure spring)
  double radius = 0.0;        // m: finger pad radius; the HIP is the pad's centre (0: a point)
};

struct FloorParams {
  bool enabled = false;
  double height = 0.0;        // m: the plane z = height, normal +z
  Material material{1.0, kInfinity, kInfinity};
};

// How Euler's equation treats the gyroscopic term w x (J w) (paper, section 3.1).
enum class Gyroscopic {
  kNeglect,    // the paper's approximation for small w: w_dot = R Jp^-1 R^T T
  kExplicit,   // w_dot = J^-1 (T - w x J w), evaluated at the start of the step
  kImplicit,   // one Newton step of implicit Euler on the body-frame Euler equation (no energy
               // gain from the gyroscopic term while dt |w| <= J_min / (2 J_max))
};

// How a physics step moves the bodies (engine/README.md, "Integrators").
enum class Integrator {
  kPaper,      // the paper's explicit step (section 3.1): the residual force and torque at the
               // start of the step, then v, p, w, R updated in turn; stable only while every
               // coupled mode of a body on its springs is (stability.hpp)
  kImplicit,   // linearly implicit: each body, and each group of bodies in contact, over all of
               // its spring-damper couplings at once (fingers, floor, other bodies); passive for
               // any stiffness, damping and physics rate
};

// Rotation about the axis through the god-objects of a two-finger grasp (paper, section 3.2).
enum class Torsion {
  kNone,          // only the residual torque acts (the fingers' forces, gravity at the centre)
  kGravityDrop,   // A < A_crit: gravity turns the body about the axis, scaled by (1 - A/A_crit);
                  // A >= A_crit: no rotation about the axis
  kGimbal,        // A > A_crit: the gimbal pitch of `gimbal_finger` turns the body about the axis
};

struct GraspParams {
  Torsion torsion = Torsion::kNone;
  double critical_area = 0.0;   // m^2: A_crit, friction-circle area (pi r^2 of the smaller circle
                                //      of the two fingers) at which the grasp resists torsion
  int gimbal_finger = -1;       // index into Model::fingers whose gimbal pitch turns the body
  double dead_band = 0.0;       // N m: T_crit; a residual torque |T| <= T_crit is set to zero
                                //      (paper, section 5), 0 for none
  double torsional_damping = 0.0;   // N m s/rad: c_t, the finger pads' torsional friction about
                                    //      the grasp axis with gravity drop; > 0 makes the turn
                                    //      quasi-static, w_u = T_u / c_t each physics step (see
                                    //      engine/README.md); 0: the inertial swing w_u += dt T_u / J
};

// Sleeping (engine/README.md, "Sleep"): a body whose speeds stay under both thresholds for
// `time` (counted in physics ticks: ceil(time x physics rate)) stops being stepped, its pose
// frozen and its velocities zero, until a finger touches it or a moving body reaches it.
struct SleepParams {
  bool enabled = false;          // off by default: on changes the traces of resting bodies
  double linear_speed = 1e-3;    // m/s: |v| at or under this counts as still
  double angular_speed = 1e-2;   // rad/s: |w| at or under this counts as still
  double time = 0.5;             // s: how long a body stays still before it sleeps
};

struct Model;
// The contact law of body b on the floor, and of bodies a and b, with the implicit integrator's
// defaults filled in (with_default_law).
ContactPair floor_pair(const Model& model, int body);
ContactPair body_pair(const Model& model, int a, int b);

struct Model {
  Rates rates;
  SleepParams sleep;
  Integrator integrator = Integrator::kPaper;
  int implicit_order = 2;     // under kImplicit: 2, BDF2 restarted by backward Euler wherever an
                              // island's contacts change (island_solve.hpp); 1, backward Euler
  bool local_model = false;   // under kImplicit: the fast loops see each body move on between
                              // physics steps (local_model.hpp); else they see its last pose
  Gyroscopic gyroscopic = Gyroscopic::kNeglect;
  GraspParams grasp;
  Vec3 gravity{0.0, 0.0, -9.81};   // m/s^2
  FloorParams floor;
  std::vector<BodyParams> bodies;
  std::vector<FingerParams> fingers;
};

// Divisors of the servo rate, derived once from the rates.
struct Divisors {
  std::int64_t haptic;    // servo ticks per haptic tick
  std::int64_t physics;   // servo ticks per physics tick
};

// Checks the model and throws std::invalid_argument naming the offending field.
void validate(const Model& model);

// Warnings, one sentence each, for contacts stiff or damped enough to make the paper's explicit
// integration unstable at the model's physics rate (estimates per kind of spring, before a run;
// see model.cpp), and for pairs of bodies that cannot collide. The coupled modes of the contact
// set a run reaches are stability.hpp's.
std::vector<std::string> stability_warnings(const Model& model);
Divisors divisors(const Rates& rates);

// Principal moments of a solid box of mass m and half sizes h: J_x = m/3 (h_y^2 + h_z^2), etc.
Vec3 box_inertia(double mass, const Vec3& half_extents);

}  // namespace graspsim
