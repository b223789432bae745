// UdpDevice::read and render allocate nothing after warm-up (the servo tick's rule, as in
// tests/engine/test_no_allocation.cpp): counted with a replaced global operator new, in its
// own executable so the replacement touches no other test.
#include <catch2/catch.hpp>

#include <atomic>
#include <cstdlib>
#include <new>

#include "graspsim/hw/udp_device.hpp"
#include "tests/hw/udp_peer.hpp"

#include "tests/support/count_allocations.hpp"

using graspsim::test::g_allocations;

using namespace graspsim::hw;

TEST_CASE("UdpDevice read and render allocate no heap memory after warm-up", "[hw][udp][realtime]") {
  // Only the device's calls are counted (the fake server between them is the test's).
  graspsim::test::UdpPeer peer;
  UdpDeviceConfig c{"127.0.0.1", peer.port(), 0, 0.01, DeviceLimits{5.0}};
  c.lockstep = true;
  UdpDevice d(c);
  peer.receive_hello();
  long counted = 0;
  for (std::uint32_t n = 0; n < 2000; ++n) {
    // Samples, then a stretch of repeats long enough to time out, then garbage, then samples.
    if (n < 500 || n >= 1500) {
      peer.send(graspsim::test::line_sample(n));
    } else if (n < 1400) {
      peer.send(graspsim::test::line_sample(499));
    } else {
      peer.send("junk", 4);
    }
    const long before = g_allocations.load();
    d.read(n, n / 3000.0);
    d.render(Vec3(0.0, 0.0, n % 7 == 0 ? 1e9 : 1.0));
    if (n >= 10) counted += g_allocations.load() - before;
    peer.receive_force();
  }
  CHECK(d.counters().link_lost == 1);
  CHECK(d.counters().malformed == 100);
  CHECK(counted == 0);
}
