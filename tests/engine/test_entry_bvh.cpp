// The entry test on polygonal shapes goes through a face tree (SurfaceGeometry::bvh) instead of
// a scan over every face. The law it must keep: the result is the scan's, bit for bit (the
// earliest crossing, ties to the lower face index), for point fingers and pads, on a mesh of
// well-shaped triangles and on one of slivers (whose grown polygons reach far past their
// corners, the case a tree with boxes grown by r alone would get wrong).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "graspsim/engine/surface.hpp"
#include "tests/engine/shapes.hpp"

using namespace graspsim;

namespace {

// The linear scan over every face that the tree must equal bit for bit (engine/src/surface.cpp,
// surface_entry).
struct Scan {
  double t = kInfinity;
  int face = -1;
};
Scan linear_scan(const SurfaceGeometry& g, double r, const Vec3& a, const Vec3& b) {
  constexpr double kTol = 1e-10;
  Scan s;
  for (int f = 0; f < g.face_count(); ++f) {
    const auto& F = g.face(f);
    const double sa = F.normal.dot(a) - (F.offset + r), sb = F.normal.dot(b) - (F.offset + r);
    if (sa < -kTol || !(sb < 0.0)) continue;
    const double t = std::max(sa, 0.0) / (sa - sb);
    if (t >= s.t) continue;
    const Vec3 q = a + t * (b - a) - r * F.normal;
    bool inside = true;
    for (int i = 0; i < F.count && inside; ++i) {
      inside = g.edge_normal(F.first + i).dot(q - g.corner(F.first + i)) >= -(r + kTol);
    }
    if (!inside) continue;
    s.t = t;
    s.face = f;
  }
  return s;
}

// Random segments from a shell around the shape (up to `reach` beyond its bounding radius) to
// points near its surface, about `step` long, so most of them cross it.
void compare(const Shape& shape, double bound, double step, int& hits, int& misses) {
  const SurfaceGeometry g(shape);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double r : {0.0, 0.002, 0.01}) {
    for (int i = 0; i < 4000; ++i) {
      const Vec3 dir = Vec3(u(rng), u(rng), u(rng)).normalized();
      const Vec3 b = dir.cwiseProduct(shape.half_extents) * (1.0 + 0.2 * u(rng)) + 0.2 * bound * Vec3(u(rng), u(rng), u(rng));
      const Vec3 a = b + step * Vec3(u(rng), u(rng), u(rng)) + (1.0 + u(rng)) * step * dir;
      const Scan want = linear_scan(g, r, a, b);
      const auto got = surface_entry(g, r, a, b);
      INFO("r " << r << ", segment " << i);
      REQUIRE(got.has_value() == (want.face >= 0));
      if (!got) { ++misses; continue; }
      ++hits;
      REQUIRE(got->features.ids[0] == want.face);
      REQUIRE(got->t == want.t);   // bit for bit
    }
  }
}

}  // namespace

TEST_CASE("the face tree finds the linear scan's entry, bit for bit", "[surface][bvh][law]") {
  int hits = 0, misses = 0;
  SECTION("an icosphere of 5120 triangles") {
    compare(graspsim::mesh_shape(graspsim::test::icosphere(0.04, 4)), 0.04, 0.01, hits, misses);
  }
  SECTION("slivers: the icosphere squashed 50:1 (corners down to about 1 degree)") {
    TriangleMesh m = graspsim::test::icosphere(0.04, 3);
    for (Vec3& v : m.vertices) v.z() /= 50.0;
    compare(graspsim::mesh_shape(m), 0.04, 0.01, hits, misses);
  }
  // Both outcomes were exercised many times.
  CHECK(hits > 2000);
  CHECK(misses > 500);
}
