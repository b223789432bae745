// The points of a body that meet the floor (paper, section 4: the "rotate down" contact is
// computed at the vertices), per shape kind, and how far they reach from the centre of mass.
#pragma once

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/shape.hpp"

namespace graspsim {

// The eight corners of a box in its body frame, in a fixed order (x fastest, then y, then z).
Vec3 box_vertex(const Vec3& half_extents, int k);

// Floor points per shape kind: box 8 corners; convex hull and mesh their vertices; sphere its
// lowest point; capsule the lowest points of its two end spheres; cylinder 12 points on each cap's
// rim (a 12-sided prism: caps of every orientation rest on them, exactly when lying flat).
inline constexpr int kCylinderRimPoints = 12;
int floor_point_count(const Shape& shape);

// m: how far from its centre of mass a body reaches the floor in any orientation: its farthest
// floor point (a rolling point is at radius r from a centre point; the capsule's at L + r).
double floor_reach(const Shape& shape);

// Floor point k of a body turned by `rotation`, as an offset (m, world) from its centre of mass.
// `rolling` says the point is not a fixed material point but the lowest point of a round surface
// (sphere, capsule end), which the body rolls over.
Vec3 floor_point(const Shape& shape, const Mat3& rotation, int k, bool& rolling);

}  // namespace graspsim
