// Shapes: mass properties (analytic and polyhedral), principal frames, faces of convex meshes,
// and the checks that refuse meshes that do not bound a convex or closed solid.
#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include <catch2/catch.hpp>

#include "graspsim/engine/model.hpp"
#include "graspsim/engine/shape.hpp"
#include "test_shape_meshes.hpp"

using namespace graspsim;
using graspsim::test::box_mesh;
using graspsim::test::icosphere;
using graspsim::test::moved;

namespace {

constexpr double kPi = 3.14159265358979323846;

Mat3 rotation(double angle, const Vec3& axis) { return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix(); }

// Largest |a - b| relative to the largest |b|.
double rel_error(const Mat3& a, const Mat3& b) { return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff(); }

bool mentions(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The MeshError `action` throws (fails the test if none).
template <class F>
MeshError mesh_error(F action) {
  try {
    action();
  } catch (const MeshError& e) {
    return e;
  }
  FAIL("no MeshError thrown");
  return MeshError("", -1);
}

// Gauss-Legendre, 3 points: exact for polynomials up to degree 5 on [a, b].
template <class F>
double gauss3(F f, double a, double b) {
  const double m = 0.5 * (a + b), h = 0.5 * (b - a), x = std::sqrt(0.6);
  return h * (5.0 / 9.0 * f(m - h * x) + 8.0 / 9.0 * f(m) + 5.0 / 9.0 * f(m + h * x));
}

}  // namespace

TEST_CASE("Polyhedral mass properties of a box mesh equal the solid box's", "[shape][mass]") {
  // Law: a solid box of half sizes h and density rho has m = 8 rho hx hy hz and principal moments
  // box_inertia(m, h) about its centre, with no products of inertia. The 12-triangle mesh bounds
  // exactly that solid and Eberly's integrals are exact for polyhedra, so only round-off is left:
  // tolerance 1e-12 relative (a few hundred operations at 1e-16).
  const double rho = 780.0;
  for (const Vec3& h : {Vec3(0.05, 0.05, 0.05), Vec3(0.01, 0.2, 0.03), Vec3(1.0, 2.0, 3.0), Vec3(1e-3, 1e-3, 5e-2)}) {
    CAPTURE(h.transpose());
    const MassProperties mp = mass_properties(box_mesh(h), rho);
    const double m = rho * 8.0 * h.prod();
    CHECK(std::abs(mp.mass - m) <= 1e-12 * m);
    CHECK(mp.centre.norm() <= 1e-12 * h.norm());
    const Mat3 expected = box_inertia(m, h).asDiagonal();
    CHECK(rel_error(mp.inertia, expected) <= 1e-12);
    // The analytic box shape gives the same.
    const MassProperties analytic = mass_properties(box_shape(h), rho);
    CHECK(std::abs(analytic.mass - m) <= 1e-12 * m);
    CHECK(rel_error(analytic.inertia, expected) <= 1e-12);
  }
}

TEST_CASE("Parallel axis: a box mesh away from the origin keeps its inertia about its centre", "[shape][mass]") {
  // Law: translating a solid by c moves its centre of mass by c and leaves the inertia about the
  // centre of mass unchanged (the parallel-axis term m(|c|^2 1 - c c^T) belongs to the origin,
  // not to the centre). Tolerance 1e-12 relative: the two-pass integration keeps the shift's
  // cancellation small even 100 sizes away.
  const Vec3 h(0.02, 0.03, 0.05);
  const Mat3 expected = box_inertia(1000.0 * 8.0 * h.prod(), h).asDiagonal();
  for (const Vec3& c : {Vec3(0.1, -0.2, 0.3), Vec3(-5.0, 2.0, 1.0), Vec3(0.0, 0.0, 1e-3)}) {
    CAPTURE(c.transpose());
    const MassProperties mp = mass_properties(moved(box_mesh(h), Mat3::Identity(), c), 1000.0);
    CHECK((mp.centre - c).norm() <= 1e-12 * c.norm());
    CHECK(rel_error(mp.inertia, expected) <= 1e-12);
  }
}

TEST_CASE("A tessellated sphere converges to 4/3 pi r^3 and 2/5 m r^2 at second order", "[shape][mass]") {
  // Law: an icosphere is inscribed in the sphere; each level halves the edge length e, and the
  // gap between a chord-plane and the sphere is ~ e^2 / (8 r), so the relative errors of volume
  // and moment fall as e^2: by a factor 4 per level (second order). The measured ratios (volume:
  // 3.93, 3.98, 3.996, 3.999 from level 3) must lie within 0.15 of 4 from level 3 and within
  // 0.02 from level 5 (the constant settles as the triangles get small), and the
  // inertia is isotropic at every level (icosahedral symmetry), off-diagonals below 1e-12.
  const double r = 0.04, rho = 1200.0;
  const double volume = 4.0 / 3.0 * kPi * r * r * r;
  const double moment = 0.4 * rho * volume * r * r;
  double last_v = 0.0, last_j = 0.0;
  for (int level = 0; level <= 6; ++level) {
    const MassProperties mp = mass_properties(icosphere(r, level), rho);
    const double ev = (volume - mp.mass / rho) / volume;   // inscribed: always too small
    const double ej = (moment - mp.inertia(0, 0)) / moment;
    CAPTURE(level, ev, ej);
    CHECK(ev > 0.0);
    CHECK(ej > 0.0);
    CHECK(std::abs(mp.inertia(1, 1) - mp.inertia(0, 0)) <= 1e-12 * moment);
    CHECK(std::abs(mp.inertia(2, 2) - mp.inertia(0, 0)) <= 1e-12 * moment);
    CHECK(std::abs(mp.inertia(0, 1)) + std::abs(mp.inertia(1, 2)) + std::abs(mp.inertia(0, 2)) <= 1e-12 * moment);
    if (level >= 3) {   // the ratio tends to 4: within 0.15 from level 3, 0.02 from level 5
      const double margin = level >= 5 ? 0.02 : 0.15;
      CHECK(last_v / ev == Approx(4.0).margin(margin));
      CHECK(last_j / ej == Approx(4.0).margin(margin));
    }
    last_v = ev;
    last_j = ej;
  }
}

TEST_CASE("Sphere, cylinder and capsule moments equal their integrals over slices", "[shape][mass]") {
  // Law: a solid of revolution about z with section radius s(z) has m = rho int pi s^2 dz,
  // J_z = rho int pi s^4 / 2 dz (discs) and J_x = rho int (pi s^4 / 4 + pi s^2 z^2) dz (a disc
  // about its diameter plus the parallel-axis term of the slice at height z). For these solids
  // s^2 is a polynomial of degree <= 2 in z on each piece (r^2 on the cylinder, r^2 - (|z| - l)^2
  // on the caps), so the integrands have degree <= 4 and 3-point Gauss-Legendre per piece is
  // exact: an independent sum of the parts, equal to the analytic formulas (the capsule's with
  // each hemisphere's centre 3r/8 from its face) within round-off, 1e-12 relative.
  const double rho = 900.0;
  for (const double r : {0.01, 0.03}) {
    for (const double l : {0.0, 0.005, 0.04}) {
      CAPTURE(r, l);
      const auto slices = [&](bool caps) {
        const auto s2 = [&](double z) { return std::abs(z) <= l ? r * r : r * r - (std::abs(z) - l) * (std::abs(z) - l); };
        Vec3 out = Vec3::Zero();   // m, J_x, J_z
        std::vector<std::pair<double, double>> pieces{{-l, l}};
        if (caps) pieces.insert(pieces.end(), {{-l - r, -l}, {l, l + r}});
        for (const auto& [a, b] : pieces) {
          if (b <= a) continue;
          out[0] += gauss3([&](double z) { return rho * kPi * s2(z); }, a, b);
          out[1] += gauss3([&](double z) { return rho * kPi * (s2(z) * s2(z) / 4.0 + s2(z) * z * z); }, a, b);
          out[2] += gauss3([&](double z) { return rho * kPi * s2(z) * s2(z) / 2.0; }, a, b);
        }
        return out;
      };
      const auto compare = [&](const Shape& shape, const Vec3& sliced) {
        const MassProperties mp = mass_properties(shape, rho);
        CHECK(std::abs(mp.mass - sliced[0]) <= 1e-12 * sliced[0]);
        CHECK(std::abs(mp.inertia(0, 0) - sliced[1]) <= 1e-12 * sliced[1]);
        CHECK(std::abs(mp.inertia(1, 1) - sliced[1]) <= 1e-12 * sliced[1]);
        CHECK(std::abs(mp.inertia(2, 2) - sliced[2]) <= 1e-12 * sliced[2]);
        CHECK(mp.centre.norm() == 0.0);
      };
      compare(capsule_shape(r, l), slices(true));
      if (l > 0.0) compare(cylinder_shape(r, l), slices(false));
      if (l == 0.0) compare(sphere_shape(r), slices(true));   // a capsule of no length
    }
  }
}

TEST_CASE("A non-convex mesh (an L) has the mass properties of the two boxes it is made of", "[shape][mass]") {
  // Law: mass, first moment and inertia add over disjoint parts. The L of side 2a is the box
  // [0, 2a] x [0, a] plus the box [0, a] x [a, 2a] (height 2 hz): its centre is the mass-weighted
  // mean of theirs and its inertia about it the sum of each box's box_inertia plus its
  // parallel-axis term m (|d|^2 1 - d d^T). Tolerance 1e-12 relative (round-off).
  const double a = 0.02, hz = 0.01, rho = 500.0;
  const MassProperties mp = mass_properties(graspsim::test::l_block(a, hz), rho);
  const Vec3 h1(a, a / 2, hz), c1(a, a / 2, 0.0), h2(a / 2, a / 2, hz), c2(a / 2, 1.5 * a, 0.0);
  const double m1 = rho * 8 * h1.prod(), m2 = rho * 8 * h2.prod();
  const Vec3 c = (m1 * c1 + m2 * c2) / (m1 + m2);
  const auto shifted = [&](double m, const Vec3& h, const Vec3& d) {
    return Mat3(Mat3(box_inertia(m, h).asDiagonal()) + m * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()));
  };
  const Mat3 j = shifted(m1, h1, c1 - c) + shifted(m2, h2, c2 - c);
  CHECK(std::abs(mp.mass - (m1 + m2)) <= 1e-12 * (m1 + m2));
  CHECK((mp.centre - c).norm() <= 1e-12 * c.norm());
  CHECK(rel_error(mp.inertia, j) <= 1e-12);
  CHECK(std::abs(mp.inertia(0, 1)) > 0.1 * j(0, 0));   // the L has a product of inertia
}

