// Model checks and derived constants.
#include "graspsim/engine/model.hpp"

#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

namespace graspsim {
namespace {

[[noreturn]] void fail(const std::string& field, const std::string& what) {
  throw std::invalid_argument(field + ": " + what);
}

std::string str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void check_material(const std::string& field, const Material& m) {
  if (!(m.mu >= 0.0) || std::isinf(m.mu)) fail(field + ".mu", "must be >= 0 and finite (got " + str(m.mu) + ")");
  if (!(m.stiffness > 0.0)) fail(field + ".stiffness", "must be > 0 N/m (got " + str(m.stiffness) + ")");
  if (!(m.damping >= 0.0)) fail(field + ".damping", "must be >= 0 N s/m (got " + str(m.damping) + ")");
  if (m.mu_kinetic >= 0.0 && !(m.mu_kinetic <= m.mu))
    fail(field + ".mu_kinetic", "must be <= mu = " + str(m.mu) + " (got " + str(m.mu_kinetic) + ")");
  if (std::isnan(m.mu_kinetic) || std::isinf(m.mu_kinetic)) fail(field + ".mu_kinetic", "must be finite");
  if (!(m.viscous >= 0.0) || std::isinf(m.viscous))
    fail(field + ".viscous", "must be >= 0 N s/m and finite (got " + str(m.viscous) + ")");
}

bool finite(const Vec3& v) { return v.allFinite(); }

// The fields each shape kind uses, by the scenario's names (size, radius, length, file).
void check_shape(const std::string& f, const Shape& s) {
  const auto positive = [&](const char* field, double v, const char* what) {
    if (!(v > 0.0) || std::isinf(v)) fail(f + ": " + field, std::string(what) + " must be > 0 m and finite (got " + str(v) + ")");
  };
  switch (s.kind) {
    case ShapeKind::kBox:
      if (!(s.half_extents.minCoeff() > 0.0) || !finite(s.half_extents)) fail(f + ": size", "every side must be > 0 m and finite");
      if (!s.hull) fail(f + ": shape", "a box needs its faces (use box_shape())");
      return;
    case ShapeKind::kSphere:
      positive("radius", s.radius, "the radius");
      return;
    case ShapeKind::kCylinder:
    case ShapeKind::kCapsule:
      positive("radius", s.radius, "the radius");
      if (s.kind == ShapeKind::kCylinder) {
        positive("length", 2.0 * s.half_length, "a cylinder's length");
      } else if (!(s.half_length >= 0.0) || std::isinf(s.half_length)) {
        fail(f + ": length", "a capsule's length (of its cylinder part) must be >= 0 m and finite (got " + str(2.0 * s.half_length) + ")");
      }
      return;
    case ShapeKind::kConvex:
    case ShapeKind::kMesh:
      if (!s.mesh || s.mesh->triangles.empty()) fail(f + ": file", "the shape has no triangles");
      if (s.kind == ShapeKind::kConvex && (!s.hull || s.hull->faces.empty())) {
        fail(f + ": file", "a convex shape needs its faces (use convex_shape())");
      }
      return;
  }
  fail(f + ": shape", "unknown shape kind");
}

}  // namespace

// Springs in series add compliances; dampers in series add "mobilities" (1/c). An infinite
// layer contributes nothing, so a rigid side leaves the other in charge.
ContactPair contact_pair(const Material& a, const Material& b) {
  const auto series = [](double x, double y) {
    if (std::isinf(x)) return y;
    if (std::isinf(y)) return x;
    if (x + y == 0.0) return 0.0;   // two zero springs or dampers in series: none (not 0 / 0)
    return x * y / (x + y);
  };
  return ContactPair{std::min(a.mu, b.mu), std::min(kinetic_mu(a), kinetic_mu(b)),
                     series(a.stiffness, b.stiffness), series(a.damping, b.damping),
                     std::max(a.viscous, b.viscous)};
}

ContactPair with_default_law(const ContactPair& pair, double mass, int physics_rate) {
  ContactPair out = pair;
  const double omega = 4.0 * M_PI * physics_rate;   // rad/s: a natural period of half a step
  if (std::isinf(out.stiffness)) out.stiffness = mass * omega * omega;
  if (std::isinf(out.damping)) out.damping = 2.0 * std::sqrt(out.stiffness * mass);
  return out;
}

ContactPair floor_pair(const Model& model, int body) {
  const BodyParams& bp = model.bodies[body];
  const ContactPair pair = contact_pair(bp.material, model.floor.material);
  if (model.integrator == Integrator::kPaper) return pair;
  return with_default_law(pair, bp.mass, model.rates.physics);
}

ContactPair body_pair(const Model& model, int a, int b) {
  const BodyParams& pa = model.bodies[a];
  const BodyParams& pb = model.bodies[b];
  const ContactPair pair = contact_pair(pa.material, pb.material);
  if (model.integrator == Integrator::kPaper) return pair;
  return with_default_law(pair, pa.mass * pb.mass / (pa.mass + pb.mass), model.rates.physics);
}

Divisors divisors(const Rates& r) {
  return Divisors{r.servo / r.haptic, r.servo / r.physics};
}

Vec3 box_inertia(double m, const Vec3& h) {
  const Vec3 s = h.cwiseProduct(h);
  return Vec3(m / 3.0 * (s.y() + s.z()), m / 3.0 * (s.x() + s.z()), m / 3.0 * (s.x() + s.y()));
}

std::vector<std::string> stability_warnings(const Model& model) {
  // Symplectic Euler on one mode of stiffness K, damping C and inertia M, step h, is stable when
  // h C / M < 2 and h^2 K / M < 4 - 2 h C / M. Estimates per body, for the stiffest modes:
  //  - all fingers pressing on it at once: K = sum k_pair, C = sum c, M = m;
  //  - resting on its face on the floor: rocking, K / I = 12 k / m and C / I = 12 c / m for any
  //    box on four corner springs (K = 4 k (a^2 + b^2), I = m (a^2 + b^2) / 3).
  std::vector<std::string> out;
  const double h = 1.0 / model.rates.physics;
  // These bound the paper's explicit step only; the coupled-mode check (stability.hpp) covers
  // every scheme, and finds the implicit one stable.
  const auto check = [&](const std::string& what, double k_over_m, double c_over_m) {
    if (model.integrator != Integrator::kPaper) return;
    const double stiff = h * h * k_over_m, damp = h * c_over_m;
    if (damp < 2.0 && stiff < 4.0 - 2.0 * damp) return;
    std::ostringstream msg;
    msg << what << ": the explicit integration is likely unstable at physics " << model.rates.physics
        << " Hz (h^2 K/M = " << stiff << ", h C/M = " << damp << "; stable needs h C/M < 2 and "
        << "h^2 K/M < 4 - 2 h C/M): lower the stiffness or damping, or raise rates.physics";
    out.push_back(msg.str());
  };
  for (const BodyParams& b : model.bodies) {
    double k = 0.0, c = 0.0;
    for (int f = 0; f < static_cast<int>(model.fingers.size()); ++f) {
      const Material pad{kInfinity, model.fingers[f].stiffness, kInfinity};
      k += contact_pair(pad, b.material).stiffness;
      c += model.fingers[f].damping;
    }
    if (!model.fingers.empty()) check("object '" + b.name + "' held by every finger", k / b.mass, c / b.mass);
    if (model.floor.enabled) {
      const ContactPair pair = contact_pair(b.material, model.floor.material);
      check("object '" + b.name + "' on the floor", 12.0 * pair.stiffness / b.mass, 12.0 * pair.damping / b.mass);
    }
  }
  //  - two bodies pressed together (a box on a box): the lighter rocking on its corners on the
  //    other, which moves too: the floor's estimate with the reduced mass m_a m_b / (m_a + m_b).
  //    A pair that is rigid on both sides (infinite stiffness or damping, and under the implicit
  //    integrator no default law to fill them) does not collide.
  // Each kind of warning about pairs is said once, with its first pair and how many share it: a
  // scene of 400 boxes has 79,800 pairs.
  struct PairWarning {
    int count = 0;
    std::string first;   // the message for the first pair
  };
  PairWarning rigid, meshes, unstable;
  const auto note = [](PairWarning& w, const std::string& message) {
    if (w.count++ == 0) w.first = message;
  };
  const int n = static_cast<int>(model.bodies.size());
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      const BodyParams& pa = model.bodies[a];
      const BodyParams& pb = model.bodies[b];
      const ContactPair pair = body_pair(model, a, b);
      const auto what = [&] { return "objects '" + pa.name + "' and '" + pb.name + "'"; };
      if (std::isinf(pair.stiffness) || std::isinf(pair.damping)) {
        if (rigid.count++ == 0) {
          rigid.first = what() + " are both rigid (infinite stiffness or damping): they pass through each other; "
                        "give one of them a finite material stiffness and damping to make them collide";
        }
        continue;
      }
      if (pa.shape.kind == ShapeKind::kMesh && pb.shape.kind == ShapeKind::kMesh) {
        if (meshes.count++ == 0) {
          meshes.first = what() + " are both non-convex meshes: mesh against mesh has no contact method yet, so they "
                         "pass through each other; make one of them convex (shape = \"convex\") or another shape";
        }
        continue;
      }
      const double reduced = pa.mass * pb.mass / (pa.mass + pb.mass);
      const std::size_t before = out.size();
      check(what() + " in contact", 12.0 * pair.stiffness / reduced, 12.0 * pair.damping / reduced);
      if (out.size() > before) {
        note(unstable, out.back());
        out.pop_back();
      }
    }
  }
  for (const PairWarning* w : {&rigid, &meshes, &unstable}) {
    if (w->count == 0) continue;
    out.push_back(w->count == 1 ? w->first
                                : w->first + " (and " + std::to_string(w->count - 1) + " more pairs of objects alike)");
  }
  return out;
}

