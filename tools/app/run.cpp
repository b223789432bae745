// The run loop: devices -> engine -> devices, trace every tick, check expectations on time.
#include "app/run.hpp"
#include "graspsim_version.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <numeric>
#include <new>
#include <optional>
#include <sstream>
#include <thread>

#include "app/script_thread.hpp"
#include "app/stability_watch.hpp"

#include "graspsim/engine/energy.hpp"
#include "graspsim/engine/simulation.hpp"
#include "graspsim/engine/state_hash.hpp"
#include "graspsim/hw/mapped_device.hpp"
#include "graspsim/hw/sample_clock.hpp"
#include "graspsim/hw/sample_check.hpp"
#include "graspsim/hw/sample_counter.hpp"
#include "graspsim/hw/scripted_finger.hpp"
#include "graspsim/recordings/trace_recorder.hpp"
#include "graspsim/recordings/trace_writer.hpp"

#ifndef GRASPSIM_BUILD_FLAGS
#define GRASPSIM_BUILD_FLAGS "unknown"
#endif

namespace graspsim::app {
namespace {

// What the energy watch found, for the user: which bodies, how much, since when, and what to do.
std::string energy_gain_message(const Model& model, const EnergyGain& g, double t, std::int64_t tick) {
  std::ostringstream msg;
  msg << "objects[" << g.body + 1 << "] '" << model.bodies[g.body].name << "'";
  if (g.bodies > 1) msg << " and the " << g.bodies - 1 << " bodies touching it";
  msg << " gained " << g.energy - g.reference << " J with no finger on " << (g.bodies > 1 ? "them" : "it") << ", from " << g.reference
      << " J at t = " << g.since << " s to " << g.energy << " J at t = " << t << " s (tick " << tick
      << "; allowed " << g.bound << " J): the integration is unstable";
  if (model.integrator == Integrator::kPaper) {
    msg << " (the paper's explicit step at rates.physics = " << model.rates.physics
        << " Hz; raise the rate, soften the contact, or use integrator = \"implicit\")";
  }
  return msg.str();
}

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}


scripting::Snapshot snapshot(const Simulation& sim, const TickRecord& last,
                             const std::vector<double>& slip) {
  scripting::Snapshot s;
  scripting::fill_snapshot(sim, last, slip, s);
  return s;
}

std::string join_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

// "fnv1a64:" and 16 lower-case hex digits of the FNV-1a 64 hash of the text's bytes.
std::string source_hash(const std::string& text) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016" PRIx64, fnv1a64(text.data(), text.size()));
  return std::string("fnv1a64:") + hex;
}

// Root attributes go to the trace if there is one (no trace: the benchmark's baseline).
struct OptionalWriter {
  recordings::TraceWriter* w;
  template <typename T>
  void set_attribute(const std::string& name, const T& value) {
    if (w) w->set_attribute(name, value);
  }
};

// Crash safety (recordings/README.md): a run killed at any moment loses less than kFlushSimulated
// of simulated time, however far the writer thread lags. The trace is flushed every flush
// interval (at most kFlushSimulated / (kFlushesInFlight + 1) of simulated time), and before a
// flush is handed to the writer the one kFlushesInFlight flushes before it must be on disk: the
// loop waits for it if need be (a slow disk slows the run rather than break the bound). So the
// file always holds every tick up to kFlushesInFlight + 1 intervals ago. One in flight: two
// cost the 40 s lift 12 ms more process CPU than none (three times the flushes), one 6 ms
// (recordings/README.md "Crash safety"). It is also flushed at least every kFlushWall seconds of
// wall time (a run slower than real time). The wall clock is read every kWallCheckTicks ticks;
// it decides only when rows reach the disk, never what is written.
constexpr double kFlushSimulated = 0.25;   // s, simulated
constexpr int kFlushesInFlight = 1;
constexpr double kFlushWall = 0.9;         // s, wall (under 1 s, with the check interval's slack)
constexpr std::int64_t kWallCheckTicks = 64;

}  // namespace