TEST_CASE("The principal frame of a rotated, shifted box mesh recovers the rotation", "[shape][principal]") {
  // Law: the inertia tensor of a box turned by R0 and moved by c is R0 diag(J) R0^T about c, so
  // its eigenvectors are R0's columns. The frame assigns each axis to the file axis it is closest
  // to, so for a turn below 45 degrees the rotation found is R0 itself; for any turn it is R0 up
  // to a signed permutation of columns, with the moments permuted alike. Tolerance 1e-10
  // (eigenvectors of well-separated moments, ratio 1:2.3:3.5 here, are accurate to ~1e-15 / gap).
  const Vec3 h(0.01, 0.02, 0.03), c(0.3, -0.1, 0.2);
  const double rho = 1000.0, m = rho * 8 * h.prod();
  const Vec3 j = box_inertia(m, h);
  for (const double angle : {0.0, 0.2, 0.6}) {
    const Mat3 r0 = rotation(angle, Vec3(1, 2, 3));
    CAPTURE(angle);
    PrincipalFrame frame;
    const TriangleMesh body = to_principal_frame(moved(box_mesh(h), r0, c), frame, rho);
    CHECK((frame.centre - c).norm() <= 1e-12);
    CHECK((frame.rotation - r0).cwiseAbs().maxCoeff() <= 1e-10);
    CHECK((frame.moments - j).cwiseAbs().maxCoeff() <= 1e-10 * j.maxCoeff());
    // In its frame the mesh is the box again, vertex for vertex.
    const TriangleMesh box = box_mesh(h);
    for (std::size_t v = 0; v < box.vertices.size(); ++v) CHECK((body.vertices[v] - box.vertices[v]).norm() <= 1e-12);
  }
  for (const double angle : {1.3, 2.5, -3.0}) {
    const Mat3 r0 = rotation(angle, Vec3(-1, 0.5, 2));
    CAPTURE(angle);
    PrincipalFrame frame;
    to_principal_frame(moved(box_mesh(h), r0, c), frame, rho);
    const Mat3 p = r0.transpose() * frame.rotation;   // a signed permutation
    CHECK(std::abs(frame.rotation.determinant() - 1.0) <= 1e-12);
    for (int col = 0; col < 3; ++col) {
      int axis = 0;
      p.col(col).cwiseAbs().maxCoeff(&axis);
      CHECK(std::abs(std::abs(p(axis, col)) - 1.0) <= 1e-10);
      CHECK(std::abs(frame.moments[col] - j[axis]) <= 1e-10 * j.maxCoeff());
      // Closest to the file axes: the diagonal is the largest in its column.
      CHECK(frame.rotation(col, col) > 0.0);
    }
  }
}

