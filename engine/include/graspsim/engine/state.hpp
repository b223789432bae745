// State: exactly what carries from one servo tick to the next. Saving it (with the Model)
// is enough to resume a run; anything not here is recomputed by the step.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/surface.hpp"

namespace graspsim {

inline constexpr int kNoBody = -1;   // FingerState::body when the finger touches nothing
inline constexpr int kFloor = -2;    // FingerState::body when the finger touches the floor

// Friction-cone phase of a finger (traced as 0, 1, 2).
enum class ContactPhase : std::int8_t { kFree = 0, kStick = 1, kSlip = 2 };

struct FingerState {
  Vec3 hip_at_last_servo{0.0, 0.0, 0.0};    // m, world: HIP of the previous servo tick
  Vec3 hip_at_last_haptic{0.0, 0.0, 0.0};   // m, world: HIP used by the previous haptic tick
  bool has_last_haptic = false;             // false until the first haptic tick
  ContactPhase phase = ContactPhase::kFree;
  int body = kNoBody;                       // index into Model::bodies, kFloor or kNoBody
  Features features;                        // the contact's feature / constraint set (surface.hpp:
                                            //    box face 0..5 = +x,-x,+y,-y,+z,-z; floor 0)
  Vec3 surface_point{0.0, 0.0, 0.0};        // m: SP, the frictionless god-object, at the last
                                            //    haptic tick, in the contact frame (the walk's start)
  Vec3 normal{0.0, 0.0, 1.0};               // 1: contact normal at SP at the last haptic tick, unit,
                                            //    out of the surface, in the contact frame
  Vec3 god_object{0.0, 0.0, 0.0};           // m: GO in the contacted body's frame (world for the
                                            //    floor), so it rides with the body
  double viscous_force = 0.0;               // N: viscous part of the sliding force at the last
                                            //    haptic tick (the servo force may carry it too)
  double friction_mu = 0.0;                 // 1: friction coefficient applied at the last haptic
                                            //    tick (mu_s sticking or breaking away, else mu_k)
  double friction_radius = 0.0;             // m: the friction circle's radius at the last haptic
                                            //    tick (static or kinetic, as the phase was)
  double pitch_at_last_physics = 0.0;       // rad: gimbal pitch at the previous physics step
  bool has_pitch = false;                   // false until the first physics step
  Vec3 hip_at_last_physics{0.0, 0.0, 0.0};  // m, world: HIP at the previous physics step (implicit
                                            //    integrator: the HIP's velocity over the window)
  Vec3 window_force{0.0, 0.0, 0.0};         // N, world: this finger's force on its body summed over
                                            //    the current physics window (implicit integrator)
  bool has_last_physics = false;            // false until the first physics step (always, under
                                            //    the paper's integrator, which does not use it)
};

// One floor point of a body (a vertex, or the lowest point of a sphere) against the floor: its
// friction anchor (the paper's god-object idea applied to object contact) while it penetrates.
struct VertexContact {
  bool active = false;
  bool slipping = false;          // the anchor moved at the last step: kinetic friction applies
  Vec3 anchor{0.0, 0.0, 0.0};   // m, world: where the point stuck to the floor
  Vec3 material{0.0, 0.0, 0.0};   // m, body frame: the body's material point under a rolling
                                  //    contact (sphere, capsule end) at the last step
};

// One point of a contact manifold between two bodies A < B: its friction anchor, as a material
// point of each body, kept from step to step while the same features touch (matched by key).
struct PairPointContact {
  std::uint64_t key = 0;          // feature id (manifold.hpp)
  bool slipping = false;          // the anchors slid at the last step: kinetic friction applies
  Vec3 anchor_a{0.0, 0.0, 0.0};   // m, A's body frame: A's stuck point
  Vec3 anchor_b{0.0, 0.0, 0.0};   // m, B's body frame: B's stuck point
};

inline constexpr int kMaxPairPoints = 16;   // contact points kept per body pair

// The contact of two bodies a < b (by index) at the last physics step: its points' anchors.
struct PairContact {
  int a = 0, b = 0;                                    // body indices, a < b
  int count = 0;                                       // points found at the last step (> 0)
  std::array<PairPointContact, kMaxPairPoints> points{};
};

struct BodyState {
  Vec3 position{0.0, 0.0, 0.0};           // m: centre of mass, world
  Mat3 rotation = Mat3::Identity();       // 1: body to world (R = [n o a])
  Vec3 velocity{0.0, 0.0, 0.0};           // m/s, world
  Vec3 angular_velocity{0.0, 0.0, 0.0};   // rad/s, world
  // The pose before the last physics step: a free finger's path since its last haptic tick is
  // taken relative to the body, so a body that moved onto a resting finger is entered through
  // the face its motion brought to the finger.
  Vec3 position_before_step{0.0, 0.0, 0.0};       // m, world
  Mat3 rotation_before_step = Mat3::Identity();   // 1: body to world
  std::int64_t stepped_at = -1;                   // servo tick of the last physics step (-1: none)
  // The last implicit step, for the next one's BDF2 (island_solve.hpp, StepHistory): the
  // velocities at its start, and its island's couplings and their modes (0: none, a restart).
  Vec3 velocity_before_step{0.0, 0.0, 0.0};           // m/s, world
  Vec3 angular_velocity_before_step{0.0, 0.0, 0.0};   // rad/s, world
  std::uint64_t island_signature = 0;                 // 1
  int island_steps = 0;                               // 1: physics steps in a row with that signature
  bool asleep = false;       // sleeping: not stepped, pose frozen, velocities zero (Model::sleep)
  int still_steps = 0;       // 1: physics steps in a row with |v| and |w| under the sleep thresholds
  std::vector<VertexContact> floor_contacts;   // one per floor point of the shape (floor_points.hpp),
                                               // sized by initial_state
  // Finger wrench accumulated over the current physics window (sum over servo ticks).
  Vec3 window_force{0.0, 0.0, 0.0};       // N (summed; divided by servo/physics ticks)
  Vec3 window_torque{0.0, 0.0, 0.0};      // N m about the centre of mass (summed)
};

struct State {
  std::int64_t tick = 0;              // servo ticks done; time = tick / servo rate
  std::vector<BodyState> bodies;      // same order as Model::bodies
  std::vector<FingerState> fingers;   // same order as Model::fingers
  std::vector<PairContact> pairs;     // the pairs of bodies with contact points at the last physics
                                      // step, sorted by (a, b): memory grows with the contacts, not
                                      // with the square of the bodies
};

// The contact of bodies a < b in `state.pairs`, or nullptr when they had no points at the last step.
const PairContact* find_pair(const State& state, int a, int b);

// Wakes a sleeping body (no-op when awake): it is stepped again from rest, counting anew.
inline void wake(BodyState& body) {
  body.asleep = false;
  body.still_steps = 0;
}

// The state at t = 0 given by the model's initial conditions.
State initial_state(const Model& model);

}  // namespace graspsim
