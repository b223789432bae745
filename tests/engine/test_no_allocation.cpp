// Simulation::step allocates nothing after warm-up (Drake's rule for the servo tick): a heap
// allocation can take microseconds and its timing is unbounded, which a 3 kHz device loop
// cannot afford. Counted with a replaced global operator new (this executable only).
#include <catch2/catch.hpp>

#include <atomic>
#include <cstdlib>
#include <new>

#include "graspsim/engine/state_hash.hpp"
#include "tests/engine/harness.hpp"
#include "tests/engine/shapes.hpp"
#include "bench/mesh_grasp_scene.hpp"

#include "tests/support/count_allocations.hpp"

using graspsim::test::g_allocations;

using namespace graspsim;

// A two-finger pinch of a box on the floor, with the fingers free and moving (broadphase queries
// at every haptic tick), then in contact (friction cone, forces, windows), through physics steps
// (floor contact, integration, broadphase update). After the first 10 ticks, no allocation.
TEST_CASE("a simulation step allocates no heap memory after warm-up", "[schedule][realtime]") {
  Model m;
  m.floor.enabled = true;
  m.floor.material = Material{0.8, 100.0, 1.0};
  m.bodies.push_back(graspsim::test::make_box("box", 0.4, Vec3(0.04, 0.04, 0.04), Vec3(0.0, 0.0, 0.03),
                                              Material{0.8, kInfinity, kInfinity}));
  m.bodies.push_back(graspsim::test::make_box("other", 0.4, Vec3(0.04, 0.04, 0.04), Vec3(0.5, 0.0, 0.03),
                                              Material{0.8, kInfinity, kInfinity}));
  m.fingers.push_back(graspsim::test::make_finger("thumb", 400.0, 4.0));
  m.fingers.push_back(graspsim::test::make_finger("index", 400.0, 4.0));
  Simulation sim(m);
  const auto hips = [](std::size_t i, double t) {
    const double side = i == 0 ? -1.0 : 1.0;
    const double x = side * std::max(0.03, 0.1 - 0.1 * t);   // contact from about t = 0.6 s
    return Vec3(x, 0.0, 0.03 + 0.02 * std::max(0.0, t - 1.0));
  };
  Input input = make_input(m);
  TickRecord record = make_tick_record(m);
  std::uint64_t hashes = 0;   // the run loop hashes the State after every physics tick
  const auto step = [&] {
    for (std::size_t i = 0; i < 2; ++i) input.fingers[i].hip = hips(i, sim.time());
    sim.step(input, record);
    if (record.physics_ran) hashes ^= state_hash(sim.state());
  };
  for (int n = 0; n < 10; ++n) step();
  const long before = g_allocations.load();
  int contacts = 0;
  for (int n = 0; n < 3000 * 2; ++n) {
    step();
    if (record.haptic_ran && record.haptic[0].phase != ContactPhase::kFree) ++contacts;
  }
  const long during = g_allocations.load() - before;
  CHECK(during == 0);
  CHECK(contacts > 100);   // both regimes were visited
  CHECK(hashes != 0);
}

