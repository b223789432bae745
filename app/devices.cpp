// Device specs, the kind registry and the factory (README.md "Devices").
#include "app/devices.hpp"

#include <cmath>
#include <utility>

#include "app/replay.hpp"
#include "graspsim/hw/mapped_device.hpp"
#include "graspsim/hw/openhaptics_device.hpp"
#include "graspsim/hw/sim_phantom.hpp"
#include "graspsim/hw/udp_device.hpp"
#include "graspsim/hw/replay_device.hpp"
#include "graspsim/hw/scripted_finger.hpp"

namespace graspsim::app {
namespace {

std::string finger_names(const Model& model) {
  std::string names;
  for (const FingerParams& f : model.fingers) names += (names.empty() ? "" : ", ") + f.name;
  return names.empty() ? "none" : names;
}

std::string built_kinds(const DeviceRegistry& registry) { return registry.usages(true); }

std::unique_ptr<hw::Device> make_scripted(const DeviceContext& c) {
  return std::make_unique<hw::ScriptedFinger>(c.scenario.make_trajectory(c.finger), c.scenario.fingers()[c.finger].limits);
}

// One finger's recorded hip and gimbal, row n at servo tick n (app/replay.cpp reads them).
// The finger's script still runs alongside, its output discarded, as in `graspsim replay`: a
// script that watches the run, or Lua's math.random, sees what it saw in the recording.
std::unique_ptr<hw::Device> make_replay(const DeviceContext& c) {
  const Model& model = c.scenario.model();
  const std::string& name = model.fingers[c.finger].name;
  RecordedFinger r;
  try {
    r = read_recorded_finger(c.spec.arg, name, model.rates.servo);
  } catch (const ReplayError& e) {
    throw DeviceError(e.what());
  }
  const auto needed = static_cast<std::int64_t>(std::llround(c.scenario.duration() * model.rates.servo));
  if (static_cast<std::int64_t>(r.hip.size()) < needed) {
    throw DeviceError(c.spec.arg + ": holds " + std::to_string(r.hip.size()) + " servo ticks of finger '" + name +
                      "', but the run needs " + std::to_string(needed) + " (" + std::to_string(c.scenario.duration()) +
                      " s): shorten it with --duration");
  }
  return std::make_unique<hw::ReplayDevice>(std::move(r.hip), std::move(r.gimbal), c.scenario.fingers()[c.finger].limits,
                                            c.spec.arg + " /servo/fingers/" + name, c.scenario.make_trajectory(c.finger));
}

// A simulated Phantom (hw/sim_phantom.hpp) of model MODEL (default: the Premium 1.5 of the
// paper), held by a scripted hand that follows the finger's trajectory in the device's frame.
// Its workspace box is centred on where that hand starts (taken from a second instance of the
// trajectory, so the hand's own is not advanced), so a scenario's motion fits the device
// whatever its world coordinates; the force limits are the model's.
std::unique_ptr<hw::Device> make_sim_phantom_device(const DeviceContext& c) {
  hw::SimPhantomConfig config;
  if (!c.spec.arg.empty()) config.model = c.spec.arg;
  config.workspace_center = c.hand_in_device_frame()->position(0.0);
  return hw::make_sim_phantom(config, c.hand_in_device_frame());
}

// A device served over UDP (hw/udp_device.hpp, hw/README.md "UDP protocol"); the finger's
// force limit from the scenario is its clamp, and the device's own limits (spec `model=KEY`,
// default hw::kUdpDefaultModel, or `max_force=` / `continuous_force=`) its force safety.
std::unique_ptr<hw::Device> make_udp(const DeviceContext& c) {
  hw::UdpDeviceConfig config = hw::parse_udp_spec(c.spec.arg);
  config.limits = c.scenario.fingers()[c.finger].limits;
  return hw::make_udp_device(config);
}

// A Phantom through OpenHaptics (hw/openhaptics_device.hpp), by its configured name.
std::unique_ptr<hw::Device> make_phantom(const DeviceContext& c) {
  return hw::make_openhaptics_device(c.spec.arg);
}

}  // namespace

std::unique_ptr<hw::Trajectory> DeviceContext::hand_in_device_frame() const {
  return hw::trajectory_in_device_frame(scenario.make_trajectory(finger), scenario.fingers()[finger].mapping);
}

void DeviceRegistry::add(DeviceKind kind) {
  for (DeviceKind& k : kinds_) {
    if (k.name == kind.name) {
      k = std::move(kind);
      return;
    }
  }
  kinds_.push_back(std::move(kind));
}

const DeviceKind* DeviceRegistry::find(const std::string& name) const {
  for (const DeviceKind& k : kinds_)
    if (k.name == name) return &k;
  return nullptr;
}

std::string DeviceRegistry::usages(bool built_only) const {
  std::string out;
  for (const DeviceKind& k : kinds_)
    if (!built_only || k.factory) out += (out.empty() ? "" : ", ") + k.usage;
  return out;
}

DeviceRegistry default_registry() {
  DeviceRegistry r;
  r.add({"scripted", "scripted", false, false, make_scripted});
  DeviceKind replay{"replay", "replay:TRACE.h5", false, false, make_replay};
  replay.reads_file = true;
  r.add(replay);
  // A simulated device is not real (no hand on it): the run stays as fast as possible and
  // deterministic. UDP and OpenHaptics devices are real: the run is paced.
  r.add({"sim-phantom", "sim-phantom[:MODEL]", false, true, make_sim_phantom_device});
  // In lockstep the peer (a device server replaying or simulating a hand) answers every datagram
  // and waits for us: nobody's hand is on it in real time, so the run is not paced, and a slow
  // moment of the machine cannot stop it (a 20 ms stall on a shared VM would).
  r.add({"udp", "udp:HOST:PORT", true, true, make_udp,
         [](const std::string& arg) { return hw::parse_udp_spec(arg).lockstep; }, false});
  r.add({"phantom", "phantom:NAME", true, true, make_phantom, {}, false});
  return r;
}

DeviceSpec parse_device_spec(const std::string& text, const DeviceRegistry& registry, const std::string& where) {
  DeviceSpec spec;
  spec.text = text;
  const auto colon = text.find(':');
  spec.kind = text.substr(0, colon);
  spec.arg = colon == std::string::npos ? "" : text.substr(colon + 1);
  if (spec.kind.empty()) throw DeviceError(where + ": empty device spec (kinds: " + registry.usages() + ")");
  const DeviceKind* kind = registry.find(spec.kind);
  if (kind == nullptr) {
    throw DeviceError(where + ": unknown device kind '" + spec.kind + "' (kinds: " + registry.usages() + ")");
  }
  const bool takes_arg = kind->usage.find(':') != std::string::npos;
  const bool arg_optional = kind->usage.find("[:") != std::string::npos;
  if (takes_arg && !arg_optional && spec.arg.empty())
    throw DeviceError(where + ": device '" + spec.kind + "' needs an argument: " + kind->usage);
  if (!takes_arg && colon != std::string::npos)
    throw DeviceError(where + ": device '" + spec.kind + "' takes no argument (got '" + text + "')");
  return spec;
}

bool DevicePlan::any_real() const {
  for (bool r : real)
    if (r) return true;
  return false;
}

std::vector<bool> DevicePlan::recorded() const {
  std::vector<bool> out;
  for (const DeviceSpec& s : specs) out.push_back(s.kind != "scripted");
  return out;
}

DevicePlan plan_devices(const scripting::Scenario& scenario, const std::vector<std::string>& options,
                        const DeviceRegistry& registry) {
  const Model& model = scenario.model();
  DevicePlan plan;
  plan.specs.resize(model.fingers.size());
  std::vector<bool> given(model.fingers.size(), false);
  for (const std::string& option : options) {
    const std::string where = "--device '" + option + "'";
    const auto eq = option.find('=');
    if (eq == std::string::npos || eq == 0)
      throw DeviceError(where + ": expected FINGER=SPEC (fingers: " + finger_names(model) + "; kinds: " + registry.usages() + ")");
    const std::string finger = option.substr(0, eq);
    std::size_t f = 0;
    while (f < model.fingers.size() && model.fingers[f].name != finger) ++f;
    if (f == model.fingers.size())
      throw DeviceError(where + ": no finger '" + finger + "' in scenario '" + scenario.name() +
                        "' (fingers: " + finger_names(model) + ")");
    if (given[f]) throw DeviceError(where + ": finger '" + finger + "' already has a --device");
    given[f] = true;
    plan.specs[f] = parse_device_spec(option.substr(eq + 1), registry, where);
  }
  // The scenario's defaults where no --device overrides them (an overridden bad default is moot).
  for (std::size_t f = 0; f < model.fingers.size(); ++f) {
    if (given[f]) continue;
    const std::string where =
        "fingers[" + std::to_string(f + 1) + "] '" + model.fingers[f].name + "': device.default";
    plan.specs[f] = parse_device_spec(scenario.fingers()[f].device, registry, where);
  }
  for (std::size_t f = 0; f < plan.specs.size(); ++f) {
    const DeviceKind* kind = registry.find(plan.specs[f].kind);
    if (!kind->factory) {
      throw DeviceError("finger '" + model.fingers[f].name + "': device '" + plan.specs[f].text + "': the " + kind->name +
                        " backend is not built into this binary (built: " + built_kinds(registry) + ")");
    }
    bool real = kind->real;
    if (real && kind->waits_for_graspsim) {
      try {
        real = !kind->waits_for_graspsim(plan.specs[f].arg);
      } catch (const std::exception& e) {
        throw DeviceError("finger '" + model.fingers[f].name + "': device '" + plan.specs[f].text + "': " + e.what());
      }
    }
    plan.real.push_back(real);
    plan.script_alongside.push_back(!kind->runs_script);
    if (kind->reads_file)
      plan.files.push_back({plan.specs[f].arg, "the " + kind->name + " file of finger '" + model.fingers[f].name + "'"});
  }
  return plan;
}

std::unique_ptr<hw::Device> make_device(const DevicePlan& plan, const DeviceRegistry& registry,
                                        const scripting::Scenario& scenario, std::size_t finger) {
  const DeviceSpec& spec = plan.specs.at(finger);
  const std::string& name = scenario.model().fingers.at(finger).name;
  const DeviceKind* kind = registry.find(spec.kind);
  if (kind == nullptr) throw DeviceError("finger '" + name + "': unknown device kind '" + spec.kind + "'");
  if (!kind->factory) {
    throw DeviceError("finger '" + name + "': device '" + spec.text + "': the " + spec.kind +
                      " backend is not built into this binary (built: " + built_kinds(registry) + ")");
  }
  std::unique_ptr<hw::Device> device;
  try {
    device = kind->factory(DeviceContext{scenario, finger, spec});
  } catch (const DeviceError&) {
    throw;
  } catch (const std::exception& e) {
    throw DeviceError("finger '" + name + "': device '" + spec.text + "': " + e.what());
  }
  if (!device) throw DeviceError("finger '" + name + "': device '" + spec.text + "' could not be built");
  const hw::WorkspaceMapping& mapping = scenario.fingers()[finger].mapping;
  if (kind->mapped && !mapping.is_identity()) device = std::make_unique<hw::MappedDevice>(std::move(device), mapping);
  return device;
}

}  // namespace graspsim::app
