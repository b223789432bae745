// Tests of WaypointTrajectory (linear and minimum-jerk interpolation, holds, the segment cache,
// validation) and of ScriptedFinger::read.
#include <catch2/catch.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "graspsim/hw/scripted_finger.hpp"
#include "graspsim/hw/trajectory.hpp"
#include "tests/support/random.hpp"

using namespace graspsim::hw;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A path with segments of different lengths and durations, all times dyadic so that the
// quarter points of every segment are exact doubles:
//   [1, 2]   s: 0.1 m along x in 1 s
//   [2, 2.5] s: |(0, 0.05, -0.02)| = 0.0539 m in 0.5 s
//   [2.5, 4] s: |(-0.13, 0.15, 0.03)| = 0.2007 m in 1.5 s
const std::vector<Waypoint> kPath = {
    {1.0, Vec3(0.0, 0.0, 0.0)},
    {2.0, Vec3(0.1, 0.0, 0.0)},
    {2.5, Vec3(0.1, 0.05, -0.02)},
    {4.0, Vec3(-0.03, 0.2, 0.01)},
};

bool same_bits(const Vec3& a, const Vec3& b) {
  for (int i = 0; i < 3; ++i)
    if (std::bit_cast<std::uint64_t>(a[i]) != std::bit_cast<std::uint64_t>(b[i])) return false;
  return true;
}

std::string fmt(const Vec3& v) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "(%.17g, %.17g, %.17g)", v.x(), v.y(), v.z());
  return buf;
}

// The minimum-jerk profile, written out as in the literature (not in the Horner form the code
// uses) and evaluated in long double: an independent reference.
long double min_jerk_s(long double u) {
  return 10.0L * u * u * u - 15.0L * u * u * u * u + 6.0L * u * u * u * u * u;
}

// Largest |difference| of one component between p and a + s (b - a), in long double.
long double max_error(const Vec3& p, const Vec3& a, const Vec3& b, long double s) {
  long double worst = 0.0L;
  for (int i = 0; i < 3; ++i) {
    const long double expected = a[i] + s * (static_cast<long double>(b[i]) - a[i]);
    worst = std::max(worst, std::abs(p[i] - expected));
  }
  return worst;
}

// Tolerance for a point on segment a -> b: 1e-15 x (segment length + largest |coordinate| of
// its ends). The code computes a + s (b - a) in double: b - a, s (b - a) and the sum each round
// by at most 1.1e-16 relative of a quantity no larger than that scale (and s itself is exact
// at the quarter points, whose u and s are dyadic), so the error stays below ~4e-16 x scale;
// 1e-15 leaves a margin, and a wrong profile is off by ~1e-2 x length.
double point_tolerance(const Vec3& a, const Vec3& b) {
  return 1e-15 * ((b - a).norm() + std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff()));
}

// Velocity by central differences, dividing by the step actually taken ((t+h) - (t-h) is
// computed exactly), so only the truncation and the rounding of positions remain.
Vec3 central_velocity(WaypointTrajectory& traj, double t, double h) {
  const double tp = t + h, tm = t - h;
  return (traj.position(tp) - traj.position(tm)) / (tp - tm);
}

}  // namespace

// Piecewise-linear interpolation: p(t) = a + u (b - a), u = (t - t_a) / (t_b - t_a). At a
// waypoint u = 0 on the segment it starts, so the waypoint is returned exactly; at the middle
// of a segment p = (a + b) / 2, at its quarter points a + (b - a) / 4 and a + 3 (b - a) / 4.
TEST_CASE("linear interpolation passes exactly through the waypoints and halfway at mid-segment",
          "[hw][trajectory][law]") {
  WaypointTrajectory traj(kPath, Interpolation::kLinear);
  for (const Waypoint& w : kPath) {
    INFO("t = " << w.time << " s, got " << fmt(traj.position(w.time)));
    CHECK(traj.position(w.time) == w.position);
  }
  for (std::size_t i = 0; i + 1 < kPath.size(); ++i) {
    const Waypoint& a = kPath[i];
    const Waypoint& b = kPath[i + 1];
    for (long double u : {0.25L, 0.5L, 0.75L}) {
      const double t = a.time + static_cast<double>(u) * (b.time - a.time);   // exact (dyadic)
      const Vec3 p = traj.position(t);
      INFO("segment " << i << ", u = " << static_cast<double>(u) << ", got " << fmt(p));
      CHECK(max_error(p, a.position, b.position, u) <= point_tolerance(a.position, b.position));
    }
  }
}

