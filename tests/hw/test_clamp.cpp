// Tests of force safety: clamp_force over a deterministic sweep of requests, and Device::render
// and release() through a ScriptedFinger.
#include <catch2/catch.hpp>

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "graspsim/hw/device.hpp"
#include "graspsim/hw/scripted_finger.hpp"
#include "graspsim/hw/trajectory.hpp"
#include "tests/support/random.hpp"

using namespace graspsim::hw;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMax = DBL_MAX;
constexpr double kDenormMin = std::numeric_limits<double>::denorm_min();

bool same_bits(const Vec3& a, const Vec3& b) {
  for (int i = 0; i < 3; ++i)
    if (std::bit_cast<std::uint64_t>(a[i]) != std::bit_cast<std::uint64_t>(b[i])) return false;
  return true;
}

bool is_exact_zero(const Vec3& v) { return v.x() == 0.0 && v.y() == 0.0 && v.z() == 0.0; }

std::string fmt(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}
std::string fmt(const Vec3& v) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "(%.17g, %.17g, %.17g)", v.x(), v.y(), v.z());
  return buf;
}

// Largest binary exponent among the nonzero entries, or `fallback` if all are zero.
int max_exponent(std::initializer_list<double> values, int fallback) {
  int e = std::numeric_limits<int>::min();
  for (double x : values)
    if (x != 0.0) e = std::max(e, std::ilogb(x));
  return e == std::numeric_limits<int>::min() ? fallback : e;
}

// |v| / ref, measured independently of Eigen: everything is first scaled by the same power of
// two (exact), then squared and summed in long double, so neither overflow nor underflow of
// |v|^2 can hide a result, and the rounding (~1e-19) is far below every tolerance used here.
long double norm_ratio(const Vec3& v, double ref) {
  const int e = max_exponent({v.x(), v.y(), v.z(), ref}, 0);
  long double sum = 0.0L;
  for (int i = 0; i < 3; ++i) {
    const long double x = std::ldexp(v[i], -e);
    sum += x * x;
  }
  return std::sqrt(sum) / static_cast<long double>(std::ldexp(ref, -e));
}

// Cosine of the angle between a and b (both nonzero), scaled like norm_ratio.
long double cosine(const Vec3& a, const Vec3& b) {
  const int ea = max_exponent({a.x(), a.y(), a.z()}, 0);
  const int eb = max_exponent({b.x(), b.y(), b.z()}, 0);
  long double dot = 0.0L, aa = 0.0L, bb = 0.0L;
  for (int i = 0; i < 3; ++i) {
    const long double x = std::ldexp(a[i], -ea);
    const long double y = std::ldexp(b[i], -eb);
    dot += x * y;
    aa += x * x;
    bb += y * y;
  }
  return dot / std::sqrt(aa * bb);
}

// What one call of clamp_force did, for the coverage checks.
enum class Outcome { kZero, kUnchanged, kClamped, kFailed };

// Checks every clause of the contract (device.hpp) for one request:
//  - a non-finite request, or a limit that is not > 0 (NaN included), renders exactly zero;
//  - otherwise |out| <= limit, compared exactly: this is the hardware safety bound. |out| is
//    Eigen's norm(), the magnitude the device code itself uses; it is also measured in long
//    double, which must agree to 1e-15 (~4 ulp: the rounding of a double norm) and sees the
//    cases where |out|^2 underflows in double;
//  - a request clearly below the limit (|f| <= limit (1 - 1e-14), measured precisely) comes
//    back unchanged, bit for bit (-0.0 and denormals included);
//  - a request that was changed keeps its direction (cos >= 1 - 1e-12) and has magnitude
//    within 1e-12 relative of the limit. One rescaling of a double vector moves its direction
//    and magnitude by a few 1e-16, so 1e-12 leaves a margin of ~1000 and still catches any
//    wrong scale factor or component.
// Requests within 1e-14 of the limit may come back either way: whether |f| rounds to just
// below or just above the limit is the norm's rounding, not the contract.
Outcome check_clamp(const Vec3& f, double limit) {
  const Vec3 out = clamp_force(f, DeviceLimits{limit});
  INFO("request " << fmt(f) << " N, limit " << fmt(limit) << " N -> " << fmt(out));
  bool ok = true;
  const auto expect = [&ok](bool holds, const char* clause) {
    if (!holds) {
      ok = false;
      FAIL_CHECK(clause);
    }
  };

  if (!std::isfinite(f.x()) || !std::isfinite(f.y()) || !std::isfinite(f.z()) ||
      !(limit > 0.0)) {
    expect(is_exact_zero(out), "non-finite request or limit <= 0 / NaN must render zero");
    return ok ? Outcome::kZero : Outcome::kFailed;
  }
  expect(out.allFinite(), "finite request must give a finite force");
  expect(out.norm() <= limit, "|out| <= limit (Eigen norm, exact)");
  expect(norm_ratio(out, limit) <= 1.0L + 1e-15L, "|out| <= limit (long double norm)");

  Outcome outcome = Outcome::kUnchanged;
  if (norm_ratio(f, limit) <= 1.0L - 1e-14L) {
    expect(same_bits(out, f), "a request below the limit must come back unchanged");
  } else if (!same_bits(out, f)) {
    outcome = Outcome::kClamped;
    expect(!is_exact_zero(out), "a finite request above the limit must keep a direction");
    if (!is_exact_zero(out)) {
      expect(cosine(out, f) >= 1.0L - 1e-12L, "direction kept: cos(out, f) >= 1 - 1e-12");
      expect(std::abs(norm_ratio(out, limit) - 1.0L) <= 1e-12L,
             "magnitude within 1e-12 relative of the limit");
    }
  }
  return ok ? outcome : Outcome::kFailed;
}

