// The viewer's two resources (view/README.md, "Data path"): the scene as JSON (rates, status
// and note, floor, bodies' shapes, fingers, and the blob's layout) and the animated columns as
// one binary blob of little-endian arrays, each at an 8-byte aligned offset, which the page
// views as typed arrays without parsing.
#pragma once

#include <string>

#include "view/server/scene.hpp"

namespace graspsim::view {

struct Packed {
  std::string json;   // /scene.json
  std::string blob;   // /trace.bin
};

// Blob columns (layout entry "name"): "physics_tick", "haptic_tick" (float64, servo ticks),
// "body/<i>/position" (float64, 3 per /physics row), "body/<i>/quaternion" (float64, 4 per row,
// w x y z), "finger/<j>/hip", "finger/<j>/god_object", "finger/<j>/force",
// "finger/<j>/surface_point" (float64, 3 per /haptic row), "finger/<j>/friction_radius"
// (float64, 1 per row), "finger/<j>/state" (int8, 1 per row); for the time series and the grasp
// axis "body/<i>/grasp_area" (m^2), "body/<i>/torsion" (N m), "body/<i>/floor_contacts",
// "body/<i>/body_contacts" (counts) per /physics row and "finger/<j>/depth", "finger/<j>/slip"
// (m), "finger/<j>/body" (index, -2 floor, -1 none) per /haptic row, all float64.
Packed pack_scene(const ViewScene& scene);

}  // namespace graspsim::view
