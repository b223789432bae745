// Trajectories for scripted fingers: the HIP position (and the stylus gimbal) as a function of time.
#pragma once

#include <memory>
#include <vector>

#include "graspsim/hw/device.hpp"

namespace graspsim::hw {

// What a trajectory gives for one instant.
struct TrajectorySample {
  Vec3 position{0.0, 0.0, 0.0};   // m, world: the HIP
  Vec3 gimbal{0.0, 0.0, 0.0};     // rad: stylus gimbal (roll, pitch, yaw); scripts set the pitch
};

class Trajectory {
 public:
  virtual ~Trajectory() = default;
  // HIP position and gimbal at time t (s). Throws on a script error or a NaN t; never returns
  // a non-finite value.
  virtual TrajectorySample sample(double t) = 0;
  Vec3 position(double t) { return sample(t).position; }   // m, world
};

struct Waypoint {
  double time = 0.0;              // s
  Vec3 position{0.0, 0.0, 0.0};   // m, world
  double pitch = 0.0;             // rad: gimbal pitch, interpolated like the position
};

enum class Interpolation {
  kLinear,          // piecewise linear: constant velocity on each segment
  kMinimumJerk,     // s(u) = 10u^3 - 15u^4 + 6u^5: rests at every waypoint, as a hand does
};

// Timed waypoints, strictly increasing in time. Holds the first position before the first
// waypoint and the last one after the last.
class WaypointTrajectory final : public Trajectory {
 public:
  // Throws std::invalid_argument when empty or when times do not increase.
  WaypointTrajectory(std::vector<Waypoint> waypoints, Interpolation interpolation);
  TrajectorySample sample(double t) override;

 private:
  std::vector<Waypoint> waypoints_;
  Interpolation interpolation_;
  std::size_t segment_ = 0;   // cache: last segment used (times mostly increase)
};

}  // namespace graspsim::hw
