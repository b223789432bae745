// A scenario loaded from Lua: the engine Model, each finger's device set-up, the run's duration
// and seed, and the expectations the run checks. The only place that converts between Lua
// values and C++ types is scripting/src/lua_convert.cpp.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "graspsim/engine/model.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/simulation.hpp"
#include "graspsim/engine/state.hpp"
#include "graspsim/hw/device.hpp"
#include "graspsim/hw/mapped_device.hpp"
#include "graspsim/hw/trajectory.hpp"
#include "graspsim/scripting/error.hpp"        // ScenarioError
#include "graspsim/scripting/lua_sandbox.hpp"  // SandboxLimits

namespace graspsim::scripting {

class LuaSandbox;

// What a finger is driven by when nothing on the command line overrides it.
struct FingerSetup {
  hw::DeviceLimits limits;   // clamp for rendered forces
  // `device = { default = SPEC, scale, offset, rotation }`: the finger's device when the command
  // line names none (a --device SPEC, app/devices.hpp; "scripted" unless given) and the
  // mapping of that device's workspace into the world (not applied to scripted fingers, whose
  // trajectories are already in the world).
  std::string device = "scripted";
  hw::WorkspaceMapping mapping;
};

// One expectation about the outcome: a Lua function checked at time `at`.
struct Expectation {
  std::string what;     // the sentence the scenario gave, e.g. "box lifted at least 5 cm"
  double at = -1.0;     // s: when to check; < 0 means at the end of the run
  int function_ref = 0; // registry reference of the Lua check function (owned by the sandbox)
};

struct ExpectationResult {
  std::string what;
  bool passed = false;
  std::string detail;   // the message the check function returned, if any
};

// What the expectation functions see of the simulation (plain data, filled by the runner).
struct ObjectSnapshot {
  std::string name;
  Vec3 position{0.0, 0.0, 0.0};           // m, world
  Quat orientation = Quat::Identity();    // 1, body to world
  Vec3 velocity{0.0, 0.0, 0.0};           // m/s
  Vec3 angular_velocity{0.0, 0.0, 0.0};   // rad/s, world
  int floor_contacts = 0;                 // 1
};
struct FingerSnapshot {
  std::string name;
  Vec3 hip{0.0, 0.0, 0.0};          // m, world
  Vec3 god_object{0.0, 0.0, 0.0};   // m, world
  Vec3 force{0.0, 0.0, 0.0};        // N, world, on the finger (last haptic tick)
  std::string touching;             // name of the contacted object, "floor" or "" (free)
  ContactPhase phase = ContactPhase::kFree;   // friction-cone phase ("free", "stick", "slip")
  double slip = 0.0;                // m: total distance its god-object slid over surfaces so far
};
struct Snapshot {
  double time = 0.0;   // s
  bool local_model = false;   // the fast loops see each body move on from this pose at its
                              // velocities (engine local_model.hpp; integrator = "implicit")
  std::vector<ObjectSnapshot> objects;   // Model::bodies order
  std::vector<FingerSnapshot> fingers;   // Model::fingers order
};

// What the scenario's expectation functions and the trajectories' view see, written into `s`
// in place: after the first call, for the same model, it allocates nothing (names are assigned
// over equal names, vectors keep their size; `touching` is assigned without a temporary, within
// the room the run loop's presize_snapshot gives it). `slip` (m) is each finger's god-object
// slide so far, summed over the haptic ticks.
void fill_snapshot(const Simulation& sim, const TickRecord& last, const std::vector<double>& slip, Snapshot& s);

// Perturbed waypoints (`graspsim run --jitter A --jitter-seed N`, README.md "Perturbed
// waypoints"): every waypoint of every finger's trajectory moved by its own random offset, each
// component uniform in [-amplitude, amplitude); a trajectory given as a function gets one constant
// offset per finger instead. Positions only (a waypoint's gimbal pitch is kept). The generator
// (scripting/src/jitter.hpp) gives the same offsets on every machine for a seed.
struct Jitter {
  double amplitude = 0.0;   // m, >= 0 and finite; 0: no jitter
  std::uint64_t seed = 0;   // 1
};

// Ceilings on a run's size, checked when a scenario loads (with its --set overrides), before any
// memory or disk is committed to it (scripting/README.md, "Ceilings"):
// - kMaxServoRate: a haptic servo loop runs at 1 to 10 kHz (OpenHaptics 1 kHz, the paper 3 kHz);
//   10 times the fastest. The trace writer holds a quarter second of rows per table, so the
//   rate decides its memory: at 100 kHz 25,000 rows a table.
// - kMaxDuration: 24 h of simulated time, longer than any session with a hand on a device (the
//   library's longest scenario runs 7.5 s); at 3 kHz, 259 million servo rows (63 GB for the lift).
// What the machine can hold below them is checked before a run (app/run_budget.hpp).
inline constexpr int kMaxServoRate = 100'000;    // Hz
inline constexpr double kMaxDuration = 86'400.0;  // s

struct LoadOptions {
  // "--set name=value" overrides, applied to the scenario table before it is converted.
  std::vector<std::string> sets;
  // Memory limit and instruction budgets of the Lua state the scenario runs in.
  SandboxLimits limits;
  // Directory that relative file names in the scenario (mesh `file`s) are read from; "" means
  // the scenario file's own directory. A replay sets it: its source comes from a trace.
  std::string base_directory;
  // Applied to the trajectories after the overrides, so `--set fingers.thumb.trajectory.1.p=...`
  // moves the waypoint that is then jittered.
  Jitter jitter;
};

class Scenario {
 public:
  // Loads, runs (sandboxed, with an instruction budget) and converts a scenario file.
  // Throws ScenarioError with a message naming the file and line or the field.
  static Scenario load(const std::string& path, const LoadOptions& options = {});
  // The same from text already read (a trace's scenario_source): `path` names it in messages
  // and tracebacks and, unless options.base_directory is set, places its relative file names.
  static Scenario load_source(const std::string& source, const std::string& path,
                              const LoadOptions& options = {});