using graspsim::test::random_direction;   // tests/support/random.hpp
using graspsim::test::uniform01;

// Every third request of the sweep is pushed onto an axis or a coordinate plane, with the
// dropped components +0.0 or -0.0, so signed zeros and axis directions are covered too.
Vec3 flatten_sometimes(Vec3 v, std::uint64_t bits) {
  if (bits % 3 != 0) return v;
  const int drop = static_cast<int>((bits >> 2) % 3);
  v[drop] = (bits >> 4) % 2 ? -0.0 : 0.0;
  if ((bits >> 5) % 2) v[(drop + 1) % 3] = (bits >> 6) % 2 ? -0.0 : 0.0;
  return v;
}

}  // namespace

// Force safety (device.hpp): the largest force a device may be asked for is the limit, in the
// direction asked; below the limit the request passes untouched; NaN or infinite components
// render zero. A property test: 20,000 requests per limit, magnitudes log-uniform over
// 1e-12..1e12 N in directions uniform on the sphere, plus 7 requests per direction within a few
// ulp of the limit, for limits from 1 mN to 1 kN.
TEST_CASE("clamp_force never exceeds the limit, keeps direction, passes small forces untouched",
          "[hw][clamp_force][law]") {
  std::mt19937_64 rng(0x9e3779b97f4a7c15ULL);
  int zero = 0, unchanged = 0, clamped = 0, failed = 0;
  const auto tally = [&](Outcome o) {
    switch (o) {
      case Outcome::kZero: ++zero; break;
      case Outcome::kUnchanged: ++unchanged; break;
      case Outcome::kClamped: ++clamped; break;
      case Outcome::kFailed: ++failed; break;
    }
  };
  for (double limit : {1e-3, 3.3, 10.0, 1e3}) {   // N
    for (int k = 0; k < 20000 && failed < 10; ++k) {
      const std::uint64_t bits = rng();
      const Vec3 dir = flatten_sometimes(random_direction(rng), bits);
      const double magnitude = std::pow(10.0, -12.0 + 24.0 * uniform01(rng));   // N
      tally(check_clamp(dir * magnitude, limit));
      // Near the limit: |dir * limit| is within ~1e-16 of it, so these land on both sides.
      if (k % 10 == 0)
        for (int ulps = -3; ulps <= 3; ++ulps)
          tally(check_clamp(dir * (limit * (1.0 + ulps * DBL_EPSILON)), limit));
    }
  }
  CHECK(failed == 0);
  // The sweep did exercise both branches, many times each.
  CHECK(unchanged > 20000);
  CHECK(clamped > 20000);
  CHECK(zero == 0);
}

