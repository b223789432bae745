// Objects of every shape in a scenario: fields, mass properties from density or mass, meshes
// read from OBJ and STL files (placed by their file frame), the reader's error messages, and a
// short free fall of every shape.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <sys/stat.h>

#include <catch2/catch.hpp>

#include "graspsim/engine/record.hpp"
#include "graspsim/engine/simulation.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "mesh_file.hpp"
#include "scenario_files.hpp"

using Catch::Matchers::Contains;
using graspsim::BodyParams;
using graspsim::Mat3;
using graspsim::Quat;
using graspsim::ShapeKind;
using graspsim::Vec3;
using graspsim::scripting::Scenario;
using scripting_test::data_path;
using scripting_test::load_error;
using scripting_test::write_scenario;

namespace {

constexpr double kPi = 3.14159265358979323846;

const BodyParams& body(const Scenario& s, const std::string& name) {
  for (const BodyParams& b : s.model().bodies) {
    if (b.name == name) return b;
  }
  FAIL("no body " << name);
  return s.model().bodies.front();
}

bool close(double a, double b, double relative) { return std::abs(a - b) <= relative * std::abs(b); }

// A scenario with one object whose fields are `fields`, written next to the mesh files.
std::string one_object(const std::string& name, const std::string& fields) {
  return write_scenario(name, "return { duration = 1, objects = { { name = 'm', " + fields + " } } }\n");
}

std::string write_file(const std::string& name, const std::string& bytes) { return write_scenario(name, bytes); }

// A cube of side 2 (units of the file) as OBJ text: 8 vertices, 6 quads, counter-clockwise from outside.
const char* kCubeObj =
    "v -1 -1 -1\nv 1 -1 -1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\n"
    "f 2 4 8 6\nf 1 5 7 3\nf 3 7 8 4\nf 1 2 6 5\nf 5 6 8 7\nf 1 3 4 2\n";

// Binary STL of the triangles (each 3 corners), with an 80-byte header.
std::string binary_stl(const std::vector<std::array<Vec3, 3>>& triangles, const std::string& header) {
  std::string out = header;
  out.resize(80, ' ');
  const auto u32 = static_cast<std::uint32_t>(triangles.size());
  out.append(reinterpret_cast<const char*>(&u32), 4);
  for (const auto& t : triangles) {
    float f[12] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
      for (int i = 0; i < 3; ++i) f[3 + 3 * k + i] = static_cast<float>(t[k][i]);
    }
    out.append(reinterpret_cast<const char*>(f), sizeof f);
    out.append(2, '\0');
  }
  return out;
}

// The cube's triangles (from kCubeObj's quads, fanned), as corners.
std::vector<std::array<Vec3, 3>> cube_triangles() {
  const Vec3 v[8] = {{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {-1, 1, 1}, {1, 1, 1}};
  const int quads[6][4] = {{2, 4, 8, 6}, {1, 5, 7, 3}, {3, 7, 8, 4}, {1, 2, 6, 5}, {5, 6, 8, 7}, {1, 3, 4, 2}};
  std::vector<std::array<Vec3, 3>> out;
  for (const auto& q : quads) {
    out.push_back({v[q[0] - 1], v[q[1] - 1], v[q[2] - 1]});
    out.push_back({v[q[0] - 1], v[q[2] - 1], v[q[3] - 1]});
  }
  return out;
}

std::string ascii_stl(const std::vector<std::array<Vec3, 3>>& triangles) {
  std::string out = "solid cube\n";
  for (const auto& t : triangles) {
    out += "  facet normal 0 0 0\n    outer loop\n";
    for (const Vec3& p : t) out += "      vertex " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
    out += "    endloop\n  endfacet\n";
  }
  return out + "endsolid cube\n";
}

}  // namespace

