// Newton-Euler integration of one rigid body (paper, section 3.1).
#include "graspsim/engine/integrate.hpp"

namespace graspsim {

void orthonormalize(Mat3& R) {
  Vec3 o = R.col(1);
  Vec3 a = R.col(2).normalized();
  Vec3 n = o.cross(a).normalized();
  o = a.cross(n);
  R.col(0) = n;
  R.col(1) = o;
  R.col(2) = a;
}

void integrate_body(const BodyParams& params, BodyState& body, const Vec3& force,
                    const Vec3& torque, double dt) {
  const Vec3 a = force / params.mass;
  body.velocity += a * dt;
  body.position += body.velocity * dt;

  const Mat3& R = body.rotation;
  const Vec3 torque_body = R.transpose() * torque;
  const Vec3 w_dot = R * torque_body.cwiseQuotient(params.inertia);   // R Jp^-1 R^T T
  body.angular_velocity += w_dot * dt;

  body.rotation = (Mat3::Identity() + skew(body.angular_velocity) * dt) * R;
  orthonormalize(body.rotation);
}

}  // namespace graspsim
