// Replaying a trace: read its scenario and device samples, check them, and hand the run loop a
// ReplayDevice per finger.
#include "app/replay.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "graspsim/hw/replay_device.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_recorder.hpp"

namespace graspsim::app {
namespace {

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

// An (n, 3) float64 dataset as n vectors.
std::vector<hw::Vec3> read_vec3(const std::string& trace, const std::string& path) {
  const recordings::Dataset d = recordings::read_dataset(trace, path);
  if (d.shape.size() != 2 || d.shape[1] != 3 || d.dtype != recordings::DType::kFloat64) {
    throw ReplayError(trace + ": " + path + ": expected an (n, 3) float64 dataset");
  }
  std::vector<hw::Vec3> rows(d.shape[0]);
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i] = {d.values[3 * i], d.values[3 * i + 1], d.values[3 * i + 2]};
  return rows;
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
  std::error_code ec;
  if (!fs::is_regular_file(trace, ec)) throw ReplayError(trace + ": no such file");
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
  plan.status = required_string(trace, "status");
  plan.scenario_path = required_string(trace, "scenario_path");
  plan.scenario_source_hash = required_string(trace, "scenario_source_hash");
  const std::string source = required_string(trace, "scenario_source");
  plan.overrides = split_lines(required_string(trace, "overrides"));
  plan.overrides.insert(plan.overrides.end(), options.sets.begin(), options.sets.end());
  plan.what_if = !options.sets.empty();

  // The scenario, from the trace's own text: messages name the recorded path; relative mesh
  // files are read from the recorded path's directory (or --scenario-dir).
  scripting::LoadOptions load;
  load.sets = plan.overrides;
  load.base_directory = options.scenario_dir;
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

  // The device inputs, one row per servo tick from 0.
  const recordings::Dataset ticks = recordings::read_dataset(trace, "/servo/tick");
  std::int64_t rows = static_cast<std::int64_t>(ticks.values.size());
  for (std::size_t f = 0; f < model.fingers.size(); ++f) {
    const std::string& name = model.fingers[f].name;
    const std::string p = "/servo/fingers/" + name + "/";
    if (!recordings::has_object(trace, p + "hip") || !recordings::has_object(trace, p + "gimbal")) {
      throw ReplayError(trace + ": the scenario's finger '" + name + "' has no recorded inputs (" + p +
                        "hip and gimbal); fingers in the trace: " + recorded_fingers(trace));
    }
    RecordedFinger r{read_vec3(trace, p + "hip"), read_vec3(trace, p + "gimbal")};
    rows = std::min({rows, static_cast<std::int64_t>(r.hip.size()), static_cast<std::int64_t>(r.gimbal.size())});
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

std::string ReplayPlan::replay_of() const { return trace + "\n" + scenario_source_hash; }

RunOptions ReplayPlan::run_options(const std::string& out) const {
  RunOptions options;
  options.out = out;
  options.overrides = overrides;
  options.max_ticks = recorded_ticks;
  options.attributes.emplace_back("replay_of", replay_of());
  options.make_device = [this](std::size_t f) -> std::unique_ptr<hw::Device> {
    return std::make_unique<hw::ReplayDevice>(fingers[f].hip, fingers[f].gimbal, scenario->fingers()[f].limits,
                                              trace + " /servo/fingers/" + scenario->model().fingers[f].name,
                                              scenario->make_trajectory(f));
  };
  return options;
}

ReplayPlan load_replay(const std::string& trace, const ReplayOptions& options) {
  try {
    return load(trace, options);
  } catch (const recordings::TraceError& e) {
    throw ReplayError(e.what());   // already names the file and the dataset
  }
}

}  // namespace graspsim::app
