// Surface queries per shape (surface.hpp): entry, tracking of the frictionless god-object SP,
// against analytic geometry.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "graspsim/engine/surface.hpp"
#include "tests/engine/shapes.hpp"

using namespace graspsim;

namespace {

// Enters along a -> b, then tracks through `path`, calling `each(hip, track)` at every point;
// REQUIREs the contact to hold throughout.
template <class F>
void enter_and_track(const SurfaceGeometry& g, double r, const Vec3& a, const Vec3& b,
                     const std::vector<Vec3>& path, F each) {
  const auto e = surface_entry(g, r, a, b);
  REQUIRE(e);
  SurfaceTrack at{e->point, e->normal, 0.0, e->features};
  for (const Vec3& hip : path) {
    SurfaceTrack next;
    REQUIRE(surface_track(g, r, at.features, at.point, at.normal, hip, next));
    each(hip, at, next);
    at = next;
  }
}

}  // namespace

// Sphere of radius R, pad r: contact while |p| < R + r, SP = (R + r) p / |p|, depth R + r - |p|,
// normal radial. Swept over r and directions; exact to 1e-15 m (one rounding in the norm). A
// finger pressed past the centre keeps the hemisphere it entered (no push-through).
TEST_CASE("an analytic sphere: SP radial at R + r, depth R + r - |p|", "[surface][sphere][law]") {
  const double R = 0.04;
  for (double r : {0.0, 0.005}) {
    const SurfaceGeometry g(sphere_shape(R));
    // Entry from outside along -x: at x = R + r.
    const auto e = surface_entry(g, r, Vec3(0.1, 0.001, 0.0), Vec3(0.0, 0.001, 0.0));
    REQUIRE(e);
    CHECK(e->point.norm() == Approx(R + r).margin(1e-12));
    CHECK(e->normal.x() > 0.99);
    // A path missing the sphere enters nothing; one ending inside from inside keeps t = 0.
    CHECK_FALSE(surface_entry(g, r, Vec3(0.1, R + r + 1e-4, 0.0), Vec3(-0.1, R + r + 1e-4, 0.0)));
    SurfaceTrack at{e->point, e->normal, 0.0, e->features};
    for (int i = 0; i < 200; ++i) {
      const double phi = 0.03 * i, depth = 0.001 + 0.0001 * (i % 7);
      const Vec3 u(std::cos(phi), std::sin(phi) * std::cos(0.3), std::sin(phi) * std::sin(0.3));
      const Vec3 hip = (R + r - depth) * u;
      SurfaceTrack tr;
      REQUIRE(surface_track(g, r, at.features, at.point, at.normal, hip, tr));
      CHECK(tr.depth == Approx(R + r - hip.norm()).margin(1e-15));
      CHECK((tr.point - (R + r) * hip.normalized()).norm() < 1e-15);
      CHECK((tr.normal - hip.normalized()).norm() < 1e-15);
      at = tr;
    }
    // Outside: the contact ends.
    SurfaceTrack tr;
    CHECK_FALSE(surface_track(g, r, at.features, at.point, at.normal, (R + r + 1e-6) * at.normal, tr));
    // Pressed through the centre along -n: SP stays on the entered side, depth grows.
    const Vec3 n = at.normal;
    for (double s : {0.5 * R, 0.0, -0.5 * R}) {
      REQUIRE(surface_track(g, r, at.features, at.point, at.normal, s * n, tr));
      CHECK((tr.normal - n).norm() < 1e-15);
      CHECK(tr.depth == Approx(R + r - s).margin(1e-15));
    }
  }
}

// Capsule: the segment z in [-L, L] grown by R + r. SP = q + (R + r) (p - q)/|p - q| with q the
// closest axis point: continuous over the rim from side to cap (tested on a path around it).
TEST_CASE("a capsule: SP about the closest axis point, smooth over the rim", "[surface][capsule][law]") {
  const double R = 0.02, L = 0.03, d = 0.002;
  for (double r : {0.0, 0.004}) {
    const SurfaceGeometry g(capsule_shape(R, L));
    // Up the side at depth d, then over the top hemisphere, to the pole.
    std::vector<Vec3> path;
    for (int i = 0; i <= 100; ++i) path.emplace_back(R + r - d, 0.0, -0.01 + 0.04 * i / 100.0);
    for (int i = 0; i <= 100; ++i) {
      const double a = 0.5 * M_PI * i / 100.0;
      path.emplace_back((R + r - d) * std::cos(a), 0.0, L + (R + r - d) * std::sin(a));
    }
    int cap = 0;
    Vec3 prev = path.front();
    enter_and_track(g, r, Vec3(0.1, 0.0, -0.01), path.front(), path,
                    [&](const Vec3& hip, const SurfaceTrack& before, const SurfaceTrack& tr) {
      const Vec3 q(0.0, 0.0, std::clamp(hip.z(), -L, L));
      CHECK(tr.depth == Approx(d).margin(1e-15));
      CHECK((tr.point - (q + (R + r) * (hip - q).normalized())).norm() < 1e-15);
      // SP moves on radius R + r while the HIP moves on R + r - d: at most (R + r)/(R + r - d)
      // times as far.
      CHECK((tr.point - before.point).norm() <= (hip - prev).norm() * (R + r) / (R + r - d) * (1.0 + 1e-9) + 1e-15);
      prev = hip;
      if (tr.features.ids[0] == 1) ++cap;
    });
    CHECK(cap > 50);
  }
}

