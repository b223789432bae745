// A Phantom (Premium 1.5, Omni, Touch) driven through the OpenHaptics HD API. Declared whether
// or not graspsim was built with the SDK: without it, make_openhaptics_device throws a clear
// error saying how to build it in. No HD type appears here, so users of this header need no SDK.
//
// Device frame (what read() returns and render() takes), SI, right-handed, z up like the world:
//   x = OpenHaptics x (to the user's right), y = -OpenHaptics z (away from the user),
//   z = OpenHaptics y (up); origin at the OpenHaptics origin (the device's calibration centre).
// Position in m (HD reports mm), gimbal angles in rad exactly as HD_CURRENT_GIMBAL_ANGLES gives
// them (the stylus gimbal joints; 0 on a Premium without a gimbal encoder), buttons as
// HD_CURRENT_BUTTONS (bit 0 = button 1). Mapping this frame to the world is the caller's job
// (the finger's workspace mapping). See hw/README.md, "Connecting Phantoms (OpenHaptics)".
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "graspsim/hw/device.hpp"

namespace graspsim::hw {

// The servo callback renders zero once it has gone this many of its own frames (0.1 s at the
// 1 kHz default rate) without a new force request: the backend's last line of defence when
// graspsim's loop dies without releasing the device. Counted in servo frames, not wall time.
constexpr std::uint64_t kOpenHapticsStallFrames = 100;

// Hz: the servo rate assumed for the device clock when HD_UPDATE_RATE does not give a positive
// number at start-up (the HD scheduler's default rate).
constexpr int kOpenHapticsDefaultRate = 1000;

// Force safety timing for every Phantom (hw/README.md "Force safety"); the peak and continuous
// forces are the device's own nominal figures, read at start-up.
struct OpenHapticsOptions {
  double rise_time = 1.0;               // s: ramp-in after start, a stall or release; 0 = none
  double thermal_time_constant = 10.0;  // s: tau of the thermal model (estimate, force_safety.hpp)
};

// What the device says about itself at start-up (read once, after hdInitDevice).
struct PhantomNominal {
  double max_force = 0.0;              // N: HD_NOMINAL_MAX_FORCE, the peak force; the clamp limit
  double max_continuous_force = 0.0;   // N: HD_NOMINAL_MAX_CONTINUOUS_FORCE
  double max_stiffness = 0.0;          // N/m: HD_NOMINAL_MAX_STIFFNESS (HD reports N/mm)
};

// The device make_openhaptics_device returns, for callers that want its start-up figures
// (dynamic_cast the Device to it). Its clock (Device::sample_time) counts its own servo frames:
// the sample read in frame k (0 = the first frame served) was taken at k / rate s, rate from
// HD_UPDATE_RATE; Device::sample_sequence gives k, new_samples the frames since the previous
// read's sample.
class OpenHapticsDevice : public Device {
 public:
  virtual PhantomNominal nominal() const = 0;
  virtual std::string config_name() const = 0;   // the configured name that opened
  virtual double rate() const = 0;               // Hz: the servo rate of the device clock
};

// Opens the Phantom configured under `device_name` (the name set in Phantom Configuration /
// Touch Setup; "" or "default" for the default device), enables its force output, reads its
// nominal limits and starts the one HD scheduler callback that serves every open Phantom.
// limits().max_force is the nominal max force; in the servo callback every force also goes
// through ForceSafety (nominal peak and continuous force, `options`' ramp and thermal time
// constant, the stall at kOpenHapticsStallFrames) on the device's frame clock. Throws
// std::runtime_error naming the device, the names tried and the HD error code and string when it
// cannot be opened.
std::unique_ptr<Device> make_openhaptics_device(const std::string& device_name,
                                                const OpenHapticsOptions& options = {});

}  // namespace graspsim::hw
