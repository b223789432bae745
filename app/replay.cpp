// Replaying a trace: read its scenario and device samples, check them, and hand the run loop a
// ReplayDevice per finger.
#include "app/replay.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "graspsim/hw/replay_device.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_recorder.hpp"

namespace graspsim::app {
namespace {

// "no such file" or, for a path that is there but is no regular file (a FIFO, a device such as
// /dev/zero, a directory), what it is: the reader refuses those before HDF5 reads a byte.
void require_regular_file(const std::string& trace) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(trace, ec);
  if (ec || !fs::exists(status)) throw ReplayError(trace + ": no such file");
  if (!fs::is_regular_file(status)) throw ReplayError(trace + ": not a regular file (a trace is a file)");
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  return lines;
}

// The finger names the trace recorded, from its `devices` attribute ("name: device ..." lines).
std::string recorded_fingers(const std::string& trace) {
  if (!recordings::has_attribute(trace, "/", "devices")) return "?";
  std::string names;
  for (const std::string& line : split_lines(recordings::read_string_attribute(trace, "/", "devices"))) {
    names += (names.empty() ? "" : ", ") + line.substr(0, line.find(':'));
  }
  return names.empty() ? "none" : names;
}

// An (n, 3) float64 column `path` as n vectors.
std::vector<hw::Vec3> vec3_rows(const recordings::Dataset& d, const std::string& trace, const std::string& path) {
  if (d.shape.size() != 2 || d.shape[1] != 3 || d.dtype != recordings::DType::kFloat64) {
    throw ReplayError(trace + ": " + path + ": expected an (n, 3) float64 dataset");
  }
  std::vector<hw::Vec3> rows(d.shape[0]);
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i] = {d.values[3 * i], d.values[3 * i + 1], d.values[3 * i + 2]};
  return rows;
}

// A device's recorded samples, row n at servo tick n, in its own frame, with their own clock
// and the recorded pacing (so the run loop rewrites the same /devices row). The finger's script
// still runs alongside, as for ReplayDevice.
class DeviceRowsReplay final : public hw::Device {
 public:
  DeviceRowsReplay(const RecordedDeviceRows& rows, hw::DeviceLimits limits, std::string source,
                   std::unique_ptr<hw::Trajectory> script)
      : rows_(rows), limits_(limits), source_(std::move(source)), script_(std::move(script)) {}
  hw::DeviceSample read(std::int64_t tick, double time) override {
    if (tick < 0 || tick >= static_cast<std::int64_t>(rows_.position.size()))
      throw std::out_of_range("replay of " + source_ + ": no recorded sample for servo tick " + std::to_string(tick));
    if (script_) script_->sample(time);
    const auto n = static_cast<std::size_t>(tick);
    hw::DeviceSample s;
    s.position = rows_.position[n];
    s.gimbal = rows_.gimbal[n];
    s.buttons = rows_.buttons[n];
    time_ = rows_.device_time[n];
    row_ = n;
    overrun_ = rows_.overrun[n];
    return s;
  }
  hw::DeviceLimits limits() const override { return limits_; }
  std::string describe() const override { return "replay of " + source_; }
  bool has_sample_clock() const override { return true; }
  double sample_time() const override { return time_; }
  std::int64_t sample_sequence() const override { return rows_.sequence[row_]; }
  std::int64_t new_samples() const override { return rows_.new_samples[row_]; }
  bool has_recorded_pacing() const override { return true; }
  bool recorded_overrun() const override { return overrun_; }

 protected:
  void output(const hw::Vec3&) override {}

 private:
  const RecordedDeviceRows& rows_;
  hw::DeviceLimits limits_;
  std::string source_;
  std::unique_ptr<hw::Trajectory> script_;
  double time_ = 0.0;
  std::size_t row_ = 0;   // the last row read
  bool overrun_ = false;
};