// Servo ticks between flushes on simulated time: the largest whole number of physics (and
// haptic) periods within kFlushSimulated / (kFlushesInFlight + 1), so that every flush interval
// holds the same number of rows of every loop and each table's chunk can be exactly one interval
// (each chunk is then written once, whole: recordings/README.md "Cost"). 360 ticks (0.12 s) at
// 3000/500/50 Hz. If one physics period is longer than that: that limit, floor(kFlushSimulated /
// (kFlushesInFlight + 1) * rate_servo).
std::int64_t flush_interval_ticks(const Model& model) {
  const std::int64_t limit = std::max<std::int64_t>(
      1, static_cast<std::int64_t>(std::floor(kFlushSimulated / (kFlushesInFlight + 1) * model.rates.servo)));
  const Divisors d = divisors(model.rates);
  const std::int64_t period = std::lcm(d.haptic, d.physics);
  return period <= limit ? limit / period * period : limit;
}

namespace {

constexpr std::size_t kNoColumn = static_cast<std::size_t>(-1);

// One finger's /devices/<finger> table (recordings/README.md "Schema"): every device sample as
// the device gave it, in its own frame, with the force sent to it in that frame.
struct DeviceColumns {
  std::size_t finger;   // Model::fingers index
  recordings::TraceTable* table;
  std::size_t tick, time, device_time, position, gimbal, buttons, force, overrun;   // row offsets
  std::size_t sequence = kNoColumn, new_samples = kNoColumn;   // row offsets (kNoColumn: not written)
  // What the device offers, looked up once (not a dynamic_cast per tick on the loop):
  const hw::MappedDevice* mapped = nullptr;     // its workspace mapping, if it is mapped
  const hw::SampleCounter* counter = nullptr;   // the device's sample numbering, if it has one
  const hw::SampleClock* clock = nullptr;       // the device's own clock, if it has one
  const RecordedPacing* recorded = nullptr;     // a replayed device's recorded overrun flags
};

std::string mapping_text(const hw::WorkspaceMapping& m) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "scale %.17g; offset %.17g %.17g %.17g m; rotation %.17g %.17g %.17g rad", m.scale,
                m.offset.x(), m.offset.y(), m.offset.z(), m.rotation.x(), m.rotation.y(), m.rotation.z());
  return buf;
}

DeviceColumns device_columns(recordings::TraceWriter& writer, std::size_t finger, const std::string& name,
                             hw::Device& device, std::size_t block_rows, bool counters) {
  using recordings::DType;
  DeviceColumns c{finger, &writer.table("devices/" + name, block_rows), 0, 0, 0, 0, 0, 0, 0, 0, kNoColumn, kNoColumn};
  recordings::TraceTable& t = *c.table;
  c.tick = t.add_column("tick", 1, DType::kInt64, "tick");
  c.time = t.add_column("time", 1, DType::kFloat64, "s");
  c.device_time = t.add_column("device_time", 1, DType::kFloat64, "s");
  c.position = t.add_column("position", 3, DType::kFloat64, "m");
  c.gimbal = t.add_column("gimbal", 3, DType::kFloat64, "rad");
  c.buttons = t.add_column("buttons", 1, DType::kInt64, "1");
  c.force = t.add_column("force", 3, DType::kFloat64, "N");
  c.overrun = t.add_column("overrun", 1, DType::kInt8, "1");
  // Gaps and holds at the device's own rate (hw::SampleCounter; -1 for a device without one).
  if (counters) {
    c.sequence = t.add_column("sequence", 1, DType::kInt64, "1");
    c.new_samples = t.add_column("new_samples", 1, DType::kInt64, "1");
  }
  c.mapped = dynamic_cast<const hw::MappedDevice*>(&device);
  const hw::Device& own = c.mapped ? c.mapped->inner() : device;   // the device behind the mapping
  c.counter = dynamic_cast<const hw::SampleCounter*>(&own);
  c.clock = dynamic_cast<const hw::SampleClock*>(&own);
  c.recorded = dynamic_cast<const RecordedPacing*>(&own);
  t.set_attribute(".", "device", device.describe());
  t.set_attribute(".", "mapping", c.mapped ? mapping_text(c.mapped->mapping()) : "identity (device frame = world)");
  t.set_attribute("gimbal", "order", "roll, pitch, yaw");
  char limit[32];
  std::snprintf(limit, sizeof limit, "%.17g", device.limits().max_force);
  t.set_attribute(".", "max_force", limit);   // N: the clamp the run used (a replay uses it again)
  return c;
}

}  // namespace

