// The local model of a body between physics steps (local_model.hpp).
#include "graspsim/engine/local_model.hpp"

#include <cmath>

namespace graspsim {

Pose fast_loop_pose(const Model& model, const BodyState& body, std::int64_t tick) {
  Pose pose{body.rotation, body.position, body.velocity};
  if (!uses_local_model(model) || body.asleep || body.stepped_at < 0 || tick <= body.stepped_at) return pose;
  const double tau = static_cast<double>(tick - body.stepped_at) / static_cast<double>(model.rates.servo);   // s
  const Vec3 phi = tau * body.angular_velocity;   // rad
  const double a = phi.norm();                    // rad
  if (a == 0.0) {
    pose.position += tau * body.velocity;
    return pose;
  }
  const Mat3 s = skew(phi);
  // (1 - cos a) / a^2 and (a - sin a) / a^3, by their series below 1e-3 rad, where the closed
  // forms lose digits to cancellation (the next terms, a^4 / 720 and a^4 / 5040, are below 1e-15).
  const double a2 = a * a;
  const double c1 = a < 1e-3 ? 0.5 - a2 / 24.0 : (1.0 - std::cos(a)) / a2;
  const double c2 = a < 1e-3 ? 1.0 / 6.0 - a2 / 120.0 : (a - std::sin(a)) / (a2 * a);
  const Mat3 turn = Eigen::AngleAxisd(a, phi / a).toRotationMatrix();
  pose.rotation = turn * body.rotation;
  pose.position += tau * (body.velocity + c1 * (s * body.velocity) + c2 * (s * (s * body.velocity)));
  pose.velocity = turn * body.velocity;
  return pose;
}

double fast_loop_lead(const Model& model) {
  if (!uses_local_model(model)) return 0.0;
  const double d = static_cast<double>(model.rates.servo / model.rates.physics);   // servo ticks a window
  return (d + 1.0) / (2.0 * static_cast<double>(model.rates.servo));
}

}  // namespace graspsim