// The same contract at hand-picked edges, limit 10 N (7 N for the (2, 3, 6) family, whose
// norm is exactly 7): zero and signed zeros, the limit exactly (returned unchanged: it is
// allowed), one ulp above and below, denormals, mixed scales.
TEST_CASE("clamp_force at the edges: zero, the limit exactly, one ulp either side, denormals",
          "[hw][clamp_force][law]") {
  const double up = std::nextafter(10.0, kInf);
  const double down = std::nextafter(10.0, 0.0);
  const double dmin = DBL_MIN;   // smallest normal
  const std::vector<Vec3> at_or_below_10 = {
      Vec3(0.0, 0.0, 0.0),      Vec3(-0.0, -0.0, -0.0),   Vec3(-0.0, 0.0, -0.0),
      Vec3(10.0, 0.0, 0.0),     Vec3(0.0, -10.0, -0.0),   Vec3(-0.0, 0.0, 10.0),
      Vec3(6.0, 8.0, 0.0),      Vec3(-6.0, 0.0, 8.0),     Vec3(0.0, -8.0, -6.0),
      Vec3(down, 0.0, 0.0),     Vec3(kDenormMin, 0.0, 0.0),
      Vec3(-kDenormMin, kDenormMin, -kDenormMin),          Vec3(dmin / 3, -dmin / 7, 4.9e-320),
      Vec3(1e-300, 5.0, -0.0),  Vec3(-1e-12, 1e-300, kDenormMin)};
  for (const Vec3& f : at_or_below_10) {
    INFO("request " << fmt(f));
    CHECK(same_bits(clamp_force(f, DeviceLimits{10.0}), f));
    CHECK(check_clamp(f, 10.0) != Outcome::kFailed);
  }
  for (const Vec3& f : {Vec3(2.0, 3.0, 6.0), Vec3(-2.0, -3.0, 6.0), Vec3(6.0, -2.0, -3.0)}) {
    INFO("request " << fmt(f));
    CHECK(same_bits(clamp_force(f, DeviceLimits{7.0}), f));
  }

  // One ulp above the limit: |f| exceeds it by ~1e-16 relative, so whether the double norm
  // sees that is rounding; either way the result must obey the bound, and if changed, keep
  // direction and magnitude (check_clamp).
  for (const Vec3& f : {Vec3(up, 0.0, 0.0), Vec3(0.0, -up, 0.0), Vec3(-0.0, 0.0, up),
                        Vec3(6.0, std::nextafter(8.0, kInf), 0.0)}) {
    CHECK(check_clamp(f, 10.0) != Outcome::kFailed);
  }
  // Clearly above, with mixed scales: clamped to the limit along the request.
  for (const Vec3& f : {Vec3(up, up, up), Vec3(1e-300, 20.0, -0.0),
                        Vec3(-kDenormMin, -1e12, 1e-12), Vec3(3e11, -4e11, 1e-3)}) {
    CHECK(check_clamp(f, 10.0) == Outcome::kClamped);
  }
}

// A NaN or infinite component is a fault, whatever the others are; the safe output for a fault
// is no force: exactly zero. Likewise a limit that is zero, negative or NaN permits no force.
TEST_CASE("clamp_force renders exactly zero for non-finite requests and non-positive limits",
          "[hw][clamp_force][law]") {
  const std::vector<double> bad = {kNaN, -kNaN, kInf, -kInf};
  const std::vector<double> others = {0.0, -0.0, 1.0, -3e5, kMax, -kMax, kDenormMin, kNaN, kInf};
  for (int i = 0; i < 3; ++i)
    for (double b : bad)
      for (double o1 : others)
        for (double o2 : {0.0, -2.5, kMax}) {
          Vec3 f(o1, o2, -o1);
          f[i] = b;
          INFO("request " << fmt(f));
          CHECK(is_exact_zero(clamp_force(f, DeviceLimits{10.0})));
          CHECK(is_exact_zero(clamp_force(f, DeviceLimits{kMax})));
        }

  std::mt19937_64 rng(20240611);
  std::vector<Vec3> requests = {Vec3(0.0, 0.0, 0.0), Vec3(-0.0, 0.0, -0.0), Vec3(1e-12, 0, 0),
                                Vec3(3.0, 4.0, 0.0), Vec3(kDenormMin, 0.0, 0.0)};
  for (int k = 0; k < 50; ++k)
    requests.push_back(random_direction(rng) * std::pow(10.0, -12.0 + 24.0 * uniform01(rng)));
  for (double limit : {0.0, -0.0, -kDenormMin, -1e-300, -10.0, -kInf, kNaN, -kNaN})
    for (const Vec3& f : requests) {
      INFO("limit " << limit << ", request " << fmt(f));
      CHECK(is_exact_zero(clamp_force(f, DeviceLimits{limit})));
    }
}

