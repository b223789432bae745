// Polygon boundary traversal (engine/README.md, "Choices, and why"): the god-object walk over
// convex polyhedra and triangle meshes (surface.hpp), and finger contact on every shape kind in a
// Simulation.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "graspsim/engine/grasp_rules.hpp"
#include "graspsim/engine/surface.hpp"
#include "tests/engine/harness.hpp"
#include "tests/engine/shapes.hpp"

using namespace graspsim;
using graspsim::test::make_finger;

namespace {


// The HIP in the body's frame from a tick record (body 0, every loop at one rate).
Vec3 to_body(const TickRecord& rec, const Vec3& world) {
  const BodyRecord& b = rec.physics[0];
  return b.orientation.conjugate() * (world - b.position);
}

// Largest signed distance of x from the faces of a convex polyhedron: 0 on its surface.
double polyhedron_gap(const ConvexPolyhedron& p, const Vec3& x) {
  double gap = -kInfinity;
  for (const auto& f : p.faces) gap = std::max(gap, f.normal.dot(x) - f.offset);
  return gap;
}

}  // namespace

// A 2 mm plate (as a triangle mesh and as a convex polyhedron) pressed from above at 20 N by a
// finger of k = 2000 N/m: the HIP ends 1 cm below the top face, 8 mm beyond the bottom one, and
// in the fast variant crosses the whole plate within one haptic tick (3 m/s at 1 kHz). Law: the
// contact stays on the entered face; GO (= SP, frictionless) on the top plane z = t/2 + r to
// 1e-12 m; the force is k (z_top + r - z_hip) upwards, 20 N at the end (1e-9 relative); it never
// flips to the bottom face. Swept over a point finger and a 3 mm pad, and a sideways slide
// across the top's triangle diagonal while pressed.
TEST_CASE("a 2 mm plate pressed at 20 N keeps the contact on the entered face", "[traversal][plate][law]") {
  const double half_t = 0.001, k = 2000.0;
  const TriangleMesh plate = graspsim::test::voxel_mesh({1, 1, 1}, Vec3(0.1, 0.1, 2 * half_t),
                                                        Vec3(-0.05, -0.05, -half_t),
                                                        [](int, int, int) { return true; });
  const Shape shapes[] = {graspsim::test::mesh_shape(plate),
                          graspsim::test::convex_shape(box_polyhedron(Vec3(0.05, 0.05, half_t)))};
  for (const Shape& shape : shapes) {
    for (double r : {0.0, 0.003}) {
      for (double speed : {0.1, 3.0}) {
        Model m;
        m.gravity = Vec3::Zero();
        m.rates = Rates{1000, 1000, 1000};
        m.bodies.push_back(graspsim::test::fixed_body("plate", shape, Material{0.0, kInfinity, kInfinity}));
        FingerParams f = make_finger("finger", k);
        f.radius = r;
        m.fingers.push_back(f);
        Simulation sim(m);
        const double top = half_t + r, z_end = top - 20.0 / k;
        const auto hip = [&](std::size_t, double t) {
          const double z = std::max(z_end, 0.02 - speed * t);
          const double x = 0.01 + 0.02 * std::clamp(t - 0.3, 0.0, 0.2) / 0.2;   // across the diagonal
          return Vec3(x, 0.004, z);
        };
        int pressed = 0;
        double last_force = 0.0;
        graspsim::test::run(sim, 600, hip, [&](const TickRecord& rec) {
          const Vec3 h = to_body(rec, rec.servo[0].hip);
          if (h.z() >= top) return;
          const HapticFingerRecord& hr = rec.haptic[0];
          REQUIRE(hr.phase != ContactPhase::kFree);
          const Vec3 go = to_body(rec, hr.god_object);
          REQUIRE(go.z() == Approx(top).margin(1e-12));
          REQUIRE(rec.servo[0].force.z() == Approx(k * (top - h.z())).epsilon(1e-9));
          REQUIRE(sim.state().fingers[0].normal.z() == 1.0);
          last_force = rec.servo[0].force.z();
          ++pressed;
        });
        CHECK(pressed > 400);
        // The plate gave way by < 4e-12 m: k times that is 8e-9 N, 4e-10 relative.
        CHECK(last_force == Approx(20.0).epsilon(1e-9));
      }
    }
  }
}