// Cylinder, point finger: held on the entered side while the HIP is inside, however close to the
// rim (no jump to the cap); it ends when the HIP leaves the body over the rim. Pressed into a
// cap beyond the bottom, it stays on the cap.
TEST_CASE("a cylinder: a point finger keeps its side up to the rim and its cap through the body", "[surface][cylinder][law]") {
  const double R = 0.02, L = 0.03;
  const SurfaceGeometry g(cylinder_shape(R, L));
  const auto e = surface_entry(g, 0.0, Vec3(0.05, 0.0, 0.0), Vec3(0.015, 0.0, 0.0));
  REQUIRE(e);
  CHECK(e->point.x() == Approx(R).margin(1e-12));
  CHECK(e->features.ids[0] == 0);
  SurfaceTrack at{e->point, e->normal, 0.0, e->features};
  // Up the side, 5 mm deep (deeper than the 1e-4 m it comes under the cap): side throughout.
  for (double z = 0.0; z < L; z += 0.001) {
    const Vec3 hip(R - 0.005, 0.0, std::min(z, L - 1e-4));
    SurfaceTrack tr;
    REQUIRE(surface_track(g, 0.0, at.features, at.point, at.normal, hip, tr));
    CHECK(tr.features.ids[0] == 0);
    CHECK(tr.depth == Approx(0.005).margin(1e-15));
    CHECK((tr.point - Vec3(R, 0.0, hip.z())).norm() < 1e-15);
    at = tr;
  }
  SurfaceTrack tr;
  CHECK_FALSE(surface_track(g, 0.0, at.features, at.point, at.normal, Vec3(R - 0.005, 0.0, L + 1e-6), tr));
  // Into the top cap, then on through the body and out below: the cap holds.
  const auto top = surface_entry(g, 0.0, Vec3(0.005, 0.0, 0.05), Vec3(0.005, 0.0, -0.05));
  REQUIRE(top);
  CHECK(top->features.ids[0] == 1);
  CHECK(top->point.z() == Approx(L).margin(1e-12));
  SurfaceTrack cap{top->point, top->normal, 0.0, top->features};
  for (double z : {0.02, 0.0, -0.029}) {
    REQUIRE(surface_track(g, 0.0, cap.features, cap.point, cap.normal, Vec3(0.005, 0.0, z), tr));
    CHECK(tr.features.ids[0] == 1);
    CHECK(tr.depth == Approx(L - z).margin(1e-15));
  }
}

// Cylinder with a pad (exact Minkowski sum, rounded rim): a pad sliding up the side, over the rim
// and onto the cap at a constant depth d < r stays in contact, depth d throughout (1e-15 m),
// SP continuous (it moves at most r / (r - d) times as far as the HIP round the rim) and the
// normal turns from +x to +z.
TEST_CASE("a cylinder with a pad: over the rounded rim from side to cap", "[surface][cylinder][pad][law]") {
  const double R = 0.02, L = 0.03, r = 0.005, d = 0.002, step = 0.0002;
  const SurfaceGeometry g(cylinder_shape(R, L));
  std::vector<Vec3> path;
  for (double z = L - 0.01; z < L; z += step) path.emplace_back(R + r - d, 0.0, z);
  const int arc = 60;
  for (int i = 0; i <= arc; ++i) {
    const double a = 0.5 * M_PI * i / arc;
    path.emplace_back(R + (r - d) * std::cos(a), 0.0, L + (r - d) * std::sin(a));
  }
  for (double x = R; x > 0.005; x -= step) path.emplace_back(x, 0.0, L + r - d);
  double last_nz = -1.0;
  Vec3 prev = path.front();
  bool saw[5] = {false, false, false, false, false};
  enter_and_track(g, r, Vec3(0.1, 0.0, path.front().z()), path.front(), path,
                  [&](const Vec3& hip, const SurfaceTrack& before, const SurfaceTrack& tr) {
    CHECK(tr.depth == Approx(d).margin(1e-15));
    CHECK(tr.normal.z() >= last_nz - 1e-12);   // turns monotonically towards +z
    last_nz = tr.normal.z();
    saw[tr.features.ids[0]] = true;
    CHECK((tr.point - before.point).norm() <= (hip - prev).norm() * r / (r - d) * (1.0 + 1e-9) + 1e-15);
    prev = hip;
  });
  CHECK(saw[0]);
  CHECK(saw[3]);
  CHECK(saw[1]);
  CHECK(last_nz == Approx(1.0));

  // From the rim into the core through the cap plane (the HIP 3 mm in from the side, 0.5 mm under
  // the cap): the cap just crossed holds it, SP = (x, y, L + r), depth L + r - z; the side would
  // give R + r - rho = 8 mm.
  SurfaceTrack rim;
  REQUIRE(surface_track(g, r, Features{1, {3, 0, 0}}, Vec3(R + r, 0.0, L), Vec3::UnitX(),
                        Vec3(R + 0.001, 0.0, L + 0.001), rim));
  CHECK(rim.features.ids[0] == 3);
  SurfaceTrack in;
  REQUIRE(surface_track(g, r, rim.features, rim.point, rim.normal, Vec3(R - 0.003, 0.0, L - 0.0005), in));
  CHECK(in.features.ids[0] == 1);
  CHECK(in.depth == Approx(r + 0.0005).margin(1e-15));
  CHECK((in.point - Vec3(R - 0.003, 0.0, L + r)).norm() < 1e-15);
}
