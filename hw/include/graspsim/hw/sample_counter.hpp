// Optional, next to Device (like SampleClock): a device whose samples are numbered by the device
// says which sample the last read() returned and how many new samples came since the read
// before, so a lab can see gaps and holds in /devices/<finger> (`sequence`, `new_samples`).
//   UDP bridge:   the server's sample sequence number (uint32, wraps) and the samples accepted
//                 since the previous read (0 = held; a skip in `sequence` with 1 = a lost sample).
//   OpenHaptics:  the HD servo frame the sample was read in (0 = the first frame served) and the
//                 frames since the previous read's sample (0 = held: graspsim reads faster).
// Implemented alongside Device (class X : public Device, public SampleClock, public
// SampleCounter); the run loop finds it with dynamic_cast once per device, not per tick.
#pragma once

#include <cstdint>

namespace graspsim::hw {

class SampleCounter {
 public:
  virtual ~SampleCounter() = default;
  // 1: the device's number of the sample the last read() returned; -1 before any sample.
  virtual std::int64_t sample_sequence() const = 0;
  // 1: new samples between the previous read() and the last one (0 = the sample was held).
  virtual std::int64_t new_samples() const = 0;
};

}  // namespace graspsim::hw