TEST_CASE("every shape loads with its mass properties from density or mass", "[scripting][shape]") {
  const Scenario s = Scenario::load(data_path("shapes.lua"));
  // box: m = rho x y z, box_inertia.
  CHECK(body(s, "box").shape.kind == ShapeKind::kBox);
  CHECK(body(s, "box").mass == 500.0 * 0.02 * 0.04 * 0.06);
  // sphere: m = rho 4/3 pi r^3, J = 2/5 m r^2.
  const BodyParams& ball = body(s, "ball");
  CHECK(ball.shape.kind == ShapeKind::kSphere);
  CHECK(close(ball.mass, 1000.0 * 4.0 / 3.0 * kPi * 8e-6, 1e-12));
  CHECK(close(ball.inertia.x(), 0.4 * ball.mass * 4e-4, 1e-12));
  // cylinder with its mass given: J_x = m (3 r^2 + L^2) / 12, J_z = m r^2 / 2 whatever the density.
  const BodyParams& can = body(s, "can");
  CHECK(can.shape.kind == ShapeKind::kCylinder);
  CHECK(can.shape.half_length == 0.05);
  CHECK(can.mass == 0.3);
  CHECK(close(can.inertia.x(), 0.3 * (3 * 0.03 * 0.03 + 0.01) / 12, 1e-12));
  CHECK(close(can.inertia.z(), 0.3 * 0.03 * 0.03 / 2, 1e-12));
  // capsule: length is the cylinder part; m = rho pi r^2 (L + 4/3 r).
  const BodyParams& pill = body(s, "pill");
  CHECK(pill.shape.kind == ShapeKind::kCapsule);
  CHECK(close(pill.mass, 1100.0 * kPi * 1e-4 * (0.04 + 4.0 / 3.0 * 0.01), 1e-12));
  // octahedron |x| + |y| + |z| <= r: V = 4/3 r^3 and <x^2> = r^2 / 10, so J = m r^2 / 5.
  const BodyParams& gem = body(s, "gem");
  CHECK(gem.shape.kind == ShapeKind::kConvex);
  CHECK(gem.shape.hull->faces.size() == 8);
  CHECK(close(gem.mass, 2000.0 * 4.0 / 3.0 * 2.7e-5, 1e-12));
  for (int i = 0; i < 3; ++i) CHECK(close(gem.inertia[i], gem.mass * 9e-4 / 5.0, 1e-12));
  // ring: a 16-gon annulus (circumradii R -+ a) times height 2a. A regular n-gon of circumradius
  // c has area n c^2 sin(t) / 2 and polar moment n c^4 sin(t) (2 + cos t) / 12, t = 2 pi / n.
  const BodyParams& ring = body(s, "ring");
  CHECK(ring.shape.kind == ShapeKind::kMesh);
  CHECK(ring.shape.mesh->triangles.size() == 128);
  {
    const double n = 16, t = 2 * kPi / n, R = 0.03, a = 0.006, rho = 800;
    const auto area = [&](double c) { return n * c * c * std::sin(t) / 2; };
    const auto polar = [&](double c) { return n * std::pow(c, 4) * std::sin(t) * (2 + std::cos(t)) / 12; };
    CHECK(close(ring.mass, rho * 2 * a * (area(R + a) - area(R - a)), 1e-12));
    CHECK(close(ring.inertia.z(), rho * 2 * a * (polar(R + a) - polar(R - a)), 1e-12));
    CHECK(close(ring.inertia.x(), ring.inertia.y(), 1e-12));
    CHECK((ring.position - Vec3(0.5, 0, 1)).norm() < 1e-15);   // symmetric: centre at the file origin
  }
  // wedge in mm, scale 0.001: a right prism over the triangle of legs 40 and 30 mm, 20 mm thick.
  const BodyParams& wedge = body(s, "wedge");
  CHECK(close(wedge.mass, 700.0 * 0.5 * 0.04 * 0.03 * 0.02, 1e-12));
  CHECK(wedge.shape.hull->faces.size() == 5);
}

TEST_CASE("a mesh's position and orientation place its file frame, the body sits at its centre of mass",
          "[scripting][shape]") {
  // The wedge's centre of mass is (40/3, 10, 10) mm in its file; the scenario puts the file's
  // origin at p = (0.6, 0, 1), turned 90 degrees about z (q). Law: every mesh vertex lands where
  // the file frame puts it, p + q x_file, whichever frame the body uses internally; and the body's
  // position is the centre of mass, p + q c.
  const Scenario s = Scenario::load(data_path("shapes.lua"));
  const BodyParams& wedge = body(s, "wedge");
  const Quat q(0.7071067811865476, 0, 0, 0.7071067811865476);
  const Vec3 p(0.6, 0, 1), c(0.04 / 3, 0.01, 0.01);
  CHECK((wedge.position - (p + q.normalized() * c)).norm() <= 1e-12);
  // File vertices (mm -> m), in the order the reader meets them.
  const std::vector<Vec3> file = {{0, 0, 0.02}, {0.04, 0, 0.02}, {0, 0.03, 0.02}, {0, 0, 0}, {0, 0.03, 0}, {0.04, 0, 0}};
  const auto& body_vertices = wedge.shape.mesh->vertices;
  REQUIRE(body_vertices.size() == 6);
  for (const Vec3& x : file) {
    const Vec3 world = p + q.normalized() * x;
    double nearest = 1.0;
    for (const Vec3& v : body_vertices) nearest = std::min(nearest, (wedge.position + wedge.orientation * v - world).norm());
    CAPTURE(x.transpose());
    CHECK(nearest <= 1e-15);   // the file's floats are exact (whole mm); the rest is double round-off
  }
  // The body frame is principal: the inertia about body axes is diagonal.
  const graspsim::MassProperties mp = graspsim::mass_properties(wedge.shape, 1.0);
  CHECK(mp.centre.norm() <= 1e-15);
  CHECK(std::abs(mp.inertia(0, 1)) + std::abs(mp.inertia(0, 2)) + std::abs(mp.inertia(1, 2)) <= 1e-12 * mp.inertia.maxCoeff());
}

