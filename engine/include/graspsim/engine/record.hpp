// Records: write-only outputs of one servo tick. The engine fills them and never reads them back;
// recordings/ turns them into trace rows. Buffers are sized once (make_tick_record) so that the
// step allocates nothing.
#pragma once

#include <cstdint>
#include <vector>

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

// Device input of one finger for one servo tick.
struct FingerInput {
  Vec3 hip{0.0, 0.0, 0.0};      // m, world: haptic interface point
  Vec3 gimbal{0.0, 0.0, 0.0};   // rad: stylus gimbal angles (roll, pitch, yaw)
};

struct Input {
  std::vector<FingerInput> fingers;   // same order as Model::fingers
};

struct ServoFingerRecord {
  Vec3 hip{0.0, 0.0, 0.0};     // m, world
  Vec3 force{0.0, 0.0, 0.0};   // N, world: k (GO - HIP) demanded for the device (before clamping)
};

struct HapticFingerRecord {
  Vec3 god_object{0.0, 0.0, 0.0};      // m, world (= HIP when free)
  Vec3 surface_point{0.0, 0.0, 0.0};   // m, world: SP, the frictionless god-object on the contacted
                                       //    surface (= HIP free); on a face, the HIP's projection
  double depth = 0.0;                  // m: |SP - HIP|, the HIP's penetration (0 free)
  double friction_radius = 0.0;        // m: mu * depth
  Vec3 force{0.0, 0.0, 0.0};           // N, world: force on the finger (the servo force of this tick)
  ContactPhase phase = ContactPhase::kFree;
  int body = kNoBody;                  // contacted body index, kFloor or kNoBody
  double slip = 0.0;                   // m: distance the GO moved over the surface this tick
};

struct BodyRecord {
  Vec3 position{0.0, 0.0, 0.0};           // m, world
  Quat orientation = Quat::Identity();    // 1: body to world, w >= 0
  Vec3 velocity{0.0, 0.0, 0.0};           // m/s, world
  Vec3 angular_velocity{0.0, 0.0, 0.0};   // rad/s, world
  Vec3 force{0.0, 0.0, 0.0};              // N, world: residual force applied this step
  Vec3 torque{0.0, 0.0, 0.0};             // N m, world: residual torque about the centre of mass
  int floor_contacts = 0;                 // 1: floor points (vertices) touching the floor
  int body_contacts = 0;                  // 1: contact points with other bodies
  double grasp_area = 0.0;                // m^2: friction-circle area A of a two-finger grasp
                                          //      (0 when not held by exactly two fingers)
  double torsion = 0.0;                   // N m: gravity-drop torque about the grasp axis
  double twist = 0.0;                     // rad: turned about the grasp axis by the gimbal or
                                          //      the quasi-static gravity drop
};

// One contact point of the bodies at a physics step: a floor point or a body-body point, with the
// force the step applied there (paper: the clamped spring-damper; implicit: the solved force at
// the end of the step).
struct ContactRecord {
  int a = kFloor;                    // body pushed by -force (of a pair, the lower index), or kFloor
  int b = 0;                         // body pushed by +force
  Vec3 point{0.0, 0.0, 0.0};         // m, world: where the force acts
  Vec3 normal{0.0, 0.0, 1.0};        // 1, world, unit: from a towards b (the floor's points up)
  Vec3 force{0.0, 0.0, 0.0};         // N, world: on b (-force on a)
};

struct TickRecord {
  std::int64_t tick = 0;   // servo tick this record belongs to
  bool haptic_ran = false;
  bool physics_ran = false;
  std::vector<ServoFingerRecord> servo;     // per finger, every tick
  std::vector<HapticFingerRecord> haptic;   // per finger, valid when haptic_ran
  std::vector<BodyRecord> physics;          // per body, valid when physics_ran
  std::vector<ContactRecord> contacts;      // valid when physics_ran, filled only when the
                                            // Simulation records contacts (record_contacts): the contact points of the
                                            // awake bodies in the step's order (the count of
                                            // each kind per body is BodyRecord's), cleared and
                                            // refilled each physics step: no allocation once
                                            // it has held the most points of the run
  int diverged_body = -1;                   // first body whose state this tick is not finite or
                                            // faster than kDivergedSpeed / kDivergedAngularSpeed
                                            // (the integration diverged), else -1
};

TickRecord make_tick_record(const Model& model);
Input make_input(const Model& model);

}  // namespace graspsim