// Over the convex ridge of a roof-shaped prism (its normals turn by theta = 2 atan(h/w) = 53.1
// deg), as a convex polyhedron and as its triangulation: the HIP slides along x at depth d below
// the left slope, then level, over the ridge onto the right slope. Law of the frictionless
// god-object (a local minimum of |SP - HIP| on the surface, reached by the walk): SP is the HIP's
// projection on the left face while that lies on the face, then the right face's projection;
// every step moves SP only to points nearer the HIP than the old SP (the walk's distance
// decreases); SP stays on the surface (1e-12 m). At the switch SP has to jump: the left
// projection reaches the ridge when the right one is already d sin(theta) beyond it, d the depth
// then; so |dSP| <= |dHIP| + d sin(theta) (1e-12 m), with the jump shrinking with d (swept: 2,
// 0.2 and 0.02 mm; at 0.02 mm it is below the 0.05 mm step). The normal turns from n_L to n_R.
// (Friction hides the jump while sin(theta) <= mu: see the friction test below.)
TEST_CASE("a finger slides over a convex edge onto the next face", "[traversal][edge][law]") {
  const double w = 0.04, h = 0.02;
  const ConvexPolyhedron roof = graspsim::test::wedge(w, h, 0.03);
  const Vec3 ridge(0.0, 0.0, h);
  const Vec3 nL = Vec3(-h, 0.0, w).normalized(), nR = Vec3(h, 0.0, w).normalized();
  const double sin_theta = nL.cross(nR).norm();
  for (const Shape& shape : {graspsim::test::convex_shape(roof), graspsim::test::mesh_shape(graspsim::test::triangulate(roof))}) {
    const SurfaceGeometry g(shape);
    for (double d : {0.002, 0.0002, 0.00002}) {
      const double z = h - d / nL.z();   // d below the left slope at the ridge
      const double x_end = 0.5 * (d / nL.z()) * w / h;   // still below the right slope
      const auto hip_at = [&](double x) { return Vec3(x, 0.001, z + std::min(x, 0.0) * h / w); };
      const int steps = 400;
      const double x0 = -0.01;
      const auto e = surface_entry(g, 0.0, hip_at(x0) + 0.01 * nL, hip_at(x0));
      REQUIRE(e);
      SurfaceTrack at{e->point, e->normal, 0.0, e->features};
      Vec3 prev = hip_at(x0);
      bool on_right = false;
      double largest_jump = 0.0;
      for (int i = 0; i <= steps; ++i) {
        const Vec3 hip = hip_at(x0 + (x_end - x0) * i / steps);
        SurfaceTrack tr;
        REQUIRE(surface_track(g, 0.0, at.features, at.point, at.normal, hip, tr));
        CHECK(polyhedron_gap(roof, tr.point) == Approx(0.0).margin(1e-12));
        CHECK((tr.point - hip).norm() <= (at.point - hip).norm() + 1e-12);
        const Vec3 proj_L = hip - nL.dot(hip - ridge) * nL, proj_R = hip - nR.dot(hip - ridge) * nR;
        if (proj_L.x() <= -1e-12 && !on_right) {
          CHECK((tr.point - proj_L).norm() < 1e-12);
          CHECK((tr.normal - nL).norm() < 1e-12);
        } else {
          on_right = true;
          CHECK((tr.point - proj_R).norm() < 1e-12);
          CHECK((tr.normal - nR).norm() < 1e-12);
        }
        const double depth_L = -nL.dot(hip - ridge);
        const double jump = (tr.point - at.point).norm() - (hip - prev).norm();
        CHECK(jump <= std::max(depth_L, 0.0) * sin_theta + 1e-12);
        largest_jump = std::max(largest_jump, jump);
        at = tr;
        prev = hip;
      }
      CHECK(on_right);
      // The left projection reaches the ridge where x = -n_L.x depth_L, and on the level path
      // depth_L = d - n_L.x x: x = 0.559 d, depth_L = d / (1 - n_L.x^2) = 1.25 d; the jump is
      // that times sin(theta), to within one step.
      const double step = (x_end - x0) / steps;
      const double expected = d / (1.0 - nL.x() * nL.x()) * sin_theta;
      CHECK(largest_jump <= expected + step);
      CHECK(largest_jump >= expected - step);
      if (d < 0.0001) CHECK(largest_jump + (x_end - x0) / steps > 0.0);   // the smallest depth:
      if (d < 0.0001) CHECK(largest_jump < (x_end - x0) / steps);         // below one step
    }
  }
}