  Scenario(Scenario&&) noexcept;
  Scenario& operator=(Scenario&&) noexcept;
  ~Scenario();

  const std::string& path() const { return path_; }
  const std::string& source() const { return source_; }   // the file's text, for the trace
  // Every file the scenario read besides its own (mesh files), as opened: a run's output may be
  // none of them.
  const std::vector<std::string>& files() const { return files_; }
  const std::string& name() const { return name_; }
  const std::string& description() const { return description_; }
  const Model& model() const { return model_; }
  double duration() const { return duration_; }              // s
  std::uint64_t seed() const { return seed_; }
  // stability = "refuse": an unstable mode found by the stability check stops the run
  // (engine/stability.hpp); "warn" (the default) only warns.
  bool refuse_unstable() const { return refuse_unstable_; }
  const std::vector<FingerSetup>& fingers() const { return fingers_; }
  const std::vector<Expectation>& expectations() const { return expectations_; }
  // Every parameter after overrides, as sorted "path = value" lines, for the trace.
  const std::vector<std::string>& parameters() const { return parameters_; }
  // The jitter it was loaded with, and the offsets it gave (m, world), per finger: one per
  // waypoint, or one for a function trajectory; empty without jitter. `parameters()` keeps the
  // waypoints as written: the offsets are added to them.
  const Jitter& jitter() const { return jitter_; }
  const std::vector<std::vector<Vec3>>& jitter_offsets() const { return jitter_offsets_; }
  // The offsets as lines for the trace's root `jitter_offsets`, every number at %.17g (it reads
  // back to the same double): "thumb waypoint 1: dx dy dz" or "finger function: dx dy dz".
  std::vector<std::string> jitter_lines() const;

  // The scripted trajectory of finger i (waypoints, or a Lua function of time). Lua errors while
  // it runs are thrown as ScenarioError with file:line and a traceback.
  std::unique_ptr<hw::Trajectory> make_trajectory(std::size_t finger) const;

  // Paced runs (app/script_thread.hpp, scripting/README.md "Threads"): while set,
  // make_trajectory hands every Lua function trajectory (waypoints need no Lua) to the wrapper,
  // with its finger, and returns what the wrapper returns: a trajectory fed by a script thread.
  // An empty function removes it. Not thread-safe: set it before devices are built.
  using TrajectoryWrapper =
      std::function<std::unique_ptr<hw::Trajectory>(std::size_t finger, std::unique_ptr<hw::Trajectory> lua)>;
  void set_trajectory_wrapper(TrajectoryWrapper wrapper) const { wrapper_ = std::move(wrapper); }
  // True when some trajectory of a finger is a Lua function.
  bool has_lua_trajectories() const;
  // The thread guard (LuaSandbox::forbid_thread): from now on any use of this scenario's Lua state
  // from thread `id` throws and is counted; std::thread::id{} lifts it.
  void forbid_lua_on(std::thread::id id) const;
  // Entries into Lua and Lua allocations seen on a forbidden thread so far (0 in a correct run).
  std::int64_t lua_uses_on_forbidden_thread() const;

  // True when some trajectory function takes a second parameter (or ...): only then does the
  // run loop need to keep the view up to date.
  bool uses_view() const { return uses_view_; }
  // Writes `now` into the read-only view that trajectory functions get as their second argument
  // (the runner calls it before the first tick and after every physics tick). Allocates only the
  // first time.
  void update_view(const Snapshot& now) const;

  // Checks expectation i against `now` (and `initial`, the snapshot at t = 0).
  ExpectationResult check(std::size_t expectation, const Snapshot& now,
                          const Snapshot& initial) const;

 private:
  Scenario();
  // Moves the trajectories by the jitter's offsets and keeps them (load_source, after conversion).
  void apply_jitter(const Jitter& jitter);
  std::string path_, source_, name_, description_;
  std::vector<std::string> files_;
  Model model_;
  double duration_ = 0.0;
  std::uint64_t seed_ = 0;
  bool refuse_unstable_ = false;
  std::vector<FingerSetup> fingers_;
  std::vector<Expectation> expectations_;
  std::vector<std::string> parameters_;
  bool uses_view_ = false;
  // Finger trajectories: waypoints, or a registry ref to a Lua function (0 when waypoints).
  struct TrajectorySpec {
    std::vector<hw::Waypoint> waypoints;
    hw::Interpolation interpolation = hw::Interpolation::kMinimumJerk;
    int function_ref = 0;
    bool offset_function = false;    // a function trajectory moved by `offset` (jitter)
    Vec3 offset{0.0, 0.0, 0.0};      // m, world
  };
  std::vector<TrajectorySpec> trajectories_;
  Jitter jitter_;
  std::vector<std::vector<Vec3>> jitter_offsets_;   // per finger (see jitter_offsets())
  std::unique_ptr<LuaSandbox> lua_;   // owns the Lua state the functions live in
  mutable TrajectoryWrapper wrapper_;   // set by a paced run while it builds devices
  friend class ScenarioBuilder;
};

}  // namespace graspsim::scripting
