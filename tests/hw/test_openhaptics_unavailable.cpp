// Built without the OpenHaptics SDK, asking for a Phantom is a clear error that says how to get
// one, never a device that reads zeros.
#include <catch2/catch.hpp>

#include <stdexcept>

#include "graspsim/hw/openhaptics_device.hpp"

TEST_CASE("Without the SDK make_openhaptics_device names the device and the CMake option",
          "[hw][openhaptics]") {
  CHECK_THROWS_AS(graspsim::hw::make_openhaptics_device("Default PHANToM"), std::runtime_error);
  CHECK_THROWS_WITH(graspsim::hw::make_openhaptics_device("Default PHANToM"),
                    Catch::Contains("\"Default PHANToM\"") &&
                        Catch::Contains("built without OpenHaptics") &&
                        Catch::Contains("-DGRASPSIM_OPENHAPTICS=ON"));
}