void validate(const Model& model) {
  const Rates& r = model.rates;
  if (r.servo <= 0) fail("rates.servo", "must be a positive number of Hz (got " + std::to_string(r.servo) + ")");
  if (r.haptic <= 0) fail("rates.haptic", "must be a positive number of Hz (got " + std::to_string(r.haptic) + ")");
  if (r.physics <= 0) fail("rates.physics", "must be a positive number of Hz (got " + std::to_string(r.physics) + ")");
  if (r.servo % r.haptic != 0)
    fail("rates.haptic", std::to_string(r.haptic) + " Hz does not divide rates.servo = " + std::to_string(r.servo) + " Hz");
  if (r.servo % r.physics != 0)
    fail("rates.physics", std::to_string(r.physics) + " Hz does not divide rates.servo = " + std::to_string(r.servo) + " Hz");
  if (!finite(model.gravity)) fail("gravity", "must be finite");
  if (model.implicit_order != 1 && model.implicit_order != 2)
    fail("implicit_order", "must be 1 (backward Euler) or 2 (BDF2) (got " + std::to_string(model.implicit_order) + ")");
  const SleepParams& sl = model.sleep;
  if (!(sl.linear_speed >= 0.0) || std::isinf(sl.linear_speed))
    fail("sleep.linear_speed", "must be >= 0 m/s and finite (got " + str(sl.linear_speed) + ")");
  if (!(sl.angular_speed >= 0.0) || std::isinf(sl.angular_speed))
    fail("sleep.angular_speed", "must be >= 0 rad/s and finite (got " + str(sl.angular_speed) + ")");
  if (!(sl.time > 0.0) || !(sl.time <= 1e6))
    fail("sleep.time", "must be > 0 s and at most 1e6 s (got " + str(sl.time) + ")");
  const GraspParams& g = model.grasp;
  if (!(g.critical_area >= 0.0) || std::isinf(g.critical_area))
    fail("grasp.critical_area", "must be >= 0 m^2 and finite (got " + str(g.critical_area) + ")");
  if (g.torsion != Torsion::kNone && !(g.critical_area > 0.0))
    fail("grasp.critical_area", "must be > 0 m^2 when grasp.torsion is set");
  if (g.gimbal_finger >= static_cast<int>(model.fingers.size()) || g.gimbal_finger < -1)
    fail("grasp.gimbal_finger", "is not a finger");
  if ((g.torsion == Torsion::kGimbal) != (g.gimbal_finger >= 0))
    fail("grasp.gimbal_finger", "names the finger whose gimbal turns the body, with grasp.torsion = "
         "\"gimbal\" and only then");
  if (!(g.dead_band >= 0.0) || std::isinf(g.dead_band))
    fail("grasp.dead_band", "must be >= 0 N m and finite (got " + str(g.dead_band) + ")");
  if (!(g.torsional_damping >= 0.0) || std::isinf(g.torsional_damping))
    fail("grasp.torsional_damping", "must be >= 0 N m s/rad and finite (got " + str(g.torsional_damping) + ")");
  if (g.torsional_damping > 0.0 && g.torsion != Torsion::kGravityDrop)
    fail("grasp.torsional_damping", "applies with grasp.torsion = \"gravity_drop\" only");
  if (model.floor.enabled) {
    check_material("floor.material", model.floor.material);
    if (!std::isfinite(model.floor.height)) fail("floor.height", "must be finite");
  }
  std::set<std::string> names;
  for (std::size_t i = 0; i < model.bodies.size(); ++i) {
    const BodyParams& b = model.bodies[i];
    const std::string f = "objects[" + std::to_string(i + 1) + "] '" + b.name + "'";
    if (b.name.empty()) fail(f, "name must not be empty");
    if (!names.insert(b.name).second) fail(f, "name '" + b.name + "' is used twice");
    check_shape(f, b.shape);
    if (!(b.mass > 0.0) || std::isinf(b.mass)) fail(f + ": mass", "must be > 0 kg and finite (got " + str(b.mass) + ")");
    const Vec3& j = b.inertia;
    if (!(j.minCoeff() > 0.0) || !finite(j)) fail(f + ": inertia", "principal moments must be > 0 kg m^2");
    // A physical body's principal moments obey the triangle inequality J_a + J_b >= J_c.
    const double slack = 1e-12 * j.sum();
    if (j.x() + j.y() < j.z() - slack || j.y() + j.z() < j.x() - slack || j.x() + j.z() < j.y() - slack)
      fail(f + ": inertia", "principal moments break the triangle inequality (no real body has them)");
    check_material(f + ": material", b.material);
    if (!finite(b.position) || !finite(b.velocity) || !finite(b.angular_velocity) || !b.orientation.coeffs().allFinite())
      fail(f, "initial position, orientation and velocities must be finite");
    if (std::abs(b.orientation.norm() - 1.0) > 1e-9) fail(f + ": orientation", "must be a unit quaternion");
    if (model.floor.enabled && model.integrator == Integrator::kPaper) {
      const ContactPair pair = contact_pair(b.material, model.floor.material);
      if (std::isinf(pair.stiffness))
        fail(f + ": material.stiffness", "the object and the floor are both rigid (infinite "
             "stiffness); the paper's penalty floor contact needs a finite stiffness on one of them "
             "(integrator = \"implicit\" chooses one)");
      if (std::isinf(pair.damping))
        fail(f + ": material.damping", "the object and the floor both leave damping unset "
             "(infinite); the paper's penalty floor contact needs a finite damping on one of them (0 for "
             "none; integrator = \"implicit\" chooses one)");
    }
  }
  names.clear();
  for (std::size_t i = 0; i < model.fingers.size(); ++i) {
    const FingerParams& p = model.fingers[i];
    const std::string f = "fingers[" + std::to_string(i + 1) + "] '" + p.name + "'";
    if (p.name.empty()) fail(f, "name must not be empty");
    if (!names.insert(p.name).second) fail(f, "name '" + p.name + "' is used twice");
    if (!(p.stiffness > 0.0) || std::isinf(p.stiffness)) fail(f + ": stiffness", "must be > 0 N/m and finite (got " + str(p.stiffness) + ")");
    if (!(p.damping >= 0.0) || std::isinf(p.damping)) fail(f + ": damping", "must be >= 0 N s/m and finite (got " + str(p.damping) + ")");
    if (!(p.radius >= 0.0) || std::isinf(p.radius)) fail(f + ": radius", "must be >= 0 m and finite (got " + str(p.radius) + ")");
  }
}

}  // namespace graspsim
