// Replaying a trace, in one place: the recorded scenario (the trace's own scenario_source and
// overrides, plus any new --set) rerun with every finger fed from its recorded device samples
// (/servo hip and gimbal, row n = servo tick n; /devices rows through the recorded mapping)
// instead of its script, and the new trace compared with the recording bit for bit. The trace is
// read here (HDF5 stays out of hw/ and engine/); the fingers are hw::ReplayDevice. `graspsim
// replay` (tools/cli/replay.cpp) parses its arguments and prints what run_replay returns. See
// README.md, "Replaying a trace".
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/run.hpp"
#include "graspsim/hw/device.hpp"
#include "graspsim/hw/mapped_device.hpp"
#include "graspsim/recordings/trace_compare.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::app {

// The trace cannot be replayed as asked (not a trace, no device inputs, a finger or rate that
// does not match, a scenario that does not load): a message naming the file and the dataset,
// attribute or field. The CLI exits 2.
class ReplayError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ReplayOptions {
  std::vector<std::string> sets;   // --set NAME=VALUE given to replay, applied after the recorded ones
  // Directory that relative file names of the scenario (mesh files) are read from; "" means the
  // directory of the recorded scenario_path, taken relative to the working directory (as the
  // original run did when it ran from the same place).
  std::string scenario_dir;
};

// One finger's recorded device samples (/devices/<finger>), one element per servo tick: what
// its device gave, in the device's frame, with the workspace mapping the run applied.
struct RecordedDeviceRows {
  std::vector<hw::Vec3> position;        // m, device frame
  std::vector<hw::Vec3> gimbal;          // rad
  std::vector<std::uint32_t> buttons;    // bit i: button i
  std::vector<double> device_time;       // s, the device's clock
  std::vector<std::int64_t> sequence;    // 1: the device's sample number (-1: none)
  std::vector<std::int64_t> new_samples; // 1: new samples since the tick before (-1: not known)
  bool counted = true;                   // the table has sequence and new_samples (optional)
  std::vector<bool> overrun;             // the recorded run's pacing
  bool mapped = false;                   // the run mapped the samples (else device frame = world)
  hw::WorkspaceMapping mapping;          // parsed back exactly from the table's `mapping`
  hw::DeviceLimits limits;               // the device's, from the table's `max_force`
};

// One finger's recorded inputs, one element per servo tick.
struct RecordedFinger {
  std::vector<hw::Vec3> hip;      // m, world
  std::vector<hw::Vec3> gimbal;   // rad (roll, pitch, yaw)
  // Present when the trace has /devices/<finger>: the replay then feeds the device samples
  // through the same mapping (the same world hip, bit for bit) and rewrites the same table.
  std::optional<RecordedDeviceRows> device;
};

struct ReplayPlan {
  std::string trace;                      // the trace replayed, as given
  std::string status;                     // its root `status`
  std::string scenario_path;              // recorded scenario_path
  std::string scenario_source_hash;       // recorded scenario_source_hash
  std::vector<std::string> overrides;     // recorded overrides, then ReplayOptions::sets
  // What the recording holds (root `record`): the replay records the same, so that the two
  // compare table for table.
  recordings::RecordSelection record;
  std::unique_ptr<scripting::Scenario> scenario;   // loaded from the trace's source
  std::vector<RecordedFinger> fingers;    // Model::fingers order
  std::int64_t recorded_ticks = 0;        // servo ticks with a sample for every finger
  std::int64_t scenario_ticks = 0;        // duration * rate_servo of the (overridden) scenario
  bool what_if = false;                   // ReplayOptions::sets was not empty
  std::vector<std::string> notes;         // e.g. a cut trace replayed up to its last tick
  // The root attribute a replay trace carries: "<trace as given>\n<its scenario_source_hash>".
  std::string replay_of() const;
  // RunOptions that replay this plan (devices, max_ticks, overrides, replay_of) into `out`, with
  // the trace replayed among the inputs (the output may not be it). The plan must outlive the run.
  RunOptions run_options(const std::string& out) const;
};

// One finger's recorded inputs from `trace` (/servo/fingers/<finger>/hip and gimbal), row n =
// servo tick n, for a single finger replayed in another run (`--device FINGER=replay:TRACE`):
// the trace must be a graspsim trace of schema >= 2 recorded at `rate_servo` Hz with every
// servo tick from 0 (root `record` with servo:1). Throws ReplayError naming the file and what is wrong (the fingers it holds
// when `finger` is not one of them).
RecordedFinger read_recorded_finger(const std::string& trace, const std::string& finger, int rate_servo);

// Reads the trace's scenario and device samples and checks that they can be replayed.
// Throws ReplayError (bad input) with the file and the dataset, attribute or field named.
ReplayPlan load_replay(const std::string& trace, const ReplayOptions& options = {});

// The replay's trace when none is named: "<trace's stem>.replay.h5" in the working directory.
std::string default_replay_out(const std::string& trace);

// A replay and its verdict against the recording.
struct ReplayOutcome {
  RunResult run;
  // The new trace against the recording, bitwise, on the ticks both hold (recordings::
  // compare_traces); `compare_error` says why there is none (a trace that cannot be read).
  std::optional<recordings::CompareResult> comparison;
  std::string compare_error;
  bool reproduced() const { return comparison && comparison->same(); }
  std::int64_t state_hashes() const;   // physics ticks whose state_hash was compared
};

// Runs `plan` with `options` (from plan.run_options) and compares the new trace with the
// recording. Throws what run_scenario throws (OutputError, recordings::TraceError).
ReplayOutcome run_replay(const ReplayPlan& plan, const RunOptions& options);

}  // namespace graspsim::app
