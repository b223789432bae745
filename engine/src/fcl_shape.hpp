// FCL geometry of a Shape (private to the engine: FCL types stay out of the public headers).
#pragma once

#include <memory>

#include <fcl/geometry/collision_geometry.h>

#include "graspsim/engine/shape.hpp"

namespace graspsim::detail {

// The FCL geometry of `shape`, in the body frame: Box, Sphere, Cylinder and Capsule (axis z),
// Convex from the hull's faces, and a BVHModel<OBBRSS> of the triangles for kMesh.
std::shared_ptr<fcl::CollisionGeometryd> fcl_geometry(const Shape& shape);

}  // namespace graspsim::detail