// A pad (r = 4 mm) over the same ridge, 1 mm deep: the grown surface is the faces moved out by r
// joined by the ridge's cylinder of radius r (the exact Minkowski sum at a convex edge). The HIP
// runs r - d above the left slope, round the ridge on a circle of radius r - d, and down the
// right slope. Law: depth d throughout (1e-12 m); SP continuous, moving at most r / (r - d) times
// as far as the HIP (it runs on radius r where the HIP runs on r - d); on the arc SP is held by
// both faces, SP = ridge + r (HIP - ridge)/|HIP - ridge|; the normal turns monotonically from
// n_L to n_R.
TEST_CASE("a pad goes round a convex edge on its rounded surface, continuously", "[traversal][edge][pad][law]") {
  const double w = 0.04, h = 0.02, r = 0.004, d = 0.001;
  const ConvexPolyhedron roof = graspsim::test::wedge(w, h, 0.03);
  const Vec3 ridge(0.0, 0.001, h);
  const Vec3 nL = Vec3(-h, 0.0, w).normalized(), nR = Vec3(h, 0.0, w).normalized();
  const Vec3 tL = Vec3(w, 0.0, h).normalized(), tR = Vec3(w, 0.0, -h).normalized();
  std::vector<Vec3> path;
  for (int i = 0; i <= 100; ++i) path.push_back(ridge + (r - d) * nL - tL * (0.01 * (1.0 - i / 100.0)));
  const double turn = std::acos(nL.dot(nR));
  const Vec3 across = (nR - nL.dot(nR) * nL).normalized();
  for (int i = 1; i < 60; ++i) {
    const double a = turn * i / 60.0;
    path.push_back(ridge + (r - d) * (std::cos(a) * nL + std::sin(a) * across));
  }
  for (int i = 0; i <= 100; ++i) path.push_back(ridge + (r - d) * nR + tR * (0.01 * i / 100.0));
  for (const Shape& shape : {graspsim::test::convex_shape(roof), graspsim::test::mesh_shape(graspsim::test::triangulate(roof))}) {
    const SurfaceGeometry g(shape);
    const auto e = surface_entry(g, r, path.front() + 0.01 * nL, path.front());
    REQUIRE(e);
    SurfaceTrack at{e->point, e->normal, 0.0, e->features};
    Vec3 prev = path.front();
    double turned = -1.0;   // n . n_R, rising to 1
    int on_edge = 0;
    for (const Vec3& hip : path) {
      SurfaceTrack tr;
      REQUIRE(surface_track(g, r, at.features, at.point, at.normal, hip, tr));
      CHECK(tr.depth == Approx(d).margin(1e-12));
      CHECK((tr.point - (hip + d * tr.normal)).norm() < 1e-12);
      CHECK((tr.point - at.point).norm() <= (hip - prev).norm() * r / (r - d) * (1.0 + 1e-9) + 1e-12);
      CHECK(tr.normal.dot(nR) >= turned - 1e-12);
      turned = tr.normal.dot(nR);
      if (tr.features.count == 2) {
        ++on_edge;
        CHECK((tr.point - (ridge + r * (hip - ridge).normalized())).norm() < 1e-12);
      }
      prev = hip;
      at = tr;
    }
    CHECK(on_edge >= 58);
    CHECK((at.normal - nR).norm() < 1e-12);
  }
}

// Across a sphere of R = 5 cm tessellated in 1280 triangles, the finger pressed 2 mm in along a
// great circle tilted to cross facets at all angles: SP stays on the mesh, so between the inscribed
// and the circumscribed spheres (R - e <= |SP| <= R, e the largest facet's distance below the
// sphere, computed from the mesh), and the normal is within the facet angle (the largest angle
// between a facet normal and its corners' radii, plus the SP's own offset) of the radial direction
// at SP. The contact never ends and its depth stays within e of the analytic 2 mm.
TEST_CASE("across a tessellated sphere: SP within the tessellation error", "[traversal][sphere][law]") {
  const double R = 0.05, d = 0.002;
  const TriangleMesh mesh = graspsim::test::icosphere(R, 3);
  REQUIRE(mesh.triangles.size() == 1280);
  const SurfaceGeometry g(graspsim::test::mesh_shape(mesh));
  double e = 0.0, facet = 0.0;
  for (int f = 0; f < g.face_count(); ++f) {
    const auto& F = g.face(f);
    REQUIRE(F.offset > 0.0);   // wound counter-clockwise from outside
    e = std::max(e, R - F.offset);
    for (int c = 0; c < F.count; ++c) facet = std::max(facet, std::acos(std::min(1.0, F.normal.dot(g.corner(F.first + c).normalized()))));
  }
  const Vec3 axis = Vec3(0.3, 0.2, 1.0).normalized();
  const Vec3 u = axis.cross(Vec3::UnitX()).normalized(), v = axis.cross(u);
  // A pad of radius r runs on the facets moved out by r: between R - e + r and R + r.
  for (double r : {0.0, 0.004}) {
    const auto hip_at = [&](double a) { return (R + r - d) * (std::cos(a) * u + std::sin(a) * v); };
    const auto en = surface_entry(g, r, hip_at(0.0) * 1.2, hip_at(0.0));
    REQUIRE(en);
    SurfaceTrack at{en->point, en->normal, 0.0, en->features};
    int crossings = 0;
    for (int i = 0; i <= 4000; ++i) {
      const Vec3 hip = hip_at(2.0 * M_PI * i / 4000.0);
      SurfaceTrack tr;
      REQUIRE(surface_track(g, r, at.features, at.point, at.normal, hip, tr));
      const double rho = tr.point.norm();
      CHECK(rho <= R + r + 1e-12);
      CHECK(rho >= R - e + r - 1e-12);
      CHECK(std::acos(std::min(1.0, tr.normal.dot(tr.point / rho))) <= facet + 1e-9);
      CHECK(std::abs(tr.depth - d) <= e + 1e-12);
      if (tr.features.ids[0] != at.features.ids[0]) ++crossings;
      at = tr;
    }
    CHECK(crossings > 50);
  }
}