// The `mapping` attribute device_tables.cpp writes: "identity ..." or "scale S; offset X Y Z m; rotation R P Y rad"
// with every number at 17 significant digits, so it parses back to the same doubles.
bool parse_mapping(const std::string& text, hw::WorkspaceMapping& m) {
  if (text.rfind("identity", 0) == 0) return false;
  double v[7];
  if (std::sscanf(text.c_str(), "scale %lf; offset %lf %lf %lf m; rotation %lf %lf %lf rad", &v[0], &v[1], &v[2], &v[3],
                  &v[4], &v[5], &v[6]) != 7)
    throw ReplayError("mapping attribute '" + text + "' cannot be read");
  m.scale = v[0];
  m.offset = {v[1], v[2], v[3]};
  m.rotation = {v[4], v[5], v[6]};
  return true;
}

RecordedDeviceRows read_device_rows(const std::string& trace, const std::string& table) {
  RecordedDeviceRows r;
  // The device's sample numbering, where the trace has the columns (-1 where it predates them).
  r.counted = recordings::has_object(trace, table + "/sequence") && recordings::has_object(trace, table + "/new_samples");
  std::vector<std::string> names = {"position", "gimbal", "buttons", "device_time", "overrun", "tick"};
  if (r.counted) names.insert(names.end(), {"sequence", "new_samples"});
  const recordings::Table rows = recordings::read_table(trace, table, names);
  r.position = vec3_rows(rows.column("position"), trace, table + "/position");
  r.gimbal = vec3_rows(rows.column("gimbal"), trace, table + "/gimbal");
  const recordings::Dataset& buttons = rows.column("buttons");
  const recordings::Dataset& time = rows.column("device_time");
  const recordings::Dataset& overrun = rows.column("overrun");
  const recordings::Dataset& ticks = rows.column("tick");
  const std::size_t n = r.position.size();
  if (r.gimbal.size() != n || buttons.values.size() != n || time.values.size() != n || overrun.values.size() != n ||
      ticks.values.size() != n)
    throw ReplayError(trace + ": " + table + ": columns of different lengths");
  for (std::size_t i = 0; i < n; ++i) {
    if (ticks.values[i] != static_cast<double>(i))
      throw ReplayError(trace + ": " + table + "/tick: row " + std::to_string(i) + " is not tick " + std::to_string(i));
    r.buttons.push_back(static_cast<std::uint32_t>(buttons.values[i]));
    r.overrun.push_back(overrun.values[i] != 0.0);
  }
  r.device_time = time.values;
  for (auto [column, out] : {std::pair{"sequence", &r.sequence}, std::pair{"new_samples", &r.new_samples}}) {
    if (!r.counted) {
      out->assign(n, -1);
      continue;
    }
    const recordings::Dataset& d = rows.column(column);
    if (d.values.size() != n) throw ReplayError(trace + ": " + table + ": columns of different lengths");
    for (double v : d.values) out->push_back(static_cast<std::int64_t>(v));
  }
  r.mapped = parse_mapping(recordings::read_string_attribute(trace, table, "mapping"), r.mapping);
  r.limits.max_force = std::strtod(recordings::read_string_attribute(trace, table, "max_force").c_str(), nullptr);
  return r;
}

// What the trace holds (root `record`, `graspsim run --record`): a replay feeds every finger
// from /servo at every servo tick, and a recorded device from /devices at every servo tick.
// `what`: how the trace is used, for the message.
recordings::RecordSelection replayable_selection(const std::string& trace, const std::string& what) {
  using recordings::RecordedLoop;
  recordings::RecordSelection held;
  if (recordings::has_attribute(trace, "/", "record")) {
    const std::string text = recordings::read_string_attribute(trace, "/", "record");
    try {
      held = recordings::RecordSelection::parse(text);
    } catch (const std::invalid_argument& e) {
      throw ReplayError(trace + ": root attribute 'record' ('" + text + "') cannot be read: it " + e.what());
    }
  }
  const std::string recorded = trace + ": recorded with --record " + held.text() + ", ";
  const std::string need = ": " + what + " needs every servo tick of /servo (and of /devices, where a device was "
                           "recorded); run the scenario again without --record, or with servo (and devices) at "
                           "EVERY 1";
  if (!held.records(RecordedLoop::kServo)) throw ReplayError(recorded + "which holds no /servo" + need);
  if (held.of(RecordedLoop::kServo) > 1)
    throw ReplayError(recorded + "which keeps /servo only every " + std::to_string(held.of(RecordedLoop::kServo)) +
                      "th tick" + need);
  if (held.of(RecordedLoop::kDevices) > 1)
    throw ReplayError(recorded + "which keeps /devices only every " + std::to_string(held.of(RecordedLoop::kDevices)) +
                      "th tick" + need);
  return held;
}

