// The friction cone algorithm of Melder, Harwin & Sharkey, section 2, per finger.
#include "graspsim/engine/finger_contact.hpp"

#include <algorithm>
#include <cmath>

#include "graspsim/engine/local_model.hpp"

namespace graspsim {
namespace {

// Pose of the frame a contact lives in: a body's as the fast loops see it now (local_model.hpp),
// or the world's for the floor.
struct Frame {
  Mat3 R;   // 1: frame to world
  Vec3 p;   // m: frame origin in world
  Vec3 v;   // m/s, world: the origin's velocity
};

Frame contact_frame(const Model& model, const State& state, int body) {
  if (body < 0) return Frame{Mat3::Identity(), Vec3::Zero(), Vec3::Zero()};
  const Pose pose = fast_loop_pose(model, state.bodies[body], state.tick);
  return Frame{pose.rotation, pose.position, pose.velocity};
}


const Material& surface_material(const Model& model, int body) {
  return body >= 0 ? model.bodies[body].material : model.floor.material;
}

// The circle a GO that slipped this tick lies on: the static one the tick it breaks away,
// else the kinetic one (see finger_haptic_step).
double sliding_radius(bool was_slipping, double static_radius, double kinetic_radius) {
  return was_slipping ? kinetic_radius : static_radius;
}

}  // namespace

bool stick_slip_step(const Vec3& sp, double static_radius, double kinetic_radius,
                     const Vec3& v_rel_t, bool was_slipping, Vec3& go) {
  if (!was_slipping) return friction_circle_step(sp, static_radius, go);
  const Vec3 d = sp - go;
  const bool within = d.squaredNorm() <= kinetic_radius * kinetic_radius * (1.0 + 2e-9);
  if (within && v_rel_t.dot(d) <= 0.0) return false;   // stopped or turned back: stick
  friction_circle_step(sp, kinetic_radius, go);
  return true;
}

ContactPair finger_contact_pair(const Model& model, int finger, int body) {
  // The finger pad is a spring with no friction of its own: the surface's friction rules.
  const Material pad{kInfinity, model.fingers[finger].stiffness, kInfinity, kInfinity, 0.0};
  return contact_pair(pad, surface_material(model, body));
}

void finger_haptic_step(const Model& model, const State& state, const CollisionWorld& collision,
                        int finger, const Vec3& hip, FingerState& fs, HapticFingerRecord& rec,
                        std::vector<int>& scratch) {
  rec.slip = 0.0;
  bool track = fs.phase != ContactPhase::kFree;
  // A pad of radius r is a sphere about the HIP: it touches where its centre enters the shape
  // grown by r (surface.hpp: boxes with square edges, round shapes exactly, polygonal faces
  // offset by r).
  const double r = model.fingers[finger].radius;

  if (!track) {
    // Free: did the path since the last haptic tick enter a surface? The earliest entry wins;
    // ties go to the lower body index, then to the floor.
    const Vec3 a = fs.has_last_haptic ? fs.hip_at_last_haptic : hip;
    // The path is relative to each body: its start in the body's frame as it was at the last
    // haptic tick (before a physics step since then), its end in the body's frame now. A body
    // that moved onto a resting finger is then entered through the face that met the finger,
    // where a path taken in the current frame alone would be a point and enter nothing.
    const std::int64_t last_haptic = state.tick - model.rates.servo / model.rates.haptic;
    double best_t = kInfinity;
    collision.bodies_touching_segment(a, hip, r, scratch);
    for (int b : scratch) {
      const BodyState& bs = state.bodies[b];
      const bool moved = fs.has_last_haptic && bs.stepped_at >= last_haptic;
      const Pose then = fast_loop_pose(model, bs, last_haptic);
      const Pose now = fast_loop_pose(model, bs, state.tick);
      const Vec3 a_b = moved ? Vec3(bs.rotation_before_step.transpose() * (a - bs.position_before_step))
                             : Vec3(then.rotation.transpose() * (a - then.position));
      const Vec3 hip_b = now.rotation.transpose() * (hip - now.position);
      if (const auto e = surface_entry(collision.surface(b), r, a_b, hip_b); e && e->t < best_t) {
        best_t = e->t;
        fs.body = b;
        fs.features = e->features;
        fs.normal = e->normal;
        fs.god_object = e->point;
        fs.surface_point = e->point;
      }
    }
    const double h = model.floor.height + r;
    if (model.floor.enabled && hip.z() < h) {
      // Crossing z = h: the entry point on the plane; from below already, the HIP's projection.
      const double t = a.z() >= h ? (a.z() - h) / (a.z() - hip.z()) : 0.0;
      if (t < best_t) {
        best_t = t;
        fs.body = kFloor;
        fs.features = Features{1, {0, 0, 0}};
        fs.normal = Vec3::UnitZ();
        fs.god_object = a + t * (hip - a);
        if (a.z() < h) fs.god_object = hip;
        fs.god_object.z() = h;
        fs.surface_point = fs.god_object;
      }
    }
    track = best_t <= 1.0;
    if (track) fs.phase = ContactPhase::kStick;   // a new contact starts sticking
  }

  if (track) {
    const Frame fr = contact_frame(model, state, fs.body);
    const Vec3 hip_c = fr.R.transpose() * (hip - fr.p);   // HIP in the contact frame
    // Step 1: the surface point SP (the frictionless god-object), the contact normal and the
    // depth, tracked from the contact's features: on a box the entered face, on other shapes the
    // walk over the surface (surface.hpp). The floor is the plane z = height + r.
    SurfaceTrack tr;
    bool in_contact = false;
    if (fs.body >= 0) {
      in_contact = surface_track(collision.surface(fs.body), r, fs.features, fs.surface_point,
                                 fs.normal, hip_c, tr);
    } else {
      tr.depth = model.floor.height + r - hip_c.z();
      tr.normal = Vec3::UnitZ();
      tr.point = hip_c + tr.depth * tr.normal;
      tr.features = fs.features;
      in_contact = tr.depth > 0.0;
    }
    if (in_contact) {
      const Vec3& sp = tr.point;
      const double depth = tr.depth;
      // Step 2: friction circle radius = mu * depth: the static coefficient while sticking;
      // while slipping the kinetic one, widened by c v / k for viscous friction c v, so that the
      // sliding force k r is mu_k f_n + c v, v the finger's tangential speed over the surface.
      const ContactPair pair = finger_contact_pair(model, finger, fs.body);
      const bool was_slipping = fs.phase == ContactPhase::kSlip;
      // The finger's tangential velocity over the surface: needed only by a slipping finger
      // (whether it sticks again) and by viscous friction, so a sticking one skips it.
      Vec3 v_rel_t = Vec3::Zero();   // m/s, world
      if (was_slipping || pair.viscous > 0.0) {
        const Vec3 n_w = fr.R * tr.normal;
        const Vec3 go_w = fr.R * fs.god_object + fr.p;
        Vec3 v_rel = fs.has_last_haptic
            ? Vec3((hip - fs.hip_at_last_haptic) * static_cast<double>(model.rates.haptic))
            : Vec3::Zero();
        if (fs.body >= 0) {
          const BodyState& bs = state.bodies[fs.body];
          v_rel -= fr.v + bs.angular_velocity.cross(go_w - fr.p);
        }
        v_rel_t = v_rel - v_rel.dot(n_w) * n_w;
      }
      const double viscous = pair.viscous * v_rel_t.norm();  // N, while slipping
      const double kinetic_radius = pair.friction(true) * depth + viscous / pair.stiffness;
      // Steps 3 and 4: move the GO onto the circle only when it lies outside (stick_slip_step
      // says when a slipping finger sticks again). The circle is measured along the chord GO-SP;
      // after a traversal GO and SP may lie on different faces, and a GO moved along the chord
      // is put back onto the surface by the same walk, from SP (surface_project; a box's GO
      // stays on its face's plane, unchanged).
      const Vec3 before = fs.god_object;
      const bool slipped = stick_slip_step(sp, pair.mu * depth, kinetic_radius,
                                           fr.R.transpose() * v_rel_t, was_slipping, fs.god_object);
      if (slipped && fs.body >= 0 && collision.surface(fs.body).shape().kind != ShapeKind::kBox) {
        // Projecting a GO that the chord put under a convex edge moves it out, which can take
        // it a little past the circle: the chord point is then scaled towards SP by s, with
        // |project(SP + s (GO - SP)) - SP| = radius solved by the secant method (a few
        // rounds), keeping the largest s found inside the circle (s = 0 is SP itself).
        const SurfaceGeometry& surface = collision.surface(fs.body);
        const double circle = sliding_radius(was_slipping, pair.mu * depth, kinetic_radius);
        const Vec3 chord = fs.god_object - sp;
        const auto off = [&](double s) {
          return (surface_project(surface, r, tr, sp + s * chord) - sp).norm() - circle;
        };
        double s0 = 0.0, f0 = -circle, s1 = 1.0, f1 = off(1.0), inside = f1 <= 1e-12 * circle ? 1.0 : 0.0;
        for (int round = 0; round < 8 && inside < 1.0 && std::abs(f1) > 1e-12 * circle; ++round) {
          const double s2 = std::clamp(s1 - f1 * (s1 - s0) / (f1 - f0), 0.0, 1.0);
          s0 = s1; f0 = f1; s1 = s2; f1 = off(s2);
          if (f1 <= 1e-12 * circle) inside = std::max(inside, s1);
        }
        fs.god_object = surface_project(surface, r, tr, sp + inside * chord);
      }
      fs.surface_point = sp;
      fs.normal = tr.normal;
      fs.features = tr.features;
      // The tick the finger breaks away, its GO goes onto the static circle (the force peaks at
      // mu_s f_n); from the next tick on it slides on the kinetic one.
      const bool sliding = slipped && was_slipping;
      const double radius = sliding ? kinetic_radius : pair.mu * depth;
      fs.friction_mu = sliding ? pair.friction(true) : pair.mu;
      fs.viscous_force = sliding ? viscous : 0.0;
      fs.friction_radius = radius;
      fs.phase = slipped ? ContactPhase::kSlip : ContactPhase::kStick;
      rec.slip = (fs.god_object - before).norm();
      // Step 5, the force from HIP, GO and stiffness, is finger_force(), run at the servo rate.
      rec.god_object = fr.R * fs.god_object + fr.p;
      rec.surface_point = fr.R * sp + fr.p;
      rec.depth = depth;
      rec.friction_radius = radius;
      rec.phase = fs.phase;
      rec.body = fs.body;
    } else {
      // The HIP left the body (the frictionless god-object reached it), or, on a box, left the
      // entered face over its edge (boxes keep the paper's "no traversal of polygon
      // boundaries"): the contact ends.
      track = false;
    }
  }

  if (!track) {
    fs.phase = ContactPhase::kFree;
    fs.viscous_force = 0.0;
    fs.friction_radius = 0.0;
    fs.body = kNoBody;
    fs.god_object = hip;
    rec.god_object = hip;
    rec.surface_point = hip;
    rec.depth = 0.0;
    rec.friction_radius = 0.0;
    rec.phase = ContactPhase::kFree;
    rec.body = kNoBody;
  }
  fs.hip_at_last_haptic = hip;
  fs.has_last_haptic = true;
}

Vec3 finger_force(const Model& model, const State& state, int finger, const Vec3& hip,
                  Vec3& contact_point) {
  const FingerState& fs = state.fingers[finger];
  if (fs.phase == ContactPhase::kFree) {
    contact_point = hip;
    return Vec3::Zero();
  }
  const Frame fr = contact_frame(model, state, fs.body);
  const Vec3 go_world = fr.R * fs.god_object + fr.p;
  const Vec3 n_w = fr.R * fs.normal;   // the contact normal at SP at the last haptic tick
  contact_point = go_world - model.fingers[finger].radius * n_w;   // on the surface
  const ContactPair pair = finger_contact_pair(model, finger, fs.body);
  Vec3 force = pair.stiffness * (go_world - hip);
  const double c = model.fingers[finger].damping;
  if (c > 0.0) {
    // No previous sample on the first tick: the HIP is taken to be at rest.
    const Vec3 v_hip = state.tick > 0
        ? Vec3((hip - fs.hip_at_last_servo) * static_cast<double>(model.rates.servo))
        : Vec3::Zero();
    Vec3 v_go = Vec3::Zero();
    if (fs.body >= 0) {
      const BodyState& bs = state.bodies[fs.body];
      v_go = fr.v + bs.angular_velocity.cross(contact_point - fr.p);
    }
    force += c * (v_go - v_hip);
  }
  // The contact force stays inside the friction cone at every servo tick: it never pulls, and
  // its tangential part never exceeds mu times its normal part. The friction circle keeps the
  // spring inside the cone at haptic ticks; between them the HIP moves on while the GO waits,
  // and a damper is not bounded by the circle at all (it would act as viscous drag).
  const double f_n = n_w.dot(force);
  if (f_n <= 0.0) return Vec3::Zero();
  const Vec3 f_t = force - f_n * n_w;
  const double limit = fs.friction_mu * f_n + fs.viscous_force;   // as at the last haptic tick
  if (f_t.squaredNorm() > limit * limit) force = f_n * n_w + f_t * (limit / f_t.norm());
  return force;
}

}  // namespace graspsim
