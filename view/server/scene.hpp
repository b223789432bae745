// What the viewer draws of a trace: the scenario's floor, bodies and fingers (from the trace's
// own scenario_source and overrides) and the columns the page animates, read through
// recordings/ (HDF5 stays there). view/README.md says why the server reads the trace.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspsim/engine/model.hpp"
#include "graspsim/engine/shape.hpp"

namespace graspsim::view {

// The trace cannot be shown (a missing file, not a trace, no physics row): a message naming the
// file and what is wrong. `graspsim view` exits 2 with it.
class ViewError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct BodyView {
  std::string name;
  bool shape_known = false;       // false: the scenario did not load; the page draws a placeholder
  Shape shape;                    // body frame (origin at the centre of mass)
  std::vector<double> position;   // m, world: 3 per /physics row (centre of mass)
  std::vector<double> quaternion; // 1: 4 per /physics row, w, x, y, z, body to world
  // Per /physics row, for the time series and the grasp axis (0 where the trace lacks the column):
  std::vector<double> grasp_area;      // m^2: friction-circle area of a two-finger grasp (0: none)
  std::vector<double> torsion;         // N m: gravity-drop torque about the grasp axis
  std::vector<double> floor_contacts;  // 1: floor points touching the floor
  std::vector<double> body_contacts;   // 1: contact points with other bodies
};

struct FingerView {
  std::string name;
  double radius = 0.0;            // m: pad radius (0: a point)
  std::vector<double> hip;        // m, world: 3 per /haptic row, the /servo row at that tick
  std::vector<double> god_object; // m, world: 3 per /haptic row
  std::vector<double> force;      // N, world: 3 per /haptic row, the demanded contact force
  std::vector<std::int8_t> state; // 1 per /haptic row: 0 free, 1 stick, 2 slip
  std::vector<double> surface_point;   // m, world: 3 per /haptic row, the HIP on the contacted face
  std::vector<double> friction_radius; // m: 1 per /haptic row, mu depth (the friction circle)
  std::vector<double> depth;      // m: 1 per /haptic row, |surface point - HIP| (0 free)
  std::vector<double> slip;       // m: 1 per /haptic row, the god-object's slide this tick
  std::vector<double> body;       // 1 per /haptic row: contacted body index, -2 floor, -1 none
};

struct ViewScene {
  bool live = false;              // a running scenario (live.hpp): no rows, the page streams them
  std::string trace;              // the file as given
  std::string scenario_name;
  std::string status;             // root `status`
  std::string note;               // "" for a complete trace; else what the page says about it
  int rate_servo = 0, rate_haptic = 0, rate_physics = 0;   // Hz
  double duration = 0.0;          // s: the scenario's requested duration
  bool floor = false;
  double floor_height = 0.0;      // m
  std::vector<std::int64_t> physics_tick;   // servo ticks of the /physics rows kept
  std::vector<std::int64_t> haptic_tick;    // servo ticks of the /haptic rows kept
  std::vector<BodyView> bodies;             // Model::bodies order
  std::vector<FingerView> fingers;          // Model::fingers order
  // /contacts at the kept physics ticks (a trace recorded without it: contacts false, no rows):
  // one entry per floor or body-body point, in the table's order.
  bool contacts = false;
  std::vector<std::int64_t> contact_tick;   // servo tick of the physics step
  std::vector<double> contact_a;            // 1: -2 floor, else the body pushed by -force
  std::vector<double> contact_b;            // 1: the body pushed by force
  std::vector<double> contact_point;        // m, world: 3 per row
  std::vector<double> contact_force;        // N, world: 3 per row, on b
};

// Reads `trace`. Tables are cut to the ticks all of them hold (a cut trace's tables may differ by
// a flush interval), so the page shows the run up to its last common tick. Throws ViewError.
ViewScene load_scene(const std::string& trace);

// The floor, and each body's shape and each finger's pad radius, from a scenario's model (no rows):
// what a trace's recorded scenario and a live run both give the page.
void add_model(const Model& model, ViewScene& scene);

}  // namespace graspsim::view