TEST_CASE("every shape falls freely from a loaded scenario", "[scripting][shape][run]") {
  // Law: with gravity alone each body follows the implicit step's free fall whatever its shape;
  // 1 s at 50 Hz. Its first three steps are backward Euler (BDF2 waits for kSettledSteps), with
  // p_k = p_0 + g (t_k^2 / 2 + h t_k / 2), errors e_2 = g h^2 and e_3 = 3/2 g h^2 against
  // g t^2 / 2; BDF2 then reproduces the parabola and carries the error as
  // e_{n+1} = (4 e_n - e_{n-1}) / 3 = 7/4 g h^2 - 1/4 g h^2 3^-(n-3) (engine/README.md, "Second
  // order"). Tolerance 1e-12 m (rounding over 50 steps).
  const Scenario s = Scenario::load(data_path("shapes.lua"));
  graspsim::Simulation sim(s.model());
  graspsim::Input input = graspsim::make_input(sim.model());
  graspsim::TickRecord record = graspsim::make_tick_record(sim.model());
  for (int n = 0; n < 3000; ++n) sim.step(input, record);
  const double t = 1.0, dt = 1.0 / 50;
  for (std::size_t i = 0; i < s.model().bodies.size(); ++i) {
    const BodyParams& b = s.model().bodies[i];
    CAPTURE(b.name);
    const Vec3 expected = b.position + s.model().gravity * (0.5 * t * t + dt * dt * (1.75 - 0.25 * std::pow(3.0, -47.0)));
    CHECK((sim.state().bodies[i].position - expected).norm() <= 1e-12);
  }
}

TEST_CASE("the OBJ reader: polygons, negative indices, v/vt/vn, comments and ignored statements",
          "[scripting][shape][mesh_file]") {
  // The same cube written two ways gives the same solid: side 2 cm (scale 0.01), so m = rho 8e-6.
  const std::string plain = write_file("cube_plain.obj", kCubeObj);
  const std::string fancy = write_file("cube_fancy.obj",
      "# a cube\r\nmtllib cube.mtl\no cube\ng side\ns off\n"
      "v -1 -1 -1\nv 1 -1 -1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1  # last\n"
      "vt 0 0\nvn 1 0 0\nusemtl steel\n"
      "f -7/1/1 -5/1/1 -1/1/1 -3/1/1\nf 1//1 5//1 7//1 3//1\nf 3/1 7/1 8/1\nf 3 8 4\nf 1 2 6 5\n"
      "f 5 6 8 7\nf 1 3 4 2\n");
  for (const std::string& file : {plain, fancy}) {
    CAPTURE(file);
    const Scenario s = Scenario::load(one_object("cube_" + std::to_string(file.size()) + ".lua",
        "shape = 'convex', file = '" + std::filesystem::path(file).filename().string() + "', scale = 0.01, density = 1000"));
    const BodyParams& b = s.model().bodies[0];
    CHECK(close(b.mass, 1000 * 8e-6, 1e-12));
    CHECK(b.shape.hull->faces.size() == 6);
    CHECK(close(b.inertia.x(), b.mass * 2e-4 / 3, 1e-12));   // box_inertia: m/3 (h_y^2 + h_z^2)
  }
}

TEST_CASE("the STL reader: binary (even when it starts with 'solid') and ASCII give the same solid",
          "[scripting][shape][mesh_file]") {
  const auto tris = cube_triangles();
  write_file("cube_solid.stl", binary_stl(tris, "solid but binary"));
  write_file("cube_bin.stl", binary_stl(tris, "made by a test"));
  write_file("cube_ascii.stl", ascii_stl(tris));
  for (const char* name : {"cube_solid.stl", "cube_bin.stl", "cube_ascii.stl"}) {
    CAPTURE(name);
    const Scenario s = Scenario::load(one_object(std::string(name) + ".lua",
        std::string("shape = 'mesh', file = '") + name + "', scale = 0.01, mass = 2"));
    const BodyParams& b = s.model().bodies[0];
    CHECK(b.shape.mesh->vertices.size() == 8);   // corners of 12 triangles merged by position
    CHECK(close(b.inertia.x(), 2.0 * 2e-4 / 3, 1e-12));
  }
}

