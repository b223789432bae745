// Vector types and the few small helpers the engine shares. Scalar Eigen (EIGEN_DONT_VECTORIZE)
// so that every build sums in the same order.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace graspsim {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

// Skew-symmetric matrix S(w) with S(w) x = w x x (paper, section 3.1).
inline Mat3 skew(const Vec3& w) {
  Mat3 s;
  s << 0.0, -w.z(), w.y(),
       w.z(), 0.0, -w.x(),
       -w.y(), w.x(), 0.0;
  return s;
}

// Quaternion of a rotation matrix, sign fixed so that w >= 0 (one representative per rotation,
// so traces compare bit for bit).
inline Quat quat_of(const Mat3& r) {
  Quat q(r);
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  return q;
}

}  // namespace graspsim