bool RunResult::passed() const {
  return error.empty() &&
         std::all_of(expectations.begin(), expectations.end(), [](const auto& e) { return e.passed; });
}

RunResult run_scenario(const scripting::Scenario& scenario, const RunOptions& options) {
  const Model& model = scenario.model();
  RunResult result;
  result.trace_path = options.out.empty() ? default_trace_name(scenario.name()) : options.out;

  recordings::TraceOptions trace_options;
  if (options.block_rows > 0) trace_options.block_rows = options.block_rows;
  trace_options.compression = options.compression;
  // HDF5 writes and flushes run on a writer thread: the run loop only fills memory
  // (recordings/README.md "Cost"); the file is the same as without it.
  trace_options.background = options.background_writer;
  // Without a trace (the logging benchmark's baseline) every attribute and row is skipped.
  std::optional<recordings::TraceWriter> writer_holder;
  std::optional<OutputClaim> claim;   // the output path, locked; the trace is written to its partial name
  // A failure that escapes before the loop (the file or its first attributes cannot be
  // written: a full disk) leaves a partial trace without a tick: it is closed and removed, and
  // the output path is as it was.
  struct AbandonOnThrow {
    std::optional<recordings::TraceWriter>& writer;
    std::optional<OutputClaim>& claim;
    const int uncaught = std::uncaught_exceptions();
    ~AbandonOnThrow() {
      if (std::uncaught_exceptions() <= uncaught) return;
      try {
        if (writer) writer->close("error: the run could not start");
      } catch (...) {
      }
      if (claim) claim->abandon();
    }
  } abandon_on_throw{writer_holder, claim};
  if (options.write_trace) {
    std::vector<InputFile> inputs = options.inputs;
    inputs.push_back({scenario.path(), "the scenario"});
    for (const std::string& f : scenario.files()) inputs.push_back({f, "a mesh file of the scenario"});
    refuse_input_as_output(result.trace_path, inputs);   // throws OutputError
    claim.emplace(result.trace_path);                     // throws OutputError
    writer_holder.emplace(claim->partial(), trace_options);   // throws TraceError if it cannot
  } else {
    result.trace_path.clear();
  }
  OptionalWriter writer{writer_holder ? &*writer_holder : nullptr};

  // The file explains and replays itself: the scenario text, every parameter, rates, seed, build.
  writer.set_attribute("schema_version", recordings::kSchemaVersion);
  writer.set_attribute("scenario_path", scenario.path());
  writer.set_attribute("scenario_name", scenario.name());
  writer.set_attribute("scenario_source", scenario.source());
  writer.set_attribute("scenario_source_hash", source_hash(scenario.source()));
  writer.set_attribute("overrides", join_lines(options.overrides));
  writer.set_attribute("integrator", std::string(model.integrator == Integrator::kPaper ? "paper" : "implicit"));
  writer.set_attribute("local_model", static_cast<std::int64_t>(model.local_model ? 1 : 0));
  writer.set_attribute("parameters", join_lines(scenario.parameters()));
  // Perturbed waypoints (README.md "Perturbed waypoints"): a replay loads the scenario with the
  // same jitter; the offsets themselves, to read and to check the generator against.
  if (scenario.jitter().amplitude > 0.0) {
    writer.set_attribute("jitter_amplitude", scenario.jitter().amplitude);
    writer.set_attribute("jitter_seed", static_cast<std::int64_t>(scenario.jitter().seed));
    writer.set_attribute("jitter_offsets", join_lines(scenario.jitter_lines()));
  }
  writer.set_attribute("rate_servo", std::int64_t{model.rates.servo});
  writer.set_attribute("rate_haptic", std::int64_t{model.rates.haptic});
  writer.set_attribute("rate_physics", std::int64_t{model.rates.physics});
  writer.set_attribute("seed", static_cast<std::int64_t>(scenario.seed()));
  writer.set_attribute("duration", scenario.duration());
  writer.set_attribute("graspsim_version", GRASPSIM_VERSION);
#if defined(__clang__)
  writer.set_attribute("compiler", std::string("clang++ ") + __VERSION__);   // "clang++ Debian Clang 14.0.6"
#else
  writer.set_attribute("compiler", std::string("g++ ") + __VERSION__);       // "g++ 12.2.0"
#endif
  writer.set_attribute("build_flags", GRASPSIM_BUILD_FLAGS);
  for (const auto& [name, value] : options.attributes) writer.set_attribute(name, value);

  std::vector<std::unique_ptr<hw::Device>> devices;
  std::vector<double> slip(model.fingers.size(), 0.0);
  // Paced runs keep Lua off the loop's thread (script_thread.hpp, README.md "Devices"): Lua
  // trajectories are sampled ahead on a script thread (declared after the devices, so it stops
  // before they go), expectations are checked after the loop from snapshots the loop copied at
  // their ticks, and the loop's thread may not enter Lua at all (Scenario::forbid_lua_on).
  const bool paced = options.pacer != nullptr;
  std::optional<ScriptThread> script;
  std::vector<std::pair<std::int64_t, std::size_t>> due;   // (tick, expectation) in due order
  std::size_t next_due = 0;
  std::vector<scripting::Snapshot> due_snapshots;   // paced: the snapshot at each due tick
  scripting::Snapshot initial;                      // the snapshot at t = 0
  // Zero force on every device, even if one of them fails to take it (its error is kept for
  // the result when the run has none: a device that may still push is worth reporting).
  std::string release_error;
  const auto release_all = [&devices, &release_error] {
    for (auto& d : devices) {
      try {
        d->release();
      } catch (const std::exception& e) {
        if (release_error.empty()) release_error = "releasing " + d->describe() + ": " + e.what();
      }
    }
  };
  // Written now and again at close with the run's own, so a trace cut by a crash still has the
  // model's.
  StabilityWatch stability(model, options.refuse_unstable || scenario.refuse_unstable(), options.on_warning);
  stability.before_run();
  writer.set_attribute("warnings", stability.text());
  writer.set_attribute("force_ramp", options.force_ramp);

  EnergyWatch energy(model);   // a blow-up of bodies nothing powers stops the run (energy.hpp)

  const auto start = Clock::now();
  std::optional<Simulation> sim_holder;
  bool realtime = false;   // this thread is SCHED_FIFO (until the loop ends)
  bool started = false;    // every device was built: the run goes on to its first tick
  // "interrupted [by SIGTERM] at t = T s".
  const auto interrupted_at = [&options](double t) {
    const int signal = options.interrupt_signal ? options.interrupt_signal->load() : 0;
    const char* name = signal > 0 ? sigabbrev_np(signal) : nullptr;
    return std::string("interrupted") + (name ? std::string(" by SIG") + name : std::string()) + " at t = " +
           std::to_string(t) + " s";
  };
  try {
    std::ostringstream device_list;
    {
      // Paced: every Lua trajectory a device asks for is fed by the script thread.
      struct Unwrap {
        const scripting::Scenario& s;
        ~Unwrap() { s.set_trajectory_wrapper({}); }
      } unwrap{scenario};
      if (paced && scenario.has_lua_trajectories()) {
        ScriptThreadOptions so;
        so.rate_servo = model.rates.servo;
        so.physics_divisor = divisors(model.rates).physics;
        so.end_tick = static_cast<std::int64_t>(std::llround(scenario.duration() * model.rates.servo));
        so.view = scenario.uses_view();
        so.wait_for_samples = options.wait_for_script;
        script.emplace(scenario, so);
        scenario.set_trajectory_wrapper(
            [&script](std::size_t, std::unique_ptr<hw::Trajectory> lua) { return script->wrap(std::move(lua)); });
      }
      for (std::size_t f = 0; f < model.fingers.size(); ++f) {
        if (options.make_device) devices.push_back(options.make_device(f));
        else devices.push_back(std::make_unique<hw::ScriptedFinger>(scenario.make_trajectory(f),
                                                                    scenario.fingers()[f].limits));
        device_list << model.fingers[f].name << ": " << devices.back()->describe()
                    << " (max force " << devices.back()->limits().max_force << " N)\n";
      }
    }
    started = true;
    writer.set_attribute("devices", device_list.str());
    // Every sample is checked (finite, inside the device's workspace) before the engine sees it.
    std::vector<hw::SampleCheck> checks;
    for (std::size_t f = 0; f < devices.size(); ++f) checks.emplace_back(*devices[f], model.fingers[f].name);
    std::vector<hw::DeviceSample> samples(devices.size());   // this tick's, as read (world)
    // The scripts of fingers whose device does not run them (RunOptions::script_alongside).
    std::vector<std::unique_ptr<hw::Trajectory>> side_scripts(devices.size());
    for (std::size_t f = 0; f < options.script_alongside.size() && f < devices.size(); ++f)
      if (options.script_alongside[f]) side_scripts[f] = scenario.make_trajectory(f);

    Simulation& sim = sim_holder.emplace(model);
    std::optional<recordings::TraceRecorder> recorder;
    const std::int64_t flush_ticks = flush_interval_ticks(model);
    std::int64_t until_flush = flush_ticks;   // servo ticks to the next flush on simulated time
    // The tickets of the last kFlushesInFlight flushes handed to the writer, oldest at `oldest`.
    std::array<std::uint64_t, kFlushesInFlight> flush_tickets{};
    std::size_t oldest = 0;
    if (writer_holder) recorder.emplace(*writer_holder, model, options.block_rows > 0 ? 0 : flush_ticks);
    std::vector<DeviceColumns> device_tables;
    if (writer_holder) {
      for (std::size_t f = 0; f < options.record_devices.size() && f < devices.size(); ++f)
        if (options.record_devices[f])
          device_tables.push_back(device_columns(*writer_holder, f, model.fingers[f].name, *devices[f],
                                                 options.block_rows > 0 ? options.block_rows : flush_ticks,
                                                 options.device_counters));
    }
    Input input = make_input(model);
    TickRecord record = make_tick_record(model);
    std::vector<Vec3> rendered(model.fingers.size(), Vec3::Zero());
    const auto ticks = static_cast<std::int64_t>(std::llround(scenario.duration() * model.rates.servo));
    const std::int64_t run_ticks = options.max_ticks >= 0 ? std::min(ticks, options.max_ticks) : ticks;

    // Expectations in the order they fall due: (tick, index), so ties keep the scenario's order.
    for (std::size_t i = 0; i < scenario.expectations().size(); ++i) {
      const double at = scenario.expectations()[i].at;
      const std::int64_t tick = at < 0.0 ? ticks : std::min<std::int64_t>(ticks, std::llround(at * model.rates.servo));
      due.emplace_back(tick, i);
    }
    std::sort(due.begin(), due.end());
    for (const auto& e : scenario.expectations())
      result.expectations.push_back({e.what, false, "not checked: the run stopped before it was due"});
    // The read-only view trajectory functions get: the state as the last physics tick left it
    // (before the first tick: the initial state, fingers at zero and free). Updated only when a
    // physics tick ran, and only if some trajectory function takes it.
    const bool view = scenario.uses_view();
    scripting::Snapshot view_state;
    if (view) {
      scripting::fill_snapshot(sim, record, slip, view_state);
      scenario.update_view(view_state);
    }
    if (paced) {
      // Room for every snapshot the loop will copy, so that copying allocates nothing.
      scripting::Snapshot prototype;
      scripting::fill_snapshot(sim, record, slip, prototype);
      presize_snapshot(prototype);
      due_snapshots.assign(due.size(), prototype);
      for (scripting::Snapshot& s : due_snapshots) presize_snapshot(s);
      initial = prototype;
      presize_snapshot(initial);
      if (script && script->has_feeds()) {
        if (view) script->prepare_views(prototype);
        script->start();
      }
    }
    const bool script_feeds = script && script->has_feeds();
    const auto check_due = [&](std::int64_t tick) {
      while (next_due < due.size() && due[next_due].first == tick) {
        const std::size_t i = due[next_due].second;
        // Paced: only the copy here; the check runs after the loop, off the real-time thread.
        if (paced) scripting::fill_snapshot(sim, record, slip, due_snapshots[next_due]);
        else result.expectations[i] = scenario.check(i, snapshot(sim, record, slip), initial);
        ++next_due;
      }
    };

    auto last_progress = start;
    auto last_flush = start;
    if (options.pacer) {
      // The writer thread exists already (the TraceWriter started it), so only this thread
      // becomes real-time; the CLI has warned if the system does not allow it.
      if (options.realtime) realtime = enter_realtime().empty();
      scenario.forbid_lua_on(std::this_thread::get_id());
      options.pacer->start();
    }
    for (std::int64_t n = 0; n < run_ticks; ++n) {
      const double t = sim.time();
      for (std::size_t f = 0; f < devices.size(); ++f) {
        if (side_scripts[f]) side_scripts[f]->sample(t);   // for what the script keeps; output unused
        samples[f] = devices[f]->read(n, t);
        checks[f].check(samples[f], n, t);   // throws: the run stops with the device's fault
        input.fingers[f].hip = samples[f].position;
        input.fingers[f].gimbal = samples[f].gimbal;
      }
      if (n == 0) {
        // Before the first step no finger record exists yet: a finger is where its device is.
        for (std::size_t f = 0; f < devices.size(); ++f) record.servo[f].hip = record.haptic[f].god_object = input.fingers[f].hip;
        if (paced) scripting::fill_snapshot(sim, record, slip, initial);
        else initial = snapshot(sim, record, slip);
      }
      check_due(n);
      sim.step(input, record);
      if (options.force_ramp > 0.0 && t < options.force_ramp) {
        const double ramp = t / options.force_ramp;   // 1: linear rise from 0 at t = 0
        for (std::size_t f = 0; f < devices.size(); ++f) rendered[f] = devices[f]->render(ramp * record.servo[f].force);
      } else {
        for (std::size_t f = 0; f < devices.size(); ++f) rendered[f] = devices[f]->render(record.servo[f].force);
      }
      TickPace pace;
      if (options.pacer) {
        // The forces are out: wait for this tick's deadline (or count it late). A stall releases
        // every device at once, before anything else runs, and ends the run.
        pace = options.pacer->end_tick(n);
        if (pace.stalled || pace.lagging) {
          release_all();
          char why[240];
          if (pace.stalled) {
            std::snprintf(why, sizeof why,
                          "the servo loop stalled: tick %lld's forces went out %.3f ms after the previous "
                          "tick's (stall timeout %.3f ms); every device was released",
                          static_cast<long long>(n), pace.gap * 1e3, options.pacer->stall_timeout() * 1e3);
          } else {
            std::snprintf(why, sizeof why,
                          "the servo loop fell behind: tick %lld ended %.3f ms past its deadline (lag limit "
                          "%.3f ms): it cannot keep %lld Hz here; every device was released",
                          static_cast<long long>(n), pace.lateness * 1e3, options.pacer->lag_limit() * 1e3,
                          static_cast<long long>(model.rates.servo));
          }
          throw std::runtime_error(why);
        }
      }
      for (const DeviceColumns& c : device_tables) {
        // The device's own view: before the mapping (device frame) and the force it was sent.
        const hw::DeviceSample* raw = c.mapped ? &c.mapped->last_device_sample() : &samples[c.finger];
        const hw::Vec3* force = c.mapped ? &c.mapped->last_device_force() : &rendered[c.finger];
        double* row = c.table->append_row();
        row[c.tick] = static_cast<double>(n);
        row[c.time] = static_cast<double>(n) / model.rates.servo;
        row[c.device_time] = c.clock ? c.clock->sample_time() : t;
        for (int i = 0; i < 3; ++i) {
          row[c.position + i] = raw->position[i];
          row[c.gimbal + i] = raw->gimbal[i];
          row[c.force + i] = (*force)[i];
        }
        row[c.buttons] = static_cast<double>(raw->buttons);
        row[c.overrun] = (c.recorded ? c.recorded->recorded_overrun() : pace.overrun) ? 1.0 : 0.0;
        if (c.sequence != kNoColumn) {
          row[c.sequence] = c.counter ? static_cast<double>(c.counter->sample_sequence()) : -1.0;
          row[c.new_samples] = c.counter ? static_cast<double>(c.counter->new_samples()) : -1.0;
        }
      }
      if (recorder) {
        recorder->record(record, rendered, input, sim.state());
        // A countdown, not (n + 1) % flush_ticks: a 64-bit division every tick would be an eighth
        // of what logging cost the run loop (perf, the 40 s lift).
        if (--until_flush == 0 ||
            (n % kWallCheckTicks == 0 && seconds_since(last_flush) >= kFlushWall)) {
          // The flush kFlushesInFlight before this one must be on disk first (kFlushSimulated).
          writer_holder->wait(flush_tickets[oldest]);
          flush_tickets[oldest] = writer_holder->flush();
          oldest = (oldest + 1) % flush_tickets.size();
          last_flush = Clock::now();
          until_flush = flush_ticks - (n + 1) % flush_ticks;   // rare: keep the simulated phase
        }
      }
      ++result.servo_ticks;
      if (record.diverged_body >= 0) {
        const BodyState& bs = sim.state().bodies[record.diverged_body];
        std::ostringstream msg;
        msg << "objects[" << record.diverged_body + 1 << "] '" << model.bodies[record.diverged_body].name
            << "' diverged at t = " << t << " s (tick " << n << "): speed "
            << bs.velocity.norm() << " m/s, spin " << bs.angular_velocity.norm()
            << " rad/s (limits " << kDivergedSpeed << " m/s, " << kDivergedAngularSpeed
            << " rad/s); the explicit integration is unstable for these stiffnesses, dampings and "
               "masses at rates.physics = " << model.rates.physics << " Hz";
        throw std::runtime_error(msg.str());
      }
      if (record.physics_ran) {
        stability.after_physics(sim.state(), n, t);   // throws to refuse
        if (const std::optional<EnergyGain> gain = energy.after_physics(sim.state(), t)) {
          throw std::runtime_error(energy_gain_message(model, *gain, t, n));
        }
      }
      if (record.haptic_ran) {
        ++result.haptic_ticks;
        for (std::size_t f = 0; f < slip.size(); ++f) slip[f] += record.haptic[f].slip;
      }
      result.physics_ticks += record.physics_ran;
      if (view && record.physics_ran && !paced) {
        scripting::fill_snapshot(sim, record, slip, view_state);
        scenario.update_view(view_state);
      }
      if (script_feeds) {
        // Paced: the view goes to the script thread (a copy into a preallocated slot), then the
        // tick is done: the script thread may compute the sample that needed it.
        if (view && record.physics_ran) {
          if (scripting::Snapshot* v = script->view_slot()) {
            scripting::fill_snapshot(sim, record, slip, *v);
            script->commit_view(n);
          }
        }
        script->tick_done(n);
      }
      // Paced (a hand on a device): Ctrl-C is seen at the next tick, not up to a second later.
      if (options.pacer && options.interrupt && options.interrupt->load()) {
        result.interrupted = true;
        throw std::runtime_error(interrupted_at(sim.time()));
      }
      // Wall-clock checks only every 3000 ticks: they are the only clock reads in the loop.
      if (n % 3000 == 2999) {
        if (options.interrupt && options.interrupt->load()) {
          result.interrupted = true;
          throw std::runtime_error(interrupted_at(sim.time()));
        }
        // The first progress line after 2 s: a quick run prints none.
        if (options.progress && !options.pacer && seconds_since(start) > 2.0 && seconds_since(last_progress) > 0.25) {
          last_progress = Clock::now();
          options.progress(sim.time(), scenario.duration());
        }
      }
    }
    if (run_ticks == 0) {
      if (paced) scripting::fill_snapshot(sim, record, slip, initial);
      else initial = snapshot(sim, record, slip);
    }
    check_due(run_ticks);
  } catch (const std::bad_alloc&) {
    // The estimate before the run (run_budget.hpp) leaves room; this is the machine running out
    // anyway (another process took it), said as such rather than as a bare "std::bad_alloc".
    result.error = "out of memory after " + std::to_string(result.servo_ticks) +
                   " servo ticks: the machine could not give the run the memory it asked for";
  } catch (const std::exception& e) {
    result.error = e.what();
  }
  if (sim_holder) result.simulated = sim_holder->time();
  result.warnings = stability.lines();
  release_all();   // at the end, on error, on interrupt: no device keeps a force
  if (result.error.empty() && !release_error.empty()) result.error = release_error;
  if (realtime) leave_realtime();
  if (options.pacer) {
    result.pacing = options.pacer->summary();
    result.overruns = options.pacer->overruns();
  }
  if (paced) {
    // The loop is over and this thread ordinary again: Lua may run here once the script thread
    // has stopped. The expectations that fell due are checked now, in due order, from the
    // snapshots the loop copied; a script error stops them as it stops an unpaced run.
    if (script) script->stop();
    scenario.forbid_lua_on(std::thread::id{});
    if (script && script->has_feeds()) {
      result.script_holds = script->holds();
      result.pacing += "; " + script->summary();
      writer.set_attribute("script_thread", script->summary());
    }
    try {
      for (std::size_t k = 0; k < next_due; ++k) {
        const std::size_t i = due[k].second;
        result.expectations[i] = scenario.check(i, due_snapshots[k], initial);
      }
    } catch (const std::exception& e) {
      if (result.error.empty()) result.error = e.what();
    }
  }
  result.wall = seconds_since(start);

  std::ostringstream summary;
  for (const auto& e : result.expectations) {
    summary << (e.passed ? "PASS " : "FAIL ") << e.what << (e.detail.empty() ? "" : ": " + e.detail) << "\n";
  }
  try {
    writer.set_attribute("expectations", summary.str());
    writer.set_attribute("warnings", stability.text());
    if (writer_holder) writer_holder->close(result.error.empty() ? "complete" : "error: " + result.error);
  } catch (const std::exception& e) {
    result.trace_error = e.what();
    if (result.error.empty()) result.error = std::string("writing the trace: ") + e.what();
  }
  if (!started) {
    // A device could not be built: the run never began, and nothing of it is kept.
    result.not_started = true;
    result.trace_error.clear();
    result.trace_path.clear();
    if (claim) claim->abandon();
  } else if (claim && writer_holder && writer_holder->marked()) {
    // Complete, or marked with its error: it may now take the output path.
    try {
      claim->commit();
    } catch (const OutputError& e) {
      result.trace_error = e.what();
      result.trace_path = claim->partial();
    }
  } else if (claim) {
    // Not even its status could be written: it stays under its partial name, like a cut trace.
    result.trace_path = claim->partial();
  }
  return result;
}

}  // namespace graspsim::app