// Minimum jerk (Flash & Hogan 1985): p = a + s(u) (b - a), s(u) = 10u^3 - 15u^4 + 6u^5. At the
// quarter points s = 0.103515625, 0.5, 0.896484375 (linear would give 0.25, 0.5, 0.75).
// Tolerance: see point_tolerance (the same arithmetic up to rounding).
TEST_CASE("minimum-jerk position follows s(u) = 10u^3 - 15u^4 + 6u^5 on every segment",
          "[hw][trajectory][law]") {
  WaypointTrajectory traj(kPath, Interpolation::kMinimumJerk);
  for (const Waypoint& w : kPath) CHECK(traj.position(w.time) == w.position);
  CHECK(min_jerk_s(0.25L) == 0.103515625L);   // the reference itself, worked by hand
  CHECK(min_jerk_s(0.75L) == 0.896484375L);
  for (std::size_t i = 0; i + 1 < kPath.size(); ++i) {
    const Waypoint& a = kPath[i];
    const Waypoint& b = kPath[i + 1];
    for (long double u : {0.25L, 0.5L, 0.75L}) {
      const double t = a.time + static_cast<double>(u) * (b.time - a.time);   // exact (dyadic)
      const Vec3 p = traj.position(t);
      INFO("segment " << i << ", u = " << static_cast<double>(u) << ", got " << fmt(p));
      CHECK(max_error(p, a.position, b.position, min_jerk_s(u)) <=
            point_tolerance(a.position, b.position));
    }
  }
}

// Minimum jerk rests at every waypoint and moves fastest mid-segment:
// v = s'(u) (b - a) / T with s'(u) = 30 u^2 (1 - u)^2, so s'(0) = s'(1) = 0 and the peak is
// s'(1/2) = 30/16 = 1.875, i.e. 1.875 d / T (s'' vanishes there; s''' = 60 - 360u + 360u^2).
// Measured by central differences with h = 1e-6 s:
//  - at a waypoint each side moves as 10 d (tau/T)^3, so the truncation is
//    <= 10 h^2 max(d/T^3) = 10e-12 x 0.43 m/s^3 = 4e-12 m/s. Rounding: near u = 1 the Horner
//    bracket 10 + u(-15 + 6u) can lose ~10 ulp (2e-15 in s), i.e. <= 5e-16 m in p on a 0.2 m
//    segment, and the difference of two such over 2h gives <= 5e-10 m/s. Bound: 1e-9 m/s.
//    (For the 0.1 m, 1 s segment alone the truncation is 1e-12 m/s; any profile that does not
//    rest there, e.g. linear, gives ~0.1 m/s.)
//  - at mid-segment the truncation is h^2/6 |x'''| = h^2/6 x 30 d/T^3, relative to 1.875 d/T:
//    2.7 h^2/T^2 <= 1.1e-11; rounding of the positions (~20 ulp of d) over 2h relative to
//    1.875 d/T: <= 20 x 2.2e-16 x 0.5 / 2e-6 / 1.875 = 6e-10. Bound: 1e-8 relative.
//  - "peak": the speed at u = k/32, k != 16, is below the mid-segment speed (by at least
//    15/32^2 / 1.875 = 0.8 %, far above the error).
TEST_CASE("minimum-jerk velocity is zero at the waypoints and peaks at 1.875 d/T mid-segment",
          "[hw][trajectory][law]") {
  const double h = 1e-6;   // s
  WaypointTrajectory traj(kPath, Interpolation::kMinimumJerk);
  for (const Waypoint& w : kPath) {
    const Vec3 v = central_velocity(traj, w.time, h);
    INFO("waypoint t = " << w.time << " s, v = " << fmt(v) << " m/s");
    CHECK(v.norm() < 1e-9);
  }
  for (std::size_t i = 0; i + 1 < kPath.size(); ++i) {
    const Waypoint& a = kPath[i];
    const Waypoint& b = kPath[i + 1];
    const double T = b.time - a.time;                                // s
    const Vec3 expected = 1.875 * (b.position - a.position) / T;     // m/s
    const Vec3 v_mid = central_velocity(traj, a.time + 0.5 * T, h);
    INFO("segment " << i << ": v_mid = " << fmt(v_mid) << ", expected " << fmt(expected));
    CHECK((v_mid - expected).norm() <= 1e-8 * expected.norm());
    for (int k = 1; k < 32; ++k) {
      if (k == 16) continue;
      const double t = a.time + T * k / 32.0;
      INFO("u = " << k << "/32");
      CHECK(central_velocity(traj, t, h).norm() < v_mid.norm());
    }
  }
}