// The same with every option on: implicit gyroscopic term (3x3 LU), two-finger torsion by gravity
// drop (inertial and quasi-static) with a dead band, kinetic and viscous friction, spherical pads,
// under both integrators (the implicit step's islands, active set and solve). Zero allocations.
TEST_CASE("a simulation step with every option allocates no heap memory", "[schedule][realtime]") {
  for (Integrator integrator : {Integrator::kPaper, Integrator::kImplicit})
  for (Gyroscopic gyro : {Gyroscopic::kExplicit, Gyroscopic::kImplicit}) {
    INFO((integrator == Integrator::kPaper ? "paper" : "implicit") << " integrator");
    Model m;
    m.integrator = integrator;
    m.gyroscopic = gyro;
    m.grasp.torsion = Torsion::kGravityDrop;
    m.grasp.critical_area = 1e-3;
    m.grasp.dead_band = 1e-4;
    // The inertial torsion with the explicit term, the quasi-static one (a rigid turn about the
    // axis per step) with the implicit term.
    m.grasp.torsional_damping = gyro == Gyroscopic::kImplicit ? 0.01 : 0.0;
    m.floor.enabled = true;
    m.floor.material = Material{0.8, 100.0, 1.0, 0.5, 2.0};
    m.bodies.push_back(graspsim::test::make_box("box", 0.4, Vec3(0.04, 0.04, 0.04), Vec3(0.0, 0.0, 0.03),
                                                Material{0.8, kInfinity, kInfinity, 0.5, 3.0}));
    for (const char* name : {"thumb", "index"}) {
      FingerParams f = graspsim::test::make_finger(name, 400.0, 4.0);
      f.radius = 0.005;
      m.fingers.push_back(f);
    }
    Simulation sim(m);
    Input input = make_input(m);
    TickRecord record = make_tick_record(m);
    const auto step = [&] {
      const double t = sim.time();
      for (std::size_t i = 0; i < 2; ++i) {
        const double side = i == 0 ? -1.0 : 1.0;
        input.fingers[i].hip = Vec3(side * std::max(0.035, 0.1 - 0.1 * t), 0.0, 0.03 + 0.03 * std::max(0.0, t - 1.0));
      }
      sim.step(input, record);
    };
    for (int n = 0; n < 10; ++n) step();
    const long before = g_allocations.load();
    int held = 0;
    for (int n = 0; n < 3000 * 2; ++n) {
      step();
      if (record.physics_ran && record.physics[0].grasp_area > 0.0) ++held;
    }
    CHECK(g_allocations.load() - before == 0);
    CHECK(held > 10);   // the torsion path ran
  }
}

// Bodies of every shape kind on the floor and on each other, through the body-body paths that
// are ours: a cylinder (its prism) and a convex hull on a box (manifolds), a sphere on a mesh
// slab (our sphere-triangle test); a capsule on the floor alone. The broadphase updates each FCL
// geometry (box, sphere, cylinder, capsule, convex, BVH mesh) every physics step. Not here: the
// pairs that go through fcl::collide (capsule or sphere against the others, anything but a
// sphere against a mesh), where FCL's GJK/EPA and result vectors may allocate.
TEST_CASE("bodies of every shape step without heap allocation after warm-up", "[schedule][realtime][shape]") {
  Model m;
  m.rates.physics = 500;
  m.floor.enabled = true;
  m.floor.material = Material{0.8, 20000.0, 40.0};
  TriangleMesh slab;
  {
    const ConvexPolyhedron p = box_polyhedron(Vec3(0.06, 0.06, 0.01));
    slab.vertices = p.vertices;
    for (const PolyFace& f : p.faces) {
      slab.triangles.push_back({f.vertices[0], f.vertices[1], f.vertices[2]});
      slab.triangles.push_back({f.vertices[0], f.vertices[2], f.vertices[3]});
    }
  }
  TriangleMesh cube = slab;
  for (Vec3& v : cube.vertices) v = Vec3(v.x() / 3.0, v.y() / 3.0, 2.0 * v.z());   // 4 x 4 x 4 cm
  const Material rigid{0.8, kInfinity, kInfinity}, soft{0.8, 1000.0, 10.0};
  struct Placed { Shape shape; Vec3 position; Material material; };
  const Placed bodies[] = {
      {box_shape(Vec3(0.1, 0.06, 0.02)), Vec3(0.0, 0.0, 0.0198), rigid},
      {cylinder_shape(0.02, 0.03), Vec3(-0.05, 0.0, 0.0705), soft},
      {convex_shape(cube), Vec3(0.05, 0.0, 0.0605), soft},
      {mesh_shape(slab), Vec3(0.5, 0.0, 0.0099), rigid},
      {sphere_shape(0.02), Vec3(0.5, 0.0, 0.0405), soft},
      {capsule_shape(0.01, 0.02), Vec3(1.0, 0.0, 0.0105), soft}};
  for (const Placed& p : bodies) {
    BodyParams b;
    b.name = "body" + std::to_string(m.bodies.size());
    b.shape = p.shape;
    const MassProperties mp = mass_properties(p.shape, 1000.0);
    b.mass = mp.mass;
    b.inertia = mp.inertia.diagonal();
    b.position = p.position;
    b.material = p.material;
    m.bodies.push_back(b);
  }
  Simulation sim(m);
  Input input = make_input(m);
  TickRecord record = make_tick_record(m);
  for (int n = 0; n < 10; ++n) sim.step(input, record);
  const long before = g_allocations.load();
  int touching[3] = {0, 0, 0};   // steps with body contact: cylinder, convex, sphere
  for (int n = 0; n < 3000; ++n) {
    sim.step(input, record);
    if (!record.physics_ran) continue;
    touching[0] += record.physics[1].body_contacts > 0;
    touching[1] += record.physics[2].body_contacts > 0;
    touching[2] += record.physics[4].body_contacts > 0;
  }
  CHECK(g_allocations.load() - before == 0);
  // Each contact path ran for many of the 500 physics steps (the bodies land and hop at first).
  CHECK(touching[0] > 100);
  CHECK(touching[1] > 100);
  CHECK(touching[2] > 100);
}