// Concave edge and corner of voxel meshes (cells of 2 cm): an L-shaped solid (floor and wall
// meeting at the edge x = z = 2 cm) and a cube with one octant removed (three faces meeting at the
// corner (2, 2, 2) cm). The finger enters the floor and is pushed into the edge, then the corner.
// Law: held by two planes, SP is the HIP's closest point on the edge line (x = z = 0.02,
// y = y_HIP); by three, SP is the corner; the force is k (SP - HIP) (frictionless, 1e-9
// relative, 1e-12 m).
TEST_CASE("pressed into a concave edge and a concave corner of a mesh", "[traversal][concave][law]") {
  const double k = 1000.0, c = 0.02;
  struct Case {
    TriangleMesh mesh;
    Vec3 above;    // m: start, outside over the floor
    Vec3 end;      // m: final HIP, inside
    Vec3 expect;   // m: SP there
    int planes;
  };
  const Case cases[] = {
      {graspsim::test::voxel_mesh({2, 1, 2}, Vec3::Constant(c), Vec3::Zero(),
                                  [](int i, int, int k) { return !(i == 1 && k == 1); }),
       Vec3(0.031, 0.012, 0.03), Vec3(0.015, 0.012, 0.016), Vec3(c, 0.012, c), 2},
      {graspsim::test::voxel_mesh({2, 2, 2}, Vec3::Constant(c), Vec3::Zero(),
                                  [](int i, int j, int k) { return !(i == 1 && j == 1 && k == 1); }),
       Vec3(0.031, 0.032, 0.03), Vec3(0.015, 0.016, 0.017), Vec3(c, c, c), 3},
  };
  for (const Case& cs : cases) {
    Model m;
    m.gravity = Vec3::Zero();
    m.rates = Rates{1000, 1000, 1000};
    m.bodies.push_back(graspsim::test::fixed_body("solid", graspsim::test::mesh_shape(cs.mesh), Material{0.0, kInfinity, kInfinity}));
    m.fingers.push_back(make_finger("finger", k));
    Simulation sim(m);
    const Vec3 above = cs.above, into(cs.above.x(), cs.above.y(), 0.017);
    const auto hip = [&](std::size_t, double t) {
      if (t < 0.1) return Vec3(above + (into - above) * (t / 0.1));
      return Vec3(into + (cs.end - into) * std::min((t - 0.1) / 0.2, 1.0));
    };
    TickRecord last;
    graspsim::test::run(sim, 400, hip, [&](const TickRecord& rec) { last = rec; });
    const FingerState& fs = sim.state().fingers[0];
    REQUIRE(fs.phase != ContactPhase::kFree);
    CHECK(fs.features.count == cs.planes);
    const Vec3 sp = to_body(last, last.haptic[0].surface_point);
    const Vec3 h = to_body(last, last.servo[0].hip);
    CHECK((sp - cs.expect).norm() < 1e-12);
    const Vec3 expected = k * (last.haptic[0].surface_point - last.servo[0].hip);
    CHECK((last.servo[0].force - expected).norm() <= 1e-9 * expected.norm());
    CHECK((fs.normal - (sp - h).normalized()).norm() < 1e-12);
  }
}