TEST_CASE("mesh file errors name the file and line (OBJ, ASCII STL) or triangle (binary STL)",
          "[scripting][shape][mesh_file][errors]") {
  const std::string dir = std::filesystem::path(write_file("cube.obj", kCubeObj)).parent_path().string();
  const auto error = [&](const std::string& file, const std::string& text, const std::string& shape = "convex") {
    write_file(file, text);
    return load_error(one_object("err_" + file + ".lua", "shape = '" + shape + "', file = '" + file + "', mass = 1"));
  };
  const std::string at = "objects[1] 'm': file: " + dir + "/";
  CHECK_THAT(load_error(one_object("missing.lua", "shape = 'mesh', file = 'nope.obj', mass = 1")),
             Contains(at + "nope.obj: cannot open mesh file: No such file or directory"));
  CHECK_THAT(error("bad_number.obj", "v 0 0 0\nv 1 0 0\nv 0 x1 0\n"), Contains(at + "bad_number.obj:3: bad number 'x1'"));
  CHECK_THAT(error("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n"),
             Contains(at + "bad_index.obj:5: vertex index 4 is out of range (the file has 3 vertices)"));
  CHECK_THAT(error("bad_negative.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\n"),
             Contains(at + "bad_negative.obj:3: vertex index -3 is out of range (2 vertices so far)"));
  CHECK_THAT(error("zero.obj", "v 0 0 0\nf 0 1 1\n"), Contains(at + "zero.obj:2: vertex index 0"));
  // The most negative long: its negation overflows (undefined behaviour), so the range test must
  // not negate it.
  CHECK_THAT(error("min_index.obj", "v 0 0 0\nf 1 2 -9223372036854775808\n"),
             Contains(at + "min_index.obj:2: vertex index -9223372036854775808 is out of range (1 vertices so far)"));
  CHECK_THAT(error("few.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\n"),
             Contains(at + "few.obj: a closed mesh needs at least 4 triangles (got 2)"));
  CHECK_THAT(error("line.obj", std::string(kCubeObj) + "l 1 2\n"), Contains(at + "line.obj:15: unsupported statement 'l'"));
  // A cube without its last face (line 14 of the file): the face on line 9 borders the hole.
  std::string open(kCubeObj);
  open.resize(open.rfind("f "));
  const std::string open_error = error("open.obj", open, "mesh");
  CHECK_THAT(open_error, Contains(at + "open.obj:"));
  CHECK_THAT(open_error, Contains("the mesh is not closed"));
  // One quad turned over (line 13).
  std::string turned(kCubeObj);
  turned.replace(turned.find("f 5 6 8 7"), 9, "f 7 8 6 5");
  CHECK_THAT(error("turned.obj", turned, "mesh"), Contains("not consistently oriented"));
  // The ring is closed but not convex.
  const std::string ring = std::filesystem::canonical(std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/meshes/ring.obj").string();
  const std::string ring_error = load_error(one_object("ring_convex.lua", "shape = 'convex', file = '" + ring + "', mass = 1"));
  CHECK_THAT(ring_error, Contains("ring.obj:"));
  CHECK_THAT(ring_error, Contains("the mesh is not convex"));
  CHECK_THAT(ring_error, Contains("(use shape = \"mesh\" for a non-convex solid)"));
  // STL: a facet of two vertices (ASCII, the facet's line), a truncated binary file, a NaN.
  CHECK_THAT(error("two.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n"),
             Contains(at + "two.stl:2: a facet needs 3 vertices (got 2)"));
  std::string cut = binary_stl(cube_triangles(), "binary");
  cut.resize(cut.size() - 10);
  CHECK_THAT(error("cut.stl", cut), Contains(at + "cut.stl: not an STL file"));
  auto tris = cube_triangles();
  tris[4][1].x() = std::nan("");
  CHECK_THAT(error("nan.stl", binary_stl(tris, "binary")), Contains(at + "nan.stl: triangle 5: vertex 2 is not finite"));
  CHECK_THAT(error("cube.ply", "ply\n"), Contains(at + "cube.ply: unknown mesh file type '.ply' (use .obj or .stl)"));
}

// A mesh is read from a regular file of at most kMaxMeshFileBytes (64 MiB): a link to /dev/zero
// (which reads without end), a FIFO (which blocks until a writer comes, for ever), a directory and
// a larger file are refused at once, naming the file and why; a file of exactly the limit is read
// (and refused for what it holds). The big files are sparse: no disk is used.
TEST_CASE("a mesh file must be a regular file of at most 64 MiB: a device, a FIFO, a directory or a "
          "larger file is refused at once", "[scripting][shape][mesh_file][errors]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(write_file("cube.obj", kCubeObj)).parent_path();
  const auto error = [&](const std::string& file) {
    return load_error(one_object("input_" + file + ".lua", "shape = 'mesh', file = '" + file + "', mass = 1"));
  };
  const std::string at = "objects[1] 'm': file: " + dir.string() + "/";
  std::error_code ec;
  fs::remove(dir / "zero.stl", ec);
  fs::create_symlink("/dev/zero", dir / "zero.stl");
  CHECK_THAT(error("zero.stl"), Contains(at + "zero.stl: cannot read mesh file: it is a character device, not a regular file"));
  fs::remove(dir / "pipe.obj", ec);
  REQUIRE(::mkfifo((dir / "pipe.obj").c_str(), 0600) == 0);
  CHECK_THAT(error("pipe.obj"), Contains(at + "pipe.obj: cannot read mesh file: it is a FIFO, not a regular file"));
  fs::create_directories(dir / "folder.stl");
  CHECK_THAT(error("folder.stl"), Contains(at + "folder.stl: cannot read mesh file: it is a directory, not a regular file"));
  const auto sparse = [&](const std::string& name, std::uintmax_t bytes) {
    write_file(name, "");
    fs::resize_file(dir / name, bytes);
  };
  const std::uint64_t limit = graspsim::scripting::detail::kMaxMeshFileBytes;
  REQUIRE(limit == 64ull << 20);
  sparse("over.stl", limit + 1);
  CHECK_THAT(error("over.stl"), Contains(at + "over.stl: mesh file too large: 67108865 bytes, over the limit of 67108864 bytes"));
  sparse("limit.stl", limit);   // read, and refused for its zeros: not an STL
  CHECK_THAT(error("limit.stl"), Contains(at + "limit.stl: not an STL file"));
  fs::remove(dir / "over.stl");
  fs::remove(dir / "limit.stl");
}

TEST_CASE("shape fields are checked per kind, naming the field", "[scripting][shape][errors]") {
  CHECK_THAT(load_error(one_object("ball_size.lua", "shape = 'sphere', size = {1, 1, 1}, radius = 0.1, mass = 1")),
             Contains("objects[1] 'm': size: does not apply to shape = \"sphere\" (it takes radius)"));
  CHECK_THAT(load_error(one_object("ball_radius.lua", "shape = 'sphere', radius = -0.1, mass = 1")),
             Contains("objects[1] 'm': radius: the radius must be > 0 m and finite (got -0.1)"));
  CHECK_THAT(load_error(one_object("ball_no_radius.lua", "shape = 'sphere', mass = 1")),
             Contains("objects[1] 'm': radius: missing"));
  CHECK_THAT(load_error(one_object("can_length.lua", "shape = 'cylinder', radius = 0.1, length = 0, mass = 1")),
             Contains("objects[1] 'm': length: a cylinder's length must be > 0 m and finite (got 0)"));
  CHECK_NOTHROW(Scenario::load(one_object("pill_zero.lua", "shape = 'capsule', radius = 0.1, length = 0, mass = 1")));
  CHECK_THAT(load_error(one_object("pill_file.lua", "shape = 'capsule', radius = 0.1, length = 0, file = 'x.obj', mass = 1")),
             Contains("objects[1] 'm': file: does not apply to shape = \"capsule\" (it takes radius and length)"));
  CHECK_THAT(load_error(one_object("mesh_scale.lua", "shape = 'mesh', file = 'cube.obj', scale = 0, mass = 1")),
             Contains("objects[1] 'm': scale: must be > 0 and finite (got 0)"));
  CHECK_THAT(load_error(one_object("mesh_nofile.lua", "shape = 'mesh', mass = 1")), Contains("objects[1] 'm': file: missing"));
  CHECK_THAT(load_error(one_object("cone.lua", "shape = 'cone', mass = 1")),
             Contains("objects[1] 'm': shape: unknown shape 'cone'"));
}