TEST_CASE("Equal moments keep the file's axes", "[shape][principal]") {
  // A cube has all moments equal: any axes are principal, and the frame keeps the file's
  // (rotation exactly the identity). A square prism turned about x keeps its distinct axis (the
  // turned z) and completes it from the file's x.
  PrincipalFrame frame;
  to_principal_frame(moved(box_mesh(Vec3(0.02, 0.02, 0.02)), Mat3::Identity(), Vec3(1, 2, 3)), frame);
  CHECK(frame.rotation == Mat3::Identity());
  const Mat3 r0 = rotation(0.3, Vec3::UnitX());
  to_principal_frame(moved(box_mesh(Vec3(0.02, 0.02, 0.05)), r0, Vec3::Zero()), frame);
  CHECK((frame.rotation.col(2) - r0.col(2)).norm() <= 1e-10);
  CHECK((frame.rotation.col(0) - Vec3::UnitX()).norm() <= 1e-10);
  CHECK(std::abs(frame.rotation.determinant() - 1.0) <= 1e-12);
}

TEST_CASE("The faces of a box mesh are box_polyhedron's", "[shape][convex]") {
  // 12 triangles in 6 planes merge into 6 quadrilaterals whose planes (normal, offset) are
  // exactly box_polyhedron's, counter-clockwise from outside, and whose neighbour across each
  // edge is the face box_polyhedron has across the same edge.
  const Vec3 h(0.01, 0.02, 0.03);
  const ConvexPolyhedron box = box_polyhedron(h);
  const ConvexPolyhedron p = convex_polyhedron(box_mesh(h));
  REQUIRE(p.faces.size() == 6);
  REQUIRE(p.vertices.size() == 8);
  const auto box_face = [&](const Vec3& n) {
    for (int f = 0; f < 6; ++f) {
      if (box.faces[f].normal == n) return f;
    }
    return -1;
  };
  const auto box_vertex = [&](const Vec3& x) {
    for (int v = 0; v < 8; ++v) {
      if (box.vertices[v] == x) return v;
    }
    return -1;
  };
  std::set<int> seen;
  for (const PolyFace& f : p.faces) {
    REQUIRE(f.vertices.size() == 4);
    REQUIRE(f.neighbours.size() == 4);
    const int bf = box_face(f.normal);
    REQUIRE(bf >= 0);
    seen.insert(bf);
    CHECK(f.offset == box.faces[bf].offset);
    // Counter-clockwise from outside: (v1 - v0) x (v2 - v1) along the normal.
    const Vec3& v0 = p.vertices[f.vertices[0]];
    const Vec3& v1 = p.vertices[f.vertices[1]];
    const Vec3& v2 = p.vertices[f.vertices[2]];
    CHECK((v1 - v0).cross(v2 - v1).dot(f.normal) > 0.0);
    for (int i = 0; i < 4; ++i) {
      CHECK(f.normal.dot(p.vertices[f.vertices[i]]) == f.offset);
      const int a = box_vertex(p.vertices[f.vertices[i]]), b = box_vertex(p.vertices[f.vertices[(i + 1) % 4]]);
      const auto& bv = box.faces[bf].vertices;
      int k = 0;
      while (k < 4 && !(bv[k] == a && bv[(k + 1) % 4] == b)) ++k;
      REQUIRE(k < 4);
      CHECK(box.faces[box.faces[bf].neighbours[k]].normal == p.faces[f.neighbours[i]].normal);
    }
  }
  CHECK(seen.size() == 6);
}

