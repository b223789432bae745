// Object contact: the paper's penalty "rotate down" contact of a body with the floor (section
// 4), one force per penetrating vertex, with damping so that energy is lost, and friction by a
// stick anchor per vertex (the friction circle of section 2, applied to object contact).
#pragma once

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

struct Wrench {
  Vec3 force{0.0, 0.0, 0.0};    // N, world
  Vec3 torque{0.0, 0.0, 0.0};   // N m, world, about the body's centre of mass
};

// The eight corners of a box in its body frame, in a fixed order (x fastest, then y, then z).
Vec3 box_vertex(const Vec3& half_extents, int k);

// Floor wrench on body b at its current state, updating its vertices' friction anchors.
// For each vertex at depth d > 0 below the floor, moving at u:
//   normal      f_n = max(0, k d - c u_n)                      (no pull)
//   friction    anchor a kept while |a - x_t| <= mu f_n / k, else moved onto that circle;
//               f_t = k (a - x_t) - c u_t, scaled down to |f_t| <= mu f_n
// where x_t is the vertex projected on the floor and (k, c, mu) = contact_pair(body, floor).
// Returns the number of vertices in contact.
int floor_contact(const Model& model, int body, BodyState& bs, Wrench& out);

}  // namespace graspsim
