// The real-time profile's scene (engine/README.md, "Speed"), built in C++ with the engine alone:
// three fingers grasp a 5,120-triangle pebble resting on the floor, lift it 3 cm and hold it, while
// a box rests untouched on the floor nearby. Shared by tools/bench/profile.cpp and the allocation
// test (tests/engine/test_no_allocation.cpp), so both see the same scene.
//
//   pebble   an icosphere of level 4 (20 x 4^4 = 5,120 triangles, 2,562 vertices) scaled to a
//            spheroid of semi-axes 35 x 35 x 25 mm, kind `mesh` (the finger walk over triangles,
//            the entry test over the triangles the path may cross), density 1000 kg/m^3:
//            m = 4/3 pi a b c rho = 0.128 kg (a little less: the facets lie inside)
//   floor    soft, 20 N/m and 0.2 N s/m per vertex: the pebble rests on a few tens of vertices,
//            about 2 mm deep; physics at 250 Hz keeps that stiff patch stable (h^2 K / m << 4)
//   fingers  three of 300 N/m at 120 degrees about the vertical, at the pebble's equator, 8 mm
//            into the surface once closed: 2.4 N each, mu = 0.8: friction 5.8 N against
//            m g = 1.25 N
//   timeline 0-1 s settle (fingers wait 3 cm off the surface), 1-1.5 s close, 1.5-2 s hold,
//            2-2.5 s lift 3 cm, 2.5-4 s hold
#pragma once

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "graspsim/engine/model.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/shape.hpp"

namespace graspsim::bench {

inline constexpr double kPebbleA = 0.035, kPebbleB = 0.035, kPebbleC = 0.025;   // m: semi-axes
inline constexpr double kPebbleRest = 0.0235;   // m: centre height at rest (~1.5 mm deep)
inline constexpr double kSceneDuration = 4.0;   // s

// An icosphere of unit radius subdivided `level` times (20 x 4^level triangles), outward.
inline TriangleMesh unit_icosphere(int level) { return icosphere_mesh(1.0, level); }

// The scene's model (sleep off, as Model's default).
inline Model mesh_grasp_model() {
  Model m;
  m.rates = Rates{3000, 500, 250};
  m.floor.enabled = true;
  m.floor.material = Material{0.8, 20.0, 0.2};
  TriangleMesh mesh = unit_icosphere(4);
  for (Vec3& v : mesh.vertices) v = Vec3(kPebbleA * v.x(), kPebbleB * v.y(), kPebbleC * v.z());
  BodyParams pebble;
  pebble.name = "pebble";
  pebble.shape = mesh_shape(mesh);
  const MassProperties mp = mass_properties(pebble.shape, 1000.0);   // centred, principal by symmetry
  pebble.mass = mp.mass;
  pebble.inertia = mp.inertia.diagonal();
  pebble.position = Vec3(0.0, 0.0, kPebbleRest);
  pebble.material = Material{0.8, kInfinity, kInfinity};
  m.bodies.push_back(pebble);
  BodyParams box;
  box.name = "box";
  const Vec3 h(0.03, 0.03, 0.02);
  box.shape = box_shape(h);
  box.mass = 0.2;
  box.inertia = box_inertia(box.mass, h);
  box.position = Vec3(0.3, 0.0, h.z() - box.mass * 9.81 / (4 * 20.0));   // at rest on 4 corners
  box.material = Material{0.8, kInfinity, kInfinity};
  m.bodies.push_back(box);
  const auto finger = [](const char* name, double k, double c) {
    FingerParams f;
    f.name = name;
    f.stiffness = k;
    f.damping = c;
    return f;
  };
  m.fingers = {finger("thumb", 300.0, 2.0), finger("index", 300.0, 2.0), finger("middle", 300.0, 2.0)};
  return m;
}

// Minimum jerk from 0 at t0 to 1 at t1.
inline double scene_ramp(double t, double t0, double t1) {
  const double u = std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
  return u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
}

// The fingers' HIPs at time t (s): each on its radial line towards the pebble's round equator,
// at 180 (thumb), 60 (index) and -60 (middle) degrees about the vertical: equal and opposite.
inline void mesh_grasp_hips(double t, Input& input) {
  const double close = scene_ramp(t, 1.0, 1.5);
  const double z = kPebbleRest + 0.03 * scene_ramp(t, 2.0, 2.5);
  const double r = kPebbleA + 0.03 - close * (0.03 + 0.008);   // m from the vertical axis
  const double angle[3] = {M_PI, M_PI / 3.0, -M_PI / 3.0};
  for (int i = 0; i < 3; ++i) input.fingers[i].hip = Vec3(r * std::cos(angle[i]), r * std::sin(angle[i]), z);
}

}  // namespace graspsim::bench