TEST_CASE("Coplanar fans merge into polygons: a prism and an octahedron", "[shape][convex]") {
  // An n-gon prism with fan-triangulated caps has n + 2 faces: two n-gons and n quadrilaterals;
  // an icosphere of level 0 (no coplanar triangles) keeps its 20. Neighbours are symmetric:
  // g is across edge a -> b of f exactly when f is across b -> a of g.
  for (int n : {3, 5, 8, 16}) {
    CAPTURE(n);
    const ConvexPolyhedron p = convex_polyhedron(graspsim::test::prism(graspsim::test::regular_polygon(n, 0.03), 0.01));
    REQUIRE(p.faces.size() == static_cast<std::size_t>(n + 2));
    int polygons = 0;
    for (std::size_t f = 0; f < p.faces.size(); ++f) {
      const PolyFace& face = p.faces[f];
      polygons += face.vertices.size() == static_cast<std::size_t>(n);
      const int k = static_cast<int>(face.vertices.size());
      for (int i = 0; i < k; ++i) {
        const PolyFace& g = p.faces[face.neighbours[i]];
        const int a = face.vertices[i], b = face.vertices[(i + 1) % k];
        const int gk = static_cast<int>(g.vertices.size());
        int j = 0;
        while (j < gk && !(g.vertices[j] == b && g.vertices[(j + 1) % gk] == a)) ++j;
        REQUIRE(j < gk);
        CHECK(g.neighbours[j] == static_cast<int>(f));
      }
    }
    CHECK(polygons == (n == 4 ? 6 : 2));
  }
  CHECK(convex_polyhedron(icosphere(1.0, 0)).faces.size() == 20);
}

