// make_openhaptics_device when graspsim was configured without the OpenHaptics SDK: the name
// still links (the CLI's device factory calls it), and asking for a Phantom says how to get one.
#include "graspsim/hw/openhaptics_device.hpp"

#include <stdexcept>

namespace graspsim::hw {

std::unique_ptr<Device> make_openhaptics_device(const std::string& device_name, const OpenHapticsOptions&) {
  throw std::runtime_error("OpenHaptics device \"" + device_name +
                           "\": graspsim was built without OpenHaptics: install the SDK and "
                           "reconfigure with -DGRASPSIM_OPENHAPTICS=ON (see hw/README.md)");
}

}  // namespace graspsim::hw