// Finger contact on other shapes: a tessellated sphere (1280 triangles: entry scans, the walk over
// facets, the friction GO projected back onto the surface while slipping), an analytic sphere
// and a cylinder, with pads. After warm-up, zero allocations.
TEST_CASE("finger contact on meshes and round shapes allocates no heap memory", "[schedule][realtime]") {
  Model m;
  m.gravity = Vec3::Zero();
  BodyParams mesh;
  mesh.name = "mesh";
  mesh.shape = graspsim::test::mesh_shape(graspsim::test::icosphere(0.05, 3));
  mesh.mass = 100.0;   // heavy enough to stay under the fingers
  mesh.inertia = Vec3::Constant(0.1);
  mesh.material = Material{0.3, kInfinity, kInfinity, 0.2, 1.0};
  m.bodies.push_back(mesh);
  BodyParams ball = mesh;
  ball.name = "ball";
  ball.shape = Shape{};
  ball.shape.kind = ShapeKind::kSphere;
  ball.shape.radius = 0.04;
  ball.position = Vec3(0.3, 0.0, 0.0);
  m.bodies.push_back(ball);
  BodyParams can = ball;
  can.name = "can";
  can.shape.kind = ShapeKind::kCylinder;
  can.shape.half_length = 0.03;
  can.position = Vec3(-0.3, 0.0, 0.0);
  m.bodies.push_back(can);
  for (const char* name : {"a", "b", "c", "d"}) {
    FingerParams f = graspsim::test::make_finger(name, 400.0, 2.0);
    f.radius = name[0] == 'a' ? 0.0 : 0.004;
    m.fingers.push_back(f);
  }
  Simulation sim(m);
  Input input = make_input(m);
  TickRecord record = make_tick_record(m);
  const auto step = [&] {
    const double t = sim.time();
    const double press = std::min(t, 0.5) * 0.02;   // into each body, then round it
    const Vec3 round(std::cos(2.0 * t), std::sin(2.0 * t) * 0.6, std::sin(2.0 * t) * 0.8);
    input.fingers[0].hip = sim.state().bodies[0].position + (0.06 - press) * round;
    input.fingers[1].hip = Vec3(0.3, 0.0, 0.0) + (0.054 - press) * round;
    input.fingers[2].hip = Vec3(-0.3, 0.0, 0.0) + (0.05 - press) * round;
    input.fingers[3].hip = Vec3(0.1 * std::cos(t), 0.1, 0.0);   // free, passing by
    sim.step(input, record);
  };
  for (int n = 0; n < 10; ++n) step();
  const long before = g_allocations.load();
  int contacts = 0, slipping = 0;
  for (int n = 0; n < 3000 * 2; ++n) {
    step();
    if (!record.haptic_ran) continue;
    for (int f = 0; f < 3; ++f) {
      if (record.haptic[f].phase != ContactPhase::kFree) ++contacts;
      if (record.haptic[f].phase == ContactPhase::kSlip) ++slipping;
    }
  }
  CHECK(g_allocations.load() - before == 0);
  CHECK(contacts > 1000);
  CHECK(slipping > 100);
}