TEST_CASE("Meshes that bound no convex or no closed solid are refused, naming the triangle", "[shape][check]") {
  const TriangleMesh box = box_mesh(Vec3(0.01, 0.02, 0.03));
  SECTION("open: a triangle missing") {
    TriangleMesh m = box;
    m.triangles.erase(m.triangles.begin() + 5);
    const MeshError e = mesh_error([&] { check_closed_mesh(m); });
    CHECK(mentions(e.what(), "not closed"));
    CHECK(e.triangle() >= 0);
  }
  SECTION("one triangle turned over") {
    TriangleMesh m = box;
    std::swap(m.triangles[7][1], m.triangles[7][2]);
    const MeshError e = mesh_error([&] { mesh_shape(m); });
    CHECK(mentions(e.what(), "not consistently oriented"));
    CHECK((e.triangle() == 7 || mentions(e.what(), "triangle 7")));
  }
  SECTION("every triangle turned over: inside out") {
    TriangleMesh m = box;
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
    CHECK(mentions(mesh_error([&] { check_closed_mesh(m); }).what(), "inside out"));
  }
  SECTION("too few triangles, bad indices, a repeated vertex") {
    TriangleMesh m = box;
    m.triangles.resize(3);
    CHECK(mentions(mesh_error([&] { check_closed_mesh(m); }).what(), "at least 4 triangles"));
    m = box;
    m.triangles[4][2] = 8;
    MeshError e = mesh_error([&] { check_closed_mesh(m); });
    CHECK(mentions(e.what(), "out of range"));
    CHECK(e.triangle() == 4);
    m = box;
    m.triangles[2][0] = m.triangles[2][1];
    e = mesh_error([&] { check_closed_mesh(m); });
    CHECK(mentions(e.what(), "one vertex twice"));
    CHECK(e.triangle() == 2);
  }
  SECTION("not convex: the L is a closed mesh but not a convex one") {
    const TriangleMesh l = graspsim::test::l_block(0.02, 0.01);
    CHECK_NOTHROW(check_closed_mesh(l));
    CHECK_NOTHROW(mesh_shape(l));
    const MeshError e = mesh_error([&] { convex_shape(l); });
    CHECK(mentions(e.what(), "not convex"));
    CHECK(e.triangle() >= 0);
  }
  SECTION("a dent of 1e-5 of the size is refused, 1e-7 is taken as flat") {
    // The tolerance is 1e-6 of the bounding box's diagonal (files written with 6-7 digits).
    for (const double dent : {1e-5, 1e-7}) {
      TriangleMesh m = graspsim::test::prism(graspsim::test::regular_polygon(8, 1.0), 0.5);
      const double size = 2.0 * std::sqrt(2.0 + 0.25);   // diagonal of the bounding box, ~2.6
      m.vertices[8].z() -= dent * size;                  // a top vertex pushed in
      if (dent > 1e-6) {
        CHECK(mentions(mesh_error([&] { convex_polyhedron(m); }).what(), "not convex"));
      } else {
        CHECK_NOTHROW(convex_polyhedron(m));
      }
    }
  }
}

