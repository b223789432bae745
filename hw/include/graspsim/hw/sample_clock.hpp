// Optional, next to Device: a device with its own clock says when its last sample was taken, on
// that clock (a UDP device's `device time`, a Phantom's scheduler time). The run loop records it
// in /devices/<finger>/device_time; a device without one is recorded with the simulated time of
// the servo tick that read it. Implemented alongside Device (class X : public Device, public
// SampleClock); the run loop finds it with dynamic_cast, so Device needs no member for it.
#pragma once

namespace graspsim::hw {

class SampleClock {
 public:
  virtual ~SampleClock() = default;
  virtual double sample_time() const = 0;   // s, the device's clock: when the last read sample was taken
};

}  // namespace graspsim::hw
