// Device specs and the device factory: what drives each finger of a run. `--device FINGER=SPEC`
// on `graspsim run` overrides the scenario's default (`device = { default = SPEC }`, else
// "scripted"). SPEC is KIND or KIND:ARG; the kinds live in a registry (kind -> factory), so a
// backend built into this binary registers itself in one line (default_registry()) and one that
// is not gives a clear error. See README.md "Devices".
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/output_file.hpp"
#include "graspsim/hw/device.hpp"
#include "graspsim/hw/trajectory.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::app {

// A device spec or --device option that cannot be used: the message names the option or the
// scenario field, and lists the fingers or kinds there are. The CLI exits 2.
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct DeviceSpec {
  std::string text;   // as given, e.g. "udp:127.0.0.1:7001"
  std::string kind;   // before the first ':', e.g. "udp"
  std::string arg;    // after it ("" when there is none), e.g. "127.0.0.1:7001"
};

// What a factory gets: the scenario, the finger and its spec.
struct DeviceContext {
  const scripting::Scenario& scenario;
  std::size_t finger;        // Model::fingers index
  const DeviceSpec& spec;
  // The finger's scripted trajectory in the device's frame (the scenario's mapping inverted):
  // the hand that holds a simulated device, so that the mapped device goes where the script says.
  std::unique_ptr<hw::Trajectory> hand_in_device_frame() const;
};

using DeviceFactory = std::function<std::unique_ptr<hw::Device>(const DeviceContext&)>;

struct DeviceKind {
  std::string name;          // "udp"
  std::string usage;         // "udp:HOST:PORT", for messages and --help
  bool real = false;         // a device in the real world (a hand on it): the run is paced in real time
  bool mapped = true;        // gives device-frame samples: the scenario's workspace mapping applies
  DeviceFactory factory;     // empty: not built into this binary (an error naming the kind)
  // Set for a real kind whose spec can ask it to wait for graspsim (co-simulation, e.g.
  // `udp:...,lockstep`): true for such a spec, whose device then counts as not real (the run is
  // not paced: the peer answers every datagram, so wall time decides nothing).
  std::function<bool(const std::string& arg)> waits_for_graspsim = {};
  // Whether the device runs the finger's script itself (scripted: it is the script; replay: it
  // runs it alongside; sim-phantom: the hand follows it). false (udp, phantom): the run loop runs
  // it alongside (RunOptions::Devices::script_alongside).
  bool runs_script = true;
  // ARG names a file the device reads (replay:TRACE.h5): the run's output may not be that file.
  bool reads_file = false;
};

class DeviceRegistry {
 public:
  void add(DeviceKind kind);   // replaces a kind of the same name
  const DeviceKind* find(const std::string& name) const;
  // "scripted, replay:TRACE.h5, ..." in registration order (built_only: those with a factory).
  std::string usages(bool built_only = false) const;
 private:
  std::vector<DeviceKind> kinds_;   // registration order (messages list them so)
};

// scripted, replay:TRACE.h5, sim-phantom[:MODEL], udp:HOST:PORT and phantom:NAME, each with its
// factory (phantom's, in a binary built without the OpenHaptics SDK, throws naming the SDK).
DeviceRegistry default_registry();

// Parses KIND[:ARG]; throws DeviceError naming `where` for an empty spec, an unknown kind (listing
// the kinds) or a kind that needs an argument and has none.
DeviceSpec parse_device_spec(const std::string& text, const DeviceRegistry& registry, const std::string& where);

// One spec per finger of a scenario: the scenario's defaults, then the --device options.
struct DevicePlan {
  std::vector<DeviceSpec> specs;   // Model::fingers order
  std::vector<bool> real;          // per finger: DeviceKind::real, unless the spec waits for graspsim
  bool any_real() const;
  // Fingers whose device is not "scripted": their samples go to /devices/<finger> in the trace.
  std::vector<bool> recorded() const;
  // Fingers whose device does not run the finger's script (DeviceKind::runs_script false).
  std::vector<bool> script_alongside;
  // The files the devices read (DeviceKind::reads_file), for RunOptions::inputs.
  std::vector<InputFile> files;
};

// `options` are the --device values "FINGER=SPEC" in the order given. Throws DeviceError for a
// malformed option, an unknown finger (listing the scenario's fingers), a finger given twice, or
// a bad spec (also the scenario's own `device.default`, named by its field), or a kind that is
// not built into this binary: all before any device opens or any trace is written.
DevicePlan plan_devices(const scripting::Scenario& scenario, const std::vector<std::string>& options,
                        const DeviceRegistry& registry);

// Builds finger f's device from the plan, wrapped in hw::MappedDevice when its kind is mapped
// and the scenario's mapping is not the identity. Throws DeviceError when the kind is not built
// into this binary or its factory fails (a trace that cannot be read, a device that does not
// open), naming the finger and the spec.
std::unique_ptr<hw::Device> make_device(const DevicePlan& plan, const DeviceRegistry& registry,
                                        const scripting::Scenario& scenario, std::size_t finger);

}  // namespace graspsim::app