TEST_CASE("Shapes: the analytic solids and meshes fill their fields and pass validate()", "[shape]") {
  Model model;
  const auto body = [&](const Shape& s) {
    BodyParams b;
    b.name = "b";
    b.shape = s;
    const MassProperties mp = mass_properties(s, 1000.0);
    b.mass = mp.mass;
    b.inertia = mp.inertia.diagonal();
    model.bodies = {b};
  };
  body(sphere_shape(0.02));
  CHECK_NOTHROW(validate(model));
  CHECK(model.bodies[0].shape.half_extents == Vec3(0.02, 0.02, 0.02));
  body(capsule_shape(0.01, 0.03));
  CHECK(model.bodies[0].shape.half_extents == Vec3(0.01, 0.01, 0.04));
  CHECK_NOTHROW(validate(model));
  body(convex_shape(icosphere(0.03, 1)));
  CHECK_NOTHROW(validate(model));
  body(mesh_shape(graspsim::test::l_block(0.02, 0.01)));
  CHECK_NOTHROW(validate(model));

  const auto refused = [&](const Shape& s, const std::string& message) {
    body(sphere_shape(0.02));
    model.bodies[0].shape = s;
    try {
      validate(model);
      FAIL("accepted: " << message);
    } catch (const std::invalid_argument& e) {
      CHECK(std::string(e.what()) == message);
    }
  };
  refused(sphere_shape(0.0), "objects[1] 'b': radius: the radius must be > 0 m and finite (got 0)");
  refused(cylinder_shape(0.01, 0.0), "objects[1] 'b': length: a cylinder's length must be > 0 m and finite (got 0)");
  refused(capsule_shape(0.01, -0.01), "objects[1] 'b': length: a capsule's length (of its cylinder part) must be >= 0 m and finite (got -0.02)");
  CHECK_NOTHROW(validate([&] { Model m = model; m.bodies[0].shape = capsule_shape(0.01, 0.0); return m; }()));
  Shape empty;
  empty.kind = ShapeKind::kMesh;
  refused(empty, "objects[1] 'b': file: the shape has no triangles");
  Shape no_hull = convex_shape(icosphere(0.03, 0));
  no_hull.hull.reset();
  refused(no_hull, "objects[1] 'b': file: a convex shape needs its faces (use convex_shape())");
  refused(box_shape(Vec3(0.01, 0.0, 0.01)), "objects[1] 'b': size: every side must be > 0 m and finite");
}