// A path starting inside a convex polyhedron (the body moved onto the finger, or the first tick)
// takes the face nearest to the HIP, as a box does: SP is the HIP's projection on it. Starting
// inside and ending outside enters nothing.
TEST_CASE("a convex polyhedron entered from inside takes the nearest face", "[traversal][surface]") {
  const double w = 0.04, h = 0.02;
  const ConvexPolyhedron roof = graspsim::test::wedge(w, h, 0.03);
  const SurfaceGeometry g(graspsim::test::convex_shape(roof));
  const Vec3 nL = Vec3(-h, 0.0, w).normalized();
  const Vec3 on_left(-0.01, 0.0, h - 0.01 * h / w);
  const Vec3 hip = on_left - 0.002 * nL;
  const auto e = surface_entry(g, 0.0, hip + Vec3(0.0, 0.001, 0.0), hip);
  REQUIRE(e);
  CHECK(e->t == 0.0);
  CHECK((e->normal - nL).norm() < 1e-12);
  CHECK((e->point - on_left).norm() < 1e-12);
  CHECK_FALSE(surface_entry(g, 0.0, hip, on_left + 0.002 * nL));
}

// A mesh with a degenerate (zero-area) triangle: that face is never entered or held, and the
// rest works (no NaN). The plate with one extra triangle on three collinear corners.
TEST_CASE("a degenerate triangle in a mesh is ignored", "[traversal][surface]") {
  TriangleMesh plate = graspsim::test::voxel_mesh({1, 1, 1}, Vec3(0.1, 0.1, 0.002), Vec3(-0.05, -0.05, -0.001),
                                                  [](int, int, int) { return true; });
  plate.triangles.push_back({0, 1, 1});
  const SurfaceGeometry g(graspsim::test::mesh_shape(plate));
  const auto e = surface_entry(g, 0.0, Vec3(0.01, 0.01, 0.01), Vec3(0.01, 0.01, -0.01));
  REQUIRE(e);
  CHECK(e->point.z() == Approx(0.001).margin(1e-15));
  SurfaceTrack tr;
  REQUIRE(surface_track(g, 0.0, e->features, e->point, e->normal, Vec3(0.02, 0.01, -0.005), tr));
  CHECK(tr.point.allFinite());
  CHECK(tr.depth == Approx(0.006).margin(1e-15));
}

// A body moving onto a resting finger (the finger's HIP never moves; a box, the same cube as a
// closed mesh, and as a convex hull, 6 cm, flying at -1 m/s along x in zero gravity, its path
// passing 2 cm off centre in y). The finger's path since its last haptic tick is taken relative to
// the body: from the body's frame before the physics step to its frame after it. The finger
// therefore enters through the -x face, the face the body's motion brought to it, whatever the
// depth of the first haptic tick inside (up to one physics step of motion, 2 cm at 50 Hz). Taken in
// the current frame alone the path is a point: the mesh and hull would enter nothing (the ring of
// handle_lift would fall through its finger) and the box would take its nearest face, +y at 1 cm
// rather than -x at up to 2 cm.
TEST_CASE("a body moving onto a resting finger is entered through the face that met it", "[finger_contact][law]") {
  const Vec3 h(0.03, 0.03, 0.03);
  const TriangleMesh cube = graspsim::test::box_mesh(h);
  for (const Shape& shape : {box_shape(h), graspsim::mesh_shape(cube), graspsim::convex_shape(cube)}) {
    for (int physics : {50, 500}) {
      Model m;
      m.rates.physics = physics;
      m.gravity = Vec3::Zero();
      BodyParams b = graspsim::test::make_box("cube", 0.5, h, Vec3(0.1, -0.02, 0.0), Material{0.5, kInfinity, kInfinity});
      b.shape = shape;
      b.velocity = Vec3(-1.0, 0.0, 0.0);
      m.bodies.push_back(b);
      m.fingers.push_back(make_finger("finger", 100.0));
      Simulation sim(m);
      Input input = make_input(m);   // the HIP stays at the origin
      TickRecord record = make_tick_record(m);
      INFO("shape kind " << static_cast<int>(shape.kind) << ", physics " << physics << " Hz");
      int n = 0;
      while (sim.state().fingers[0].phase == ContactPhase::kFree && n < 3000) {
        sim.step(input, record);
        ++n;
      }
      const FingerState& fs = sim.state().fingers[0];
      REQUIRE(fs.phase != ContactPhase::kFree);
      CHECK(fs.body == 0);
      // Entered through -x: the normal in the body frame, and the GO on that face.
      CHECK(fs.normal.isApprox(Vec3(-1.0, 0.0, 0.0), 1e-12));
      CHECK(fs.god_object.x() == Approx(-h.x()).margin(1e-12));
      // It enters within one physics step of the front face reaching the finger (t = 0.07 s).
      CHECK(sim.time() <= 0.07 + 1.0 / physics + 1e-9);
    }
  }
}