// Body against body: a box resting on a box (a clipped manifold, four points, friction anchors
// matched by feature every step) and a third box falling onto them, through the broadphase and
// the pair state. Zero allocations after warm-up.
TEST_CASE("a step with body-body contact allocates no heap memory", "[schedule][realtime]") {
  Model m;
  m.rates.physics = 500;
  m.floor.enabled = true;
  m.floor.material = Material{0.8, 2000.0, 10.0};
  m.bodies.push_back(graspsim::test::make_box("bottom", 0.4, Vec3(0.06, 0.06, 0.02), Vec3(0.0, 0.0, 0.0195),
                                              Material{0.8, kInfinity, kInfinity}));
  m.bodies.push_back(graspsim::test::make_box("top", 0.2, Vec3(0.03, 0.03, 0.01), Vec3(0.0, 0.0, 0.049),
                                              Material{0.5, 1000.0, 5.0}));
  m.bodies.push_back(graspsim::test::make_box("falling", 0.1, Vec3(0.02, 0.02, 0.02), Vec3(0.01, 0.0, 0.09),
                                              Material{0.5, 1000.0, 5.0}));
  Simulation sim(m);
  sim.record_contacts(true);   // and the contact points listed for a trace
  Input input = make_input(m);
  TickRecord record = make_tick_record(m);
  for (int n = 0; n < 10; ++n) sim.step(input, record);
  const long before = g_allocations.load();
  int touching = 0, recorded = 0;
  for (int n = 0; n < 3000; ++n) {
    sim.step(input, record);
    if (record.physics_ran && record.physics[2].body_contacts > 0) ++touching;
    if (record.physics_ran) recorded = std::max(recorded, static_cast<int>(record.contacts.size()));
  }
  CHECK(g_allocations.load() - before == 0);
  CHECK(touching > 10);   // the falling box landed
  CHECK(recorded > 8);    // and its points were recorded beside the 4 + 4 of the resting two
}

// The real-time profile's scene (bench/mesh_grasp_scene.hpp): three fingers close on a
// 5,120-triangle mesh pebble resting on the floor (entry through the face tree, the walk over
// triangles), lift it and hold it, a box resting untouched nearby; with sleep off and on (the
// pebble and the box fall asleep while the fingers close, and the pebble wakes at the touch).
// After warm-up (the first 10 ticks), no servo tick allocates: not the servo-only ticks, not the
// haptic ones, not the physics ones.
TEST_CASE("three fingers on a 5120-triangle mesh step without heap allocation", "[schedule][realtime][mesh]") {
  for (bool sleep : {false, true}) {
    Model m = graspsim::bench::mesh_grasp_model();
    m.sleep.enabled = sleep;
    Simulation sim(m);
    Input input = make_input(m);
    TickRecord record = make_tick_record(m);
    const auto step = [&] {
      graspsim::bench::mesh_grasp_hips(sim.time(), input);
      sim.step(input, record);
    };
    for (int n = 0; n < 10; ++n) step();
    const long before = g_allocations.load();
    int held = 0, slept = 0;
    const auto ticks = static_cast<int>(graspsim::bench::kSceneDuration * m.rates.servo) - 10;
    for (int n = 0; n < ticks; ++n) {
      step();
      if (record.haptic_ran && record.haptic[0].body == 0 && record.haptic[1].body == 0 && record.haptic[2].body == 0) ++held;
      if (record.physics_ran && sim.state().bodies[1].asleep) ++slept;
    }
    const long during = g_allocations.load() - before;   // before INFO, which allocates
    INFO("sleep " << sleep);
    CHECK(during == 0);
    CHECK(held > 1000);                        // the three fingers held the mesh for over 2 s
    CHECK(sim.state().bodies[0].position.z() > graspsim::bench::kPebbleRest + 0.02);   // lifted
    CHECK((slept > 0) == sleep);               // the sleep paths ran when on
  }
}
