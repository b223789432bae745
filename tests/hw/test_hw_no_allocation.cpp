// The device side of a servo tick allocates nothing after warm-up, like Simulation::step
// (tests/engine/test_no_allocation.cpp): SimPhantom::read, Device::render and release, and
// ForceSafety run on the servo thread of a real-time loop. Counted with a replaced global
// operator new (this executable only).
#include <catch2/catch.hpp>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>
#include <vector>

#include "graspsim/hw/sim_phantom.hpp"
#include "graspsim/hw/trajectory.hpp"

#include "tests/support/count_allocations.hpp"

using graspsim::test::g_allocations;

using namespace graspsim::hw;

TEST_CASE("sim-phantom read, render, release and force safety allocate no heap memory",
          "[hw][sim_phantom][realtime]") {
  for (double rate : {1000.0, 3000.0}) {
    SimPhantomConfig c;
    c.device_rate_hz = rate;
    c.rise_time = 0.01;
    auto dev = make_sim_phantom(
        c, std::make_unique<WaypointTrajectory>(
               std::vector<Waypoint>{{0.0, Vec3(-0.005, 0.0, 0.0), 0.0},
                                     {0.2, Vec3(0.006, 0.0, 0.0), 0.1},
                                     {0.4, Vec3(0.006, 0.01, 0.0), 0.0}},
               Interpolation::kMinimumJerk));
    // Servo at 3 kHz against a sampled wall, with a stall and a release in the middle.
    const auto tick = [&](std::int64_t n) {
      const DeviceSample s = dev->read(n, static_cast<double>(n) / 3000.0);
      if (n == 700) dev->release();
      if (n < 800 || n > 1200)
        dev->render(Vec3(s.position.x() > 0.0 ? -2000.0 * s.position.x() : 0.0, 0.0, 0.0));
    };
    for (std::int64_t n = 0; n < 30; ++n) tick(n);   // warm-up
    const long before = g_allocations.load();
    for (std::int64_t n = 30; n < 1500; ++n) tick(n);
    CHECK(g_allocations.load() - before == 0);
  }
}