std::string required_string(const std::string& trace, const std::string& name) {
  if (!recordings::has_attribute(trace, "/", name)) {
    throw ReplayError(trace + ": root attribute '" + name + "' is missing: the trace cannot be replayed");
  }
  return recordings::read_string_attribute(trace, "/", name);
}

ReplayPlan load(const std::string& trace, const ReplayOptions& options) {
  namespace fs = std::filesystem;
  ReplayPlan plan;
  plan.trace = trace;
  require_regular_file(trace);
  if (!recordings::has_attribute(trace, "/", "schema_version")) {
    throw ReplayError(trace + ": not a graspsim trace (no root attribute 'schema_version')");
  }
  const std::int64_t schema = recordings::read_int_attribute(trace, "/", "schema_version");
  if (schema < 2) {
    throw ReplayError(trace + ": schema_version " + std::to_string(schema) +
                      " records no device inputs (/servo/fingers/<finger>/gimbal, /physics/state_hash "
                      "came with schema 2): it cannot be replayed; run its scenario again to record them");
  }
  if (schema > recordings::kSchemaVersion) {
    throw ReplayError(trace + ": schema_version " + std::to_string(schema) +
                      " is newer than this graspsim reads (" +
                      std::to_string(recordings::kSchemaVersion) + ")");
  }
  plan.record = replayable_selection(trace, "a replay");
  plan.status = required_string(trace, "status");
  // A trace whose run scaled its rendered forces by a start ramp of its own (root `force_ramp`
  // > 0, s): the one force ramp is a device's force safety, which a run does not record, so the
  // replay renders the demand clamped, and its /servo force differs from the recording's for
  // the first force_ramp seconds. The engine never saw that ramp.
  if (recordings::has_attribute(trace, "/", "force_ramp")) {
    const double ramp = recordings::read_double_attribute(trace, "/", "force_ramp");
    if (ramp > 0.0)
      plan.notes.push_back("the recording scaled rendered forces by a start ramp of " + std::to_string(ramp) +
                           " s outside force safety, which this replay does not: /servo force differs until then "
                           "(the engine is unchanged)");
  }
  plan.scenario_path = required_string(trace, "scenario_path");
  plan.scenario_source_hash = required_string(trace, "scenario_source_hash");
  const std::string source = required_string(trace, "scenario_source");
  plan.overrides = split_lines(required_string(trace, "overrides"));
  // A trace without `integrator` used the paper's step (every run that could use another
  // records it): it replays with it (first, so that a --set integrator= still wins).
  if (!recordings::has_attribute(trace, "/", "integrator")) plan.overrides.insert(plan.overrides.begin(), "integrator=paper");
  plan.overrides.insert(plan.overrides.end(), options.sets.begin(), options.sets.end());
  plan.what_if = !options.sets.empty();

  // The scenario, from the trace's own text: messages name the recorded path; relative mesh
  // files are read from the recorded path's directory (or --scenario-dir).
  scripting::LoadOptions load;
  load.sets = plan.overrides;
  load.base_directory = options.scenario_dir;
  // A jittered run (README.md "Perturbed waypoints"): the same offsets again, so that the
  // scripts that run alongside the recorded samples, and the new trace's attributes, are the run's.
  if (recordings::has_attribute(trace, "/", "jitter_amplitude")) {
    load.jitter.amplitude = recordings::read_double_attribute(trace, "/", "jitter_amplitude");
    load.jitter.seed = static_cast<std::uint64_t>(recordings::read_int_attribute(trace, "/", "jitter_seed"));
  }
  const std::string base = !options.scenario_dir.empty() ? options.scenario_dir
                         : fs::path(plan.scenario_path).parent_path().string();
  try {
    plan.scenario = std::make_unique<scripting::Scenario>(
        scripting::Scenario::load_source(source, plan.scenario_path, load));
  } catch (const scripting::ScenarioError& e) {
    std::string message = trace + ": the recorded scenario (scenario_source of " + plan.scenario_path +
                          ", with overrides) does not load: " + e.what();
    if (std::string(e.what()).find("mesh file") != std::string::npos) {
      message += "\n  (the scenario's relative file names are read from '" + (base.empty() ? "." : base) +
                 "'" + (options.scenario_dir.empty() ? ", the recorded scenario_path's directory" : "") +
                 "; --scenario-dir DIR reads them from DIR)";
    }
    throw ReplayError(message);
  }
  const Model& model = plan.scenario->model();
  if (!plan.what_if && recordings::has_attribute(trace, "/", "jitter_offsets")) {
    std::string offsets;
    for (const std::string& line : plan.scenario->jitter_lines()) offsets += line + "\n";
    if (offsets != recordings::read_string_attribute(trace, "/", "jitter_offsets")) {
      plan.notes.push_back("the jitter offsets drawn again from jitter_seed differ from the recorded "
                           "jitter_offsets (another generator?); the fingers follow their recorded "
                           "samples, so only the scripts that run alongside see other waypoints");
    }
  }

  // The recorded samples are at the recorded rates: a replay at other rates is not this motion.
  const std::pair<const char*, int> rates[] = {
      {"rate_servo", model.rates.servo}, {"rate_haptic", model.rates.haptic}, {"rate_physics", model.rates.physics}};
  for (const auto& [name, rate] : rates) {
    const std::int64_t recorded = recordings::read_int_attribute(trace, "/", name);
    if (recorded != rate) {
      throw ReplayError(trace + ": the replay would run at " + name + " = " + std::to_string(rate) +
                        " Hz, but the trace was recorded at " + std::to_string(recorded) +
                        " Hz: the recorded device samples are one per servo tick at the recorded rates "
                        "(rates cannot be changed by --set on replay)");
    }
  }

  // The device inputs, one row per servo tick from 0: every finger's, in one pass over /servo.
  const std::vector<std::string> columns = recordings::list_datasets(trace);
  std::vector<std::string> inputs = {"tick"};
  for (const FingerParams& finger : model.fingers) {
    const std::string p = "fingers/" + finger.name + "/";
    for (const char* column : {"hip", "gimbal"}) {
      if (!std::binary_search(columns.begin(), columns.end(), "/servo/" + p + column))
        throw ReplayError(trace + ": the scenario's finger '" + finger.name + "' has no recorded inputs (/servo/" + p +
                          "hip and gimbal); fingers in the trace: " + recorded_fingers(trace));
      inputs.push_back(p + column);
    }
  }
  const recordings::Table servo = recordings::read_table(trace, "/servo", inputs);
  const recordings::Dataset& ticks = servo.column("tick");
  std::int64_t rows = static_cast<std::int64_t>(ticks.values.size());
  for (std::size_t f = 0; f < model.fingers.size(); ++f) {
    const std::string& name = model.fingers[f].name;
    const std::string p = "fingers/" + name + "/";
    RecordedFinger r{vec3_rows(servo.column(p + "hip"), trace, "/servo/" + p + "hip"),
                     vec3_rows(servo.column(p + "gimbal"), trace, "/servo/" + p + "gimbal"), std::nullopt};
    rows = std::min({rows, static_cast<std::int64_t>(r.hip.size()), static_cast<std::int64_t>(r.gimbal.size())});
    if (recordings::has_object(trace, "/devices/" + name)) {
      r.device = read_device_rows(trace, "/devices/" + name);
      rows = std::min(rows, static_cast<std::int64_t>(r.device->position.size()));
    }
    plan.fingers.push_back(std::move(r));
  }
  for (std::int64_t n = 0; n < rows; ++n) {
    if (ticks.values[static_cast<std::size_t>(n)] != static_cast<double>(n)) {
      throw ReplayError(trace + ": /servo/tick: row " + std::to_string(n) + " holds tick " +
                        std::to_string(static_cast<std::int64_t>(ticks.values[static_cast<std::size_t>(n)])) +
                        ": a replay needs every servo tick from 0 (is this a decimated trace?)");
    }
  }
  for (RecordedFinger& r : plan.fingers) {
    r.hip.resize(static_cast<std::size_t>(rows));
    r.gimbal.resize(static_cast<std::size_t>(rows));
  }
  // A device session's mapping must still be the scenario's (the same source and overrides
  // give the same mapping; a --set of it is a what-if that moves the hand).
  for (std::size_t f = 0; f < plan.fingers.size(); ++f) {
    const auto& d = plan.fingers[f].device;
    const hw::WorkspaceMapping& m = plan.scenario->fingers()[f].mapping;
    if (d && d->mapped && !plan.what_if &&
        (d->mapping.scale != m.scale || d->mapping.offset != m.offset || d->mapping.rotation != m.rotation))
      throw ReplayError(trace + ": /devices/" + model.fingers[f].name +
                        ": the recorded workspace mapping is not the scenario's");
  }
  plan.recorded_ticks = rows;
  plan.scenario_ticks = static_cast<std::int64_t>(std::llround(plan.scenario->duration() * model.rates.servo));

  // A cut trace (status running, cut: repaired, error: ...) replays up to its last tick.
  if (plan.recorded_ticks < plan.scenario_ticks) {
    std::ostringstream note;
    note << "the trace holds " << plan.recorded_ticks << " of the scenario's " << plan.scenario_ticks
         << " servo ticks (status '" << plan.status << "'): replaying t = 0 to "
         << static_cast<double>(plan.recorded_ticks) / model.rates.servo
         << " s; expectations due later are not checked";
    plan.notes.push_back(note.str());
  }
  return plan;
}

}  // namespace