// Requests so large that |f|^2 overflows a double (|f| > ~1.34e154 N, e.g. DBL_MAX
// components, as a diverging solver might produce) are finite and above the limit, so the
// contract asks for the limit in the requested direction. Expected: |out| = 10 N along f.
TEST_CASE("clamp_force scales requests whose squared norm overflows (up to DBL_MAX) to the limit",
          "[hw][clamp_force][extreme]") {
  for (const Vec3& f : {Vec3(kMax, 0.0, 0.0), Vec3(-kMax, kMax, -kMax), Vec3(kMax, kMax, kMax),
                        Vec3(0.0, -kMax, 1.0), Vec3(1e300, -1e-300, 2e299),
                        Vec3(1e155, 1e155, -0.0), Vec3(2e154, 0.0, 0.0)}) {
    CHECK(check_clamp(f, 10.0) == Outcome::kClamped);
  }
}

// Limits so small that |f|^2 underflows near them (< ~1e-154 N) are still positive limits: the
// bound must hold there too. Physically meaningless values, so this only guards the arithmetic.
TEST_CASE("clamp_force holds limits too small to square in double (1e-200 N)",
          "[hw][clamp_force][extreme]") {
  for (double limit : {1e-160, 1e-200, 1e-300})
    for (const Vec3& f : {Vec3(4.2 * limit, 5.6 * limit, 0.0), Vec3(0.0, 0.0, -7.0 * limit),
                          Vec3(1.0, 0.0, 0.0)}) {
      CHECK(check_clamp(f, limit) == Outcome::kClamped);
    }
}

// Device::render sends clamp_force(f) to the device and returns it; a ScriptedFinger stores what
// was sent (last_force). release() sends zero. Expected values are worked out by hand for a
// 3.3 N limit: (30, -40, 0) N has |f| = 50 N, so it renders 3.3 (0.6, -0.8, 0) = (1.98, -2.64,
// 0) N, to within 1e-12 relative (one rescaling: a few 1e-16).
TEST_CASE("Device::render returns and stores the clamped force, release() stores zero",
          "[hw][clamp_force][device]") {
  std::vector<Waypoint> path = {{0.0, Vec3(0.01, 0.02, 0.03)}};
  ScriptedFinger finger(std::make_unique<WaypointTrajectory>(path, Interpolation::kLinear),
                        DeviceLimits{3.3});
  REQUIRE(finger.limits().max_force == 3.3);
  REQUIRE(is_exact_zero(finger.last_force()));   // nothing rendered yet

  // Below the limit (|f| = sqrt(5.25) = 2.29 N): unchanged, bit for bit.
  const Vec3 small(1.0, -2.0, 0.5);
  const Vec3 r1 = finger.render(small);
  CHECK(same_bits(r1, small));
  CHECK(same_bits(finger.last_force(), small));

  // Above: the limit along the request.
  const Vec3 big(30.0, -40.0, 0.0);
  const Vec3 expected(1.98, -2.64, 0.0);
  const Vec3 r2 = finger.render(big);
  INFO("rendered " << fmt(r2));
  CHECK(r2.norm() <= 3.3);
  CHECK(std::abs(r2.x() - expected.x()) <= 1e-12 * 3.3);
  CHECK(std::abs(r2.y() - expected.y()) <= 1e-12 * 3.3);
  CHECK(r2.z() == 0.0);
  CHECK(same_bits(finger.last_force(), r2));

  // release() after a nonzero force: zero stored.
  finger.release();
  CHECK(is_exact_zero(finger.last_force()));

  // A fault renders (and stores) zero, replacing the last good force.
  finger.render(small);
  for (const Vec3& f : {Vec3(kNaN, 0.0, 0.0), Vec3(0.0, -kInf, 1.0), Vec3(1.0, 1.0, kInf)}) {
    const Vec3 r = finger.render(f);
    CHECK(is_exact_zero(r));
    CHECK(is_exact_zero(finger.last_force()));
    finger.render(small);
  }

  // A device with a non-positive limit renders nothing.
  ScriptedFinger dead(std::make_unique<WaypointTrajectory>(path, Interpolation::kLinear),
                      DeviceLimits{0.0});
  CHECK(is_exact_zero(dead.render(small)));
  CHECK(is_exact_zero(dead.last_force()));
}
