// Newton-Euler integration of one rigid body (paper, section 3.1), with the gyroscopic term of
// Euler's equation neglected (the paper), explicit, or implicit (README.md, "Speed against
// error", measures the three).
#include "graspsim/engine/integrate.hpp"

#include <Eigen/LU>

namespace graspsim {

namespace {

// Change of the body-frame angular velocity w_b (rad/s) over dt from the gyroscopic term alone,
// Euler's torque-free equation  Jp w_b_dot = -w_b x (Jp w_b), evaluated at the start of the step
// (forward Euler):  dw_b = -dt Jp^-1 (w_b x Jp w_b).
Vec3 gyroscopic_explicit(const Vec3& inertia, const Vec3& w_b, double dt) {
  const Vec3 g = w_b.cross(inertia.cwiseProduct(w_b));   // w_b x Jp w_b   (N m)
  return -dt * g.cwiseQuotient(inertia);
}

// Change of w_b over dt from the gyroscopic term alone by one Newton step of implicit (backward)
// Euler (Erin Catto's "gyroscopic torque" method, as in Bullet's
// btRigidBody::computeGyroscopicImpulseImplicit_Body; Box2D is 2D and has no such term):
//   f(w)  = J (w - w0) + dt w x (J w)                     residual of backward Euler, f(w1) = 0
//   Jf(w) = J + dt (S(w) J - S(J w))                      since d(w x Jw)/dw = S(w) J - S(J w)
//   w1    = w0 - Jf(w0)^-1 f(w0),  f(w0) = dt w0 x J w0,  so  dw = -Jf(w0)^-1 (dt w0 x J w0).
// Jf is solved by partial-pivot LU on the fixed-size 3x3 (`partialPivLu().solve()`: no heap,
// same bits for the same inputs). Jf is not symmetric (so no LLT), and LU with pivoting is
// backward stable, where the closed-form cofactor inverse that Matrix3d::inverse() uses is not
// and multiplies by the inverse afterwards, one more rounding. Jf -> J (diagonal) as dt -> 0, so
// at the usual steps either would give the same figures to a few ulp; LU is the safer choice
// when dt |w| is large. Cost: a 3x3 build and LU, about 100 flops more than the explicit form,
// no iteration, and one Newton step only (its error against exact backward Euler is O(dt^2),
// the order of backward Euler's own local error, so the scheme stays first-order accurate).
//
// Why it injects no energy (E = 1/2 w.Jw, J symmetric positive definite):
// - Exact backward Euler: dot J (w1 - w0) = -dt w1 x J w1 with w1; the right side is
//   perpendicular to w1, so w1.J w1 = w1.J w0 and  E0 - E1 = 1/2 (w1 - w0).J (w1 - w0) >= 0:
//   it dissipates, by a second-order amount (the same with J w1: |L1| <= |L0|).
// - One Newton step from w0 (what is coded): with g = w0 x J w0, A = S(w0) J - S(J w0),
//   y = (J + dt A)^-1 g, the step is dw = -dt y, i.e. J dw = -dt g - dt A dw. Since
//   w0.g = 0 and w0.A v = w0.(w0 x J v) - w0.(J w0 x v) = -v.g,
//     E1 - E0 = w0.J dw + 1/2 dw.J dw = dt dw.g + 1/2 dw.J dw
//             = -dt^2 y.(J + dt A) y + 1/2 dt^2 y.J y = -dt^2 [1/2 y.J y + dt y.(w0 x J y)]
//   (y.S(J w0) y = 0). The first term dissipates as exact backward Euler does; the second is
//   bounded by dt |w0| |y| |J y| <= dt |w0| (Jmax / Jmin) y.J y, so
//     E1 <= E0  whenever  dt |w0| <= Jmin / (2 Jmax)
//   (0.1 <= 1/6 for moments 1:2:3 at 5 rad/s and 50 Hz). Both terms are quadratic in y, so the
//   sign holds however close the spin is to a principal axis (where g -> 0); beyond the bound
//   the step is still first-order accurate, only the guarantee is lost. The external torque is
//   added afterwards, as in the paper's form, so only the torque does work.
Vec3 gyroscopic_implicit(const Vec3& inertia, const Vec3& w_b, double dt) {
  const Mat3 J = inertia.asDiagonal();
  const Vec3 Jw = inertia.cwiseProduct(w_b);                            // J w0   (kg m^2/s)
  const Vec3 f = dt * w_b.cross(Jw);                                    // f(w0)
  const Mat3 Jf = J + dt * (skew(w_b) * J - skew(Jw));                  // Jf(w0)
  return -Jf.partialPivLu().solve(f);
}

// The torque-free part of Euler's equation over dt by the implicit midpoint rule on the body-frame
// angular momentum L = Jp w_b (K = Jp^-1):
//   L1 = L0 + dt M x K M,   M = (L0 + L1) / 2          (Euler: dL/dt = L x K L in the body frame)
// It conserves both invariants of the free body, which are quadratic in L, exactly (the midpoint
// rule keeps every quadratic invariant: Hairer, Lubich & Wanner, Geometric Numerical Integration,
// IV.2): dotting M = L0 + dt/2 M x K M with M and with K M, whose cross terms vanish,
//   M.M = M.L0    and    M.K M = L0.K M,
// so with L1 = 2 M - L0
//   |L1|^2 = 4 M.M - 4 M.L0 + |L0|^2 = |L0|^2,   L1.K L1 = 4 M.K M - 4 L0.K M + L0.K L0 = L0.K L0,
// whatever dt and |w|: no energy is gained at any spin and rate (a first-order scheme cannot
// promise that: forward Euler always gains, one Newton step of backward Euler only while
// dt |w| <= Jmin / (2 Jmax)). Chosen over the exact motion: the exact asymmetric body needs
// Jacobi's elliptic functions and an elliptic integral of the third kind per step; the midpoint
// rule keeps the two invariants that decide whether a step gains energy, and is second order.
//
// M is found by Newton's method on F(M) = M - L0 - dt/2 M x K M, whose derivative is
// I - dt/2 (S(M) K - S(K M)), from M = L0. Once an update is below 1e-9 |L0| one more is taken:
// Newton's error squares at each update (times about dt |w| Jmax / Jmin), so the last one leaves
// M at rounding. Newton converges from L0 while dt/2 |w| is about 1 or less (2 rad a step:
// 100 rad/s at 50 Hz); a step whose iteration has not come below 1e-9 |L0| in 32 updates is
// taken as two half steps instead (each conserves both invariants), so any spin and rate is
// stepped. L1 is formed as the rotation of L0 the rule is, a Cayley transform:
// (I + dt/2 S(W)) L1 = (I - dt/2 S(W)) L0 with W = K M, i.e.
//   L1 = L0 + c (a x L0 + a x (a x L0)),   a = -dt/2 W,   c = 2 / (1 + |a|^2),
// so |L1| = |L0| up to rounding, whatever rounding M carries. Returns L1 (kg m^2/s, body frame).
Vec3 midpoint_momentum_step(const Vec3& inertia, const Vec3& L0, double dt, int depth) {
  constexpr int kMaxUpdates = 32;
  constexpr int kMaxHalvings = 24;   // 2^24 substeps: far beyond the spins the divergence check lets through
  const Vec3 K = inertia.cwiseInverse();   // 1/(kg m^2)
  const double half = 0.5 * dt;            // s
  const double close = 1e-9 * L0.norm();   // kg m^2/s
  Vec3 M = L0;
  const auto newton_update = [&] {
    const Vec3 KM = K.cwiseProduct(M);
    const Vec3 F = M - L0 - half * M.cross(KM);
    const Mat3 DF = Mat3::Identity() - half * (skew(M) * K.asDiagonal() - skew(KM));
    const Vec3 step = DF.partialPivLu().solve(F);
    M -= step;
    return step.norm();
  };
  bool converged = false;
  for (int i = 0; i < kMaxUpdates && !converged; ++i) converged = newton_update() <= close;
  if (!converged && depth < kMaxHalvings) {
    const Vec3 L_half = midpoint_momentum_step(inertia, L0, half, depth + 1);
    return midpoint_momentum_step(inertia, L_half, half, depth + 1);
  }
  newton_update();
  const Vec3 a = -half * K.cwiseProduct(M);   // rad
  const Vec3 aL = a.cross(L0);
  return L0 + (2.0 / (1.0 + a.squaredNorm())) * (aL + a.cross(aL));
}

}  // namespace

void orthonormalize(Mat3& R) {
  Vec3 o = R.col(1);
  Vec3 a = R.col(2).normalized();
  Vec3 n = o.cross(a).normalized();
  o = a.cross(n);
  R.col(0) = n;
  R.col(1) = o;
  R.col(2) = a;
}

void integrate_body(const BodyParams& params, Gyroscopic gyroscopic, BodyState& body,
                    const Vec3& force, const Vec3& torque, double dt) {
  const Vec3 a = force / params.mass;
  body.velocity += a * dt;
  body.position += body.velocity * dt;

  const Mat3& R = body.rotation;

  // The gyroscopic change of w, computed in the body frame and added in the world frame,
  //   w = w_old + R dw_b(R^T w_old),
  // before the torque's change; for kNeglect nothing is added and the paper's update below runs
  // on the paper's own operands, bit for bit. Adding the change (not w = R w_b) leaves the
  // part of w that does not change free of the R R^T round trip, and makes w = 0 give dw_b = 0
  // exactly, so all three options agree bit for bit on a body at rest.
  if (gyroscopic != Gyroscopic::kNeglect) {
    const Vec3 w_b = R.transpose() * body.angular_velocity;             // R^T w   (rad/s)
    const Vec3 dw_b = gyroscopic == Gyroscopic::kExplicit
                          ? gyroscopic_explicit(params.inertia, w_b, dt)
                          : gyroscopic_implicit(params.inertia, w_b, dt);
    body.angular_velocity += R * dw_b;
  }

  // The external torque (paper): w_dot = R Jp^-1 R^T T, w = w + w_dot dt. With the explicit
  // gyroscopic change before it this is w_b += dt Jp^-1 (T_b - w_b x Jp w_b), w = R w_b
  // (in exact arithmetic; the rounding is that of the two increments).
  const Vec3 torque_body = R.transpose() * torque;
  const Vec3 w_dot = R * torque_body.cwiseQuotient(params.inertia);   // R Jp^-1 R^T T
  body.angular_velocity += w_dot * dt;

  if (gyroscopic == Gyroscopic::kNeglect) {
    // The paper's first-order increment, then its n-o-a normalisation.
    body.rotation = (Mat3::Identity() + skew(body.angular_velocity) * dt) * R;
  } else {
    // The exact rotation about w over the step, R = exp(S(w) dt) R_old (Rodrigues). The paper's
    // increment followed by the normalisation turns w in the body frame by ~(|w| dt)^2 per step,
    // which for some orderings of the moments adds energy (measured: moments 3:2:1 spun near the
    // middle axis at 50 Hz, +4% in 10 s even with the implicit term); turning exactly about w
    // leaves R^T w unchanged, so the energy is set by the angular-velocity update alone.
    const double angle = body.angular_velocity.norm() * dt;   // rad
    if (angle > 0.0) {
      body.rotation = Eigen::AngleAxisd(angle, body.angular_velocity / body.angular_velocity.norm())
                          .toRotationMatrix() * R;
    }
  }
  orthonormalize(body.rotation);
}

Vec3 gyroscopic_change(const BodyParams& params, Gyroscopic gyroscopic, const BodyState& body, double dt) {
  if (gyroscopic == Gyroscopic::kNeglect) return Vec3::Zero();
  const Mat3& R = body.rotation;
  const Vec3 w_b = R.transpose() * body.angular_velocity;              // rad/s, body frame
  const Vec3 L0 = params.inertia.cwiseProduct(w_b);                    // kg m^2/s, body frame
  if (w_b.cross(L0) == Vec3::Zero()) return Vec3::Zero();              // no gyroscopic term to step
  const Vec3 L1 = midpoint_momentum_step(params.inertia, L0, dt, 0);
  return R * (L1.cwiseQuotient(params.inertia) - w_b);
}

void move_body(const BodyParams& params, BodyState& body, const Vec3& force, const Vec3& torque, double dt) {
  body.velocity += force * (dt / params.mass);
  body.position += dt * body.velocity;

  const Mat3 R = body.rotation;
  body.angular_velocity += dt * (R * (R.transpose() * torque).cwiseQuotient(params.inertia));
  const Vec3& w = body.angular_velocity;   // rad/s
  const double angle = w.norm() * dt;      // rad
  if (angle > 0.0) body.rotation = Eigen::AngleAxisd(angle, w / w.norm()).toRotationMatrix() * R;
  orthonormalize(body.rotation);
}

void move_body_bdf2(BodyState& body, const Vec3& v1, const Vec3& w1, const Vec3& v_mean, const Vec3& w_mean,
                    double dt) {
  const double third = dt / 3.0;   // s
  body.velocity = v1;
  body.angular_velocity = w1;
  body.position += third * (v_mean + 2.0 * v1);
  const Vec3 turn = third * (w_mean + 2.0 * w1);   // rad, world: the rotation vector of the step
  const double angle = turn.norm();
  if (angle > 0.0) body.rotation = Eigen::AngleAxisd(angle, turn / angle).toRotationMatrix() * body.rotation;
  orthonormalize(body.rotation);
}

}  // namespace graspsim