// Outside the scripted span the finger holds still: the first waypoint's position before it,
// the last one's after it, bit for bit, for any time (infinite included).
TEST_CASE("a trajectory holds its first position before the first waypoint and its last after",
          "[hw][trajectory]") {
  for (Interpolation interp : {Interpolation::kLinear, Interpolation::kMinimumJerk}) {
    WaypointTrajectory traj(kPath, interp);
    for (double t : {-kInf, -1e9, 0.0, 1.0 - 1e-9, std::nextafter(1.0, 0.0), 1.0}) {
      INFO("t = " << t);
      CHECK(same_bits(traj.position(t), kPath.front().position));
    }
    for (double t : {4.0, std::nextafter(4.0, kInf), 4.0 + 1e-9, 5.0, 1e9, kInf}) {
      INFO("t = " << t);
      CHECK(same_bits(traj.position(t), kPath.back().position));
    }
  }
  // A single waypoint is held at all times.
  WaypointTrajectory still({{0.5, Vec3(0.01, -0.02, 0.03)}}, Interpolation::kMinimumJerk);
  for (double t : {-kInf, 0.0, 0.5, 0.75, kInf})
    CHECK(same_bits(still.position(t), Vec3(0.01, -0.02, 0.03)));
}

// position(t) is a function of t alone: the cached segment only speeds up the search. So a
// trajectory queried in any order (forwards, backwards, shuffled, random jumps with repeats)
// must return, bit for bit, what a fresh trajectory returns for the same t.
TEST_CASE("evaluation order does not change positions (the segment cache is invisible)",
          "[hw][trajectory]") {
  std::mt19937_64 rng(7);
  std::vector<double> times = {0.0, 4.5};
  for (const Waypoint& w : kPath) {   // on, and one ulp either side of, every waypoint
    times.push_back(w.time);
    times.push_back(std::nextafter(w.time, -kInf));
    times.push_back(std::nextafter(w.time, kInf));
  }
  for (int k = 0; k < 300; ++k) times.push_back(0.5 + 4.0 * graspsim::test::uniform01(rng));
  std::sort(times.begin(), times.end());

  for (Interpolation interp : {Interpolation::kLinear, Interpolation::kMinimumJerk}) {
    std::vector<Vec3> reference;
    for (double t : times) reference.push_back(WaypointTrajectory(kPath, interp).position(t));

    WaypointTrajectory traj(kPath, interp);
    const auto check_at = [&](std::size_t i, const char* order) {
      const Vec3 p = traj.position(times[i]);
      if (!same_bits(p, reference[i])) {
        INFO(order << ": t = " << times[i] << " gave " << fmt(p) << ", fresh "
                   << fmt(reference[i]));
        FAIL_CHECK("position depends on evaluation order");
      }
    };
    for (std::size_t i = 0; i < times.size(); ++i) check_at(i, "forwards");
    for (std::size_t i = times.size(); i-- > 0;) check_at(i, "backwards");
    std::vector<std::size_t> order(times.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    for (std::size_t i = order.size() - 1; i > 0; --i)   // Fisher-Yates, portable
      std::swap(order[i], order[rng() % (i + 1)]);
    for (std::size_t i : order) check_at(i, "shuffled");
    for (int k = 0; k < 3000; ++k) check_at(rng() % times.size(), "random jumps");
  }
  SUCCEED("all orders agree");
}

// Waypoints must be non-empty, finite, and strictly increasing in time; anything else is a
// script error reported as std::invalid_argument when the trajectory is built.
TEST_CASE("WaypointTrajectory rejects empty, non-increasing and non-finite waypoints",
          "[hw][trajectory]") {
  using W = std::vector<Waypoint>;
  const Vec3 p(0.01, 0.02, 0.03);
  for (Interpolation interp : {Interpolation::kLinear, Interpolation::kMinimumJerk}) {
    CHECK_NOTHROW(WaypointTrajectory(kPath, interp));
    CHECK_NOTHROW(WaypointTrajectory(W{{0.0, p}}, interp));
    CHECK_NOTHROW(WaypointTrajectory(W{{-1.0, p}, {std::nextafter(-1.0, 0.0), p}}, interp));

    CHECK_THROWS_AS(WaypointTrajectory(W{}, interp), std::invalid_argument);
    // equal and decreasing times, first pair and later
    CHECK_THROWS_AS(WaypointTrajectory(W{{1.0, p}, {1.0, p}}, interp), std::invalid_argument);
    CHECK_THROWS_AS(WaypointTrajectory(W{{1.0, p}, {0.5, p}}, interp), std::invalid_argument);
    CHECK_THROWS_AS(WaypointTrajectory(W{{0.0, p}, {1.0, p}, {2.0, p}, {2.0, p}}, interp),
                    std::invalid_argument);
    CHECK_THROWS_AS(WaypointTrajectory(W{{0.0, p}, {2.0, p}, {1.0, p}}, interp),
                    std::invalid_argument);
    CHECK_THROWS_AS(WaypointTrajectory(W{{0.0, p}, {-0.0, p}}, interp), std::invalid_argument);
    // non-finite times, anywhere (a NaN compares false with everything, so it must be caught
    // by its own test, not by the ordering one)
    for (double bad : {kNaN, kInf, -kInf}) {
      INFO("bad value " << bad);
      CHECK_THROWS_AS(WaypointTrajectory(W{{bad, p}}, interp), std::invalid_argument);
      CHECK_THROWS_AS(WaypointTrajectory(W{{bad, p}, {1.0, p}}, interp), std::invalid_argument);
      CHECK_THROWS_AS(WaypointTrajectory(W{{0.0, p}, {bad, p}, {3.0, p}}, interp),
                      std::invalid_argument);
      CHECK_THROWS_AS(WaypointTrajectory(W{{0.0, p}, {1.0, p}, {bad, p}}, interp),
                      std::invalid_argument);
      // non-finite position components
      for (int c = 0; c < 3; ++c) {
        Vec3 q = p;
        q[c] = bad;
        CHECK_THROWS_AS(WaypointTrajectory(W{{0.0, q}}, interp), std::invalid_argument);
        CHECK_THROWS_AS(WaypointTrajectory(W{{0.0, p}, {1.0, q}}, interp),
                        std::invalid_argument);
      }
    }
  }
}

// Trajectory::position "may throw (a script error); never returns non-finite" (trajectory.hpp).
// A NaN time, e.g. from a script's arithmetic, must therefore either throw or give a finite
// position.
TEST_CASE("WaypointTrajectory::position never returns a non-finite position, even for a NaN time",
          "[hw][trajectory]") {
  const auto check_nan_time = [](WaypointTrajectory& traj) {
    try {
      const Vec3 p = traj.position(kNaN);
      INFO("position(NaN) = " << fmt(p));
      CHECK(p.allFinite());
    } catch (const std::exception&) {
      SUCCEED("position(NaN) threw");
    }
  };
  for (Interpolation interp : {Interpolation::kLinear, Interpolation::kMinimumJerk}) {
    WaypointTrajectory fresh(kPath, interp);
    check_nan_time(fresh);
    WaypointTrajectory used(kPath, interp);
    used.position(3.0);   // cache on the last segment
    check_nan_time(used);
  }
}

// A scripted finger reads its trajectory: the sample's position is the trajectory's position at
// the given time (the tick does not matter), with no gimbal rotation and no buttons pressed.
// Expected positions come from the waypoints themselves, from s(u) at mid-segment, and from a
// twin trajectory built from the same waypoints (bit for bit).
TEST_CASE("ScriptedFinger::read returns the trajectory's position, zero gimbal and no buttons",
          "[hw][scripted_finger]") {
  ScriptedFinger finger(std::make_unique<WaypointTrajectory>(kPath, Interpolation::kMinimumJerk),
                        DeviceLimits{10.0});
  WaypointTrajectory twin(kPath, Interpolation::kMinimumJerk);
  CHECK(finger.describe() == "scripted");

  std::vector<double> times = {-1.0, 0.0, 1.0, 1.5, 2.0, 2.25, 2.5, 3.0, 3.25, 4.0, 9.0, 1.25};
  std::int64_t tick = 0;
  for (double t : times) {
    const DeviceSample s = finger.read(tick, t);
    INFO("t = " << t << " s, position " << fmt(s.position));
    CHECK(same_bits(s.position, twin.position(t)));
    CHECK(s.gimbal == Vec3::Zero());
    CHECK(s.buttons == 0u);
    // The same time at another tick reads the same sample.
    CHECK(same_bits(finger.read(tick + 1000, t).position, s.position));
    tick += 1;
  }
  for (const Waypoint& w : kPath) CHECK(finger.read(7, w.time).position == w.position);
  // Mid-segment of [2.5, 4] s: s(1/2) = 1/2, the midpoint.
  const Vec3 mid = 0.5 * (kPath[2].position + kPath[3].position);
  CHECK((finger.read(3, 3.25).position - mid).norm() <=
        point_tolerance(kPath[2].position, kPath[3].position));

  CHECK_THROWS_AS(ScriptedFinger(nullptr, DeviceLimits{10.0}), std::invalid_argument);
}

// Scripted gimbal pitch: waypoints carry a pitch that is interpolated with the same s(u) as the
// position, held before the first and after the last waypoint, and a scripted finger reports it
// as the gimbal's pitch (y), roll and yaw zero. Expected values: the waypoints' own pitches, and
// s(1/2) = 1/2 (both profiles) at mid-segment, s(1/4) = 1/4 (linear) and 10/64 - 15/256 + 6/1024
// = 0.103515625 (minimum jerk) at a quarter. Tolerance: two roundings of a pitch of 1 rad.
TEST_CASE("waypoint pitch is interpolated like the position and reaches the gimbal sample",
          "[hw][scripted_finger][gimbal]") {
  const std::vector<Waypoint> path = {{0.0, Vec3(0, 0, 0), 0.2}, {1.0, Vec3(0, 0, 0), 1.0},
                                      {2.0, Vec3(0.1, 0, 0), -0.6}};
  const double eps = 4e-16;
  for (Interpolation interp : {Interpolation::kLinear, Interpolation::kMinimumJerk}) {
    ScriptedFinger finger(std::make_unique<WaypointTrajectory>(path, interp), DeviceLimits{10.0});
    const double quarter = interp == Interpolation::kLinear ? 0.25 : 0.103515625;
    for (const Waypoint& w : path) CHECK(finger.read(0, w.time).gimbal == Vec3(0, w.pitch, 0));
    CHECK(finger.read(0, -1.0).gimbal.y() == 0.2);
    CHECK(finger.read(0, 5.0).gimbal.y() == -0.6);
    CHECK(finger.read(0, 0.5).gimbal.y() == Approx(0.6).margin(eps));
    CHECK(finger.read(0, 1.25).gimbal.y() == Approx(1.0 - 1.6 * quarter).margin(eps));
    const DeviceSample s = finger.read(0, 1.5);
    CHECK(s.gimbal.x() == 0.0);
    CHECK(s.gimbal.z() == 0.0);
  }
  // A non-finite pitch is refused like a non-finite position.
  CHECK_THROWS_AS(WaypointTrajectory({{0.0, Vec3::Zero(), std::nan("")}}, Interpolation::kLinear),
                  std::invalid_argument);
}
