// Timed-waypoint trajectories for scripted fingers.
#include "graspsim/hw/trajectory.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace graspsim::hw {

WaypointTrajectory::WaypointTrajectory(std::vector<Waypoint> waypoints, Interpolation interpolation)
    : waypoints_(std::move(waypoints)), interpolation_(interpolation) {
  if (waypoints_.empty()) throw std::invalid_argument("trajectory: needs at least one waypoint");
  for (std::size_t i = 0; i < waypoints_.size(); ++i) {
    if (!std::isfinite(waypoints_[i].time) || !waypoints_[i].position.allFinite() ||
        !std::isfinite(waypoints_[i].pitch))
      throw std::invalid_argument("trajectory[" + std::to_string(i + 1) + "]: time, position and pitch must be finite");
    if (i > 0 && !(waypoints_[i].time > waypoints_[i - 1].time))
      throw std::invalid_argument("trajectory[" + std::to_string(i + 1) +
                                  "]: times must increase strictly (t = " +
                                  std::to_string(waypoints_[i].time) + " after t = " +
                                  std::to_string(waypoints_[i - 1].time) + ")");
  }
}

namespace {
TrajectorySample at(const Waypoint& w) {
  TrajectorySample s;
  s.position = w.position;
  s.gimbal.y() = w.pitch;
  return s;
}
}  // namespace

TrajectorySample WaypointTrajectory::sample(double t) {
  if (std::isnan(t)) throw std::invalid_argument("trajectory: time is NaN");
  const std::size_t n = waypoints_.size();
  if (t <= waypoints_.front().time) return at(waypoints_.front());
  if (t >= waypoints_.back().time) return at(waypoints_.back());
  // Find the segment [i, i+1] holding t, starting from the cached one (time mostly increases).
  std::size_t i = segment_ < n - 1 ? segment_ : 0;
  if (t < waypoints_[i].time) i = 0;
  while (i + 1 < n - 1 && t >= waypoints_[i + 1].time) ++i;
  segment_ = i;
  const Waypoint& a = waypoints_[i];
  const Waypoint& b = waypoints_[i + 1];
  const double u = (t - a.time) / (b.time - a.time);
  double s = u;
  if (interpolation_ == Interpolation::kMinimumJerk) {
    // Minimum-jerk profile (Flash & Hogan 1985): zero velocity and acceleration at both ends.
    s = u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
  }
  TrajectorySample out;
  out.position = a.position + s * (b.position - a.position);
  out.gimbal.y() = a.pitch + s * (b.pitch - a.pitch);
  return out;
}

}  // namespace graspsim::hw