RecordedFinger read_recorded_finger(const std::string& trace, const std::string& finger, int rate_servo) {
  try {
    require_regular_file(trace);
    if (!recordings::has_attribute(trace, "/", "schema_version"))
      throw ReplayError(trace + ": not a graspsim trace (no root attribute 'schema_version')");
    const std::int64_t schema = recordings::read_int_attribute(trace, "/", "schema_version");
    if (schema < recordings::kOldestSchemaVersion || schema > recordings::kSchemaVersion)
      throw ReplayError(trace + ": schema_version " + std::to_string(schema) + " cannot be replayed (this graspsim reads " +
                        std::to_string(recordings::kOldestSchemaVersion) + " to " +
                        std::to_string(recordings::kSchemaVersion) + ")");
    replayable_selection(trace, "a finger replayed from it (--device FINGER=replay:TRACE)");
    const std::int64_t recorded_rate = recordings::read_int_attribute(trace, "/", "rate_servo");
    if (recorded_rate != rate_servo)
      throw ReplayError(trace + ": recorded at rate_servo = " + std::to_string(recorded_rate) + " Hz, but this run's servo rate is " +
                        std::to_string(rate_servo) + " Hz: the samples are one per recorded servo tick");
    const std::string p = "fingers/" + finger + "/";
    if (!recordings::has_object(trace, "/servo/" + p + "hip") || !recordings::has_object(trace, "/servo/" + p + "gimbal"))
      throw ReplayError(trace + ": no recorded inputs of finger '" + finger + "' (/servo/" + p +
                        "hip and gimbal); fingers in the trace: " + recorded_fingers(trace));
    const recordings::Table servo = recordings::read_table(trace, "/servo", {"tick", p + "hip", p + "gimbal"});
    RecordedFinger r{vec3_rows(servo.column(p + "hip"), trace, "/servo/" + p + "hip"),
                     vec3_rows(servo.column(p + "gimbal"), trace, "/servo/" + p + "gimbal"), std::nullopt};
    const recordings::Dataset& ticks = servo.column("tick");
    const std::size_t rows = std::min({ticks.values.size(), r.hip.size(), r.gimbal.size()});
    for (std::size_t n = 0; n < rows; ++n) {
      if (ticks.values[n] != static_cast<double>(n))
        throw ReplayError(trace + ": /servo/tick: row " + std::to_string(n) + " is not tick " + std::to_string(n) +
                          ": a replay needs every servo tick from 0 (is this a decimated trace?)");
    }
    r.hip.resize(rows);
    r.gimbal.resize(rows);
    return r;
  } catch (const recordings::TraceError& e) {
    throw ReplayError(e.what());
  }
}

