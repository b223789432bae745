// The table of haptic device models: the mechanical and electrical figures a backend, the force
// safety and the simulated Phantom need, with units and sources (hw/README.md has the table).
#pragma once

#include <span>
#include <string>

#include "graspsim/hw/device.hpp"

namespace graspsim::hw {

struct DeviceModel {
  const char* key = "";              // short name for the command line, e.g. "premium-1.5"
  const char* name = "";             // vendor's name, e.g. "Phantom Premium 1.5"
  Vec3 workspace{0.0, 0.0, 0.0};     // m: usable box along the device frame's x (width, right), y (depth,
                                     // away from the user), z (height, up): the OpenHaptics backend's frame
  double peak_force = 0.0;           // N: nominal maximum exertable force (at the nominal position)
  double continuous_force = 0.0;     // N: continuous exertable force (24 h)
  double stiffness = 0.0;            // N/m: stiffness of the device (lowest axis where given per axis)
  double tip_mass = 0.0;             // kg: apparent mass at the tip (endpoint inertia)
  double backdrive_friction = 0.0;   // N: Coulomb backdrive friction at the tip
  double damping = 0.0;              // N s/m: viscous damping at the tip (estimate: no data sheet gives it)
  double encoder_resolution = 0.0;   // m: nominal position resolution (one encoder count at the tip)
  double device_rate_hz = 0.0;       // Hz: servo rate of the vendor's driver (OpenHaptics: 1 kHz)
};

// Every known model, in a fixed order.
std::span<const DeviceModel> device_models();

// The model whose key or name is `name` (exact, case-sensitive). Throws std::invalid_argument
// naming `name` and listing the known keys and names.
const DeviceModel& device_model(const std::string& name);

}  // namespace graspsim::hw
