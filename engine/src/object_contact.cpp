// Penalty floor contact, vertex by vertex (paper, section 4).
#include "graspsim/engine/object_contact.hpp"

#include <algorithm>
#include <cmath>

#include "graspsim/engine/finger_contact.hpp"

namespace graspsim {

Vec3 box_vertex(const Vec3& h, int k) {
  return Vec3((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z());
}

int floor_contact(const Model& model, int body, BodyState& bs, Wrench& out) {
  out = Wrench{};
  const BodyParams& bp = model.bodies[body];
  const ContactPair pair = contact_pair(bp.material, model.floor.material);
  const double floor_z = model.floor.height;
  int touching = 0;
  for (int k = 0; k < 8; ++k) {
    VertexContact& vc = bs.floor_contacts[k];
    const Vec3 r = bs.rotation * box_vertex(bp.shape.half_extents, k);   // m: from centre of mass
    const Vec3 x = bs.position + r;
    const double depth = floor_z - x.z();
    if (depth <= 0.0) {
      vc.active = false;
      continue;
    }
    ++touching;
    const Vec3 u = bs.velocity + bs.angular_velocity.cross(r);   // m/s: vertex velocity
    const double f_n = std::max(0.0, pair.stiffness * depth - pair.damping * u.z());
    const Vec3 x_t(x.x(), x.y(), floor_z);
    if (!vc.active) {
      vc.active = true;
      vc.slipping = false;
      vc.anchor = x_t;
    }
    // Static coefficient while stuck, kinetic (plus viscous c |u_t|) while slipping, with the
    // fingers' rule for sticking again (stick_slip_step), on the vertex's velocity over the floor.
    const Vec3 u_t(u.x(), u.y(), 0.0);   // m/s
    const double viscous = pair.viscous * u_t.norm();   // N, while slipping
    vc.slipping = stick_slip_step(x_t, pair.mu * f_n / pair.stiffness,
                                  (pair.friction(true) * f_n + viscous) / pair.stiffness, u_t,
                                  vc.slipping, vc.anchor);
    const double mu = pair.friction(vc.slipping);
    const double limit_viscous = vc.slipping ? viscous : 0.0;
    Vec3 f_t = pair.stiffness * (vc.anchor - x_t) - pair.damping * Vec3(u.x(), u.y(), 0.0);
    const double limit = mu * f_n + limit_viscous;
    const double f_t_norm = f_t.norm();
    if (f_t_norm > limit) f_t *= limit / f_t_norm;
    const Vec3 f(f_t.x(), f_t.y(), f_n);
    out.force += f;
    out.torque += r.cross(f);
  }
  return touching;
}

}  // namespace graspsim