std::string ReplayPlan::replay_of() const { return trace + "\n" + scenario_source_hash; }

RunOptions ReplayPlan::run_options(const std::string& out) const {
  RunOptions options;
  options.out = out;
  options.overrides = overrides;
  options.stop.max_ticks = recorded_ticks;
  options.trace.record = record;
  // A replay always writes its trace: it is what is compared with the recording.
  options.trace.naming.write_none = "a replay writes its trace to compare it with the recording: name a file with --out";
  options.attributes.emplace_back("replay_of", replay_of());
  options.inputs.push_back({trace, "the trace replayed"});
  for (const RecordedFinger& r : fingers) {
    options.devices.record.push_back(r.device.has_value());
    // A device table without the counter columns: the replay writes none either, so that it can
    // equal the recording (compare refuses tables whose columns differ).
    if (r.device && !r.device->counted) options.devices.counters = false;
  }
  options.devices.make = [this](std::size_t f) -> std::unique_ptr<hw::Device> {
    const std::string& name = scenario->model().fingers[f].name;
    if (const auto& d = fingers[f].device) {
      // The device's own samples through the recorded mapping: the same world hip, bit for bit.
      std::unique_ptr<hw::Device> rows = std::make_unique<DeviceRowsReplay>(
          *d, d->limits, trace + " /devices/" + name, scenario->make_trajectory(f));
      if (!d->mapped) return rows;
      return std::make_unique<hw::MappedDevice>(std::move(rows), d->mapping);
    }
    return std::make_unique<hw::ReplayDevice>(fingers[f].hip, fingers[f].gimbal, scenario->fingers()[f].limits,
                                              trace + " /servo/fingers/" + scenario->model().fingers[f].name,
                                              scenario->make_trajectory(f));
  };
  return options;
}

std::string default_replay_out(const std::string& trace) {
  return std::filesystem::path(trace).stem().string() + ".replay.h5";
}

std::int64_t ReplayOutcome::state_hashes() const {
  if (comparison)
    for (const auto& d : comparison->datasets)
      if (d.path == "physics/state_hash") return d.elements;
  return 0;
}

ReplayOutcome run_replay(const ReplayPlan& plan, const RunOptions& options) {
  ReplayOutcome outcome;
  outcome.run = run_scenario(*plan.scenario, options);
  if (outcome.run.not_started) return outcome;
  try {
    recordings::CompareOptions bitwise;
    bitwise.bitwise = true;
    outcome.comparison = recordings::compare_traces(plan.trace, outcome.run.trace_path, bitwise);
  } catch (const recordings::TraceError& e) {
    outcome.compare_error = e.what();
  }
  return outcome;
}

ReplayPlan load_replay(const std::string& trace, const ReplayOptions& options) {
  try {
    return load(trace, options);
  } catch (const recordings::TraceError& e) {
    throw ReplayError(e.what());   // already names the file and the dataset
  }
}

}  // namespace graspsim::app
