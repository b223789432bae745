// Loading a scenario: read the file, run it in the sandbox, apply --set overrides, copy the
// returned table out of Lua and convert it; then trajectories and expectations call back into it.
#include "graspsim/scripting/scenario.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <lua.hpp>

#include "jitter.hpp"
#include "lua_convert.hpp"
#include "lua_trajectory.hpp"
#include "messages.hpp"
#include "overrides.hpp"
#include "schema.hpp"

namespace graspsim::scripting {
namespace {

std::string read_file(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    throw ScenarioError("cannot open scenario '" + path + "': " + std::strerror(errno));
  }
  std::string text;
  char buffer[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, file)) > 0) text.append(buffer, n);
  const bool failed = std::ferror(file) != 0;
  const int error = errno;
  std::fclose(file);
  if (failed) throw ScenarioError("cannot read scenario '" + path + "': " + std::strerror(error));
  return text;
}

// "scenarios/two_finger_lift.lua" -> "two_finger_lift"
std::string default_name(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  if (name.size() > 4 && name.compare(name.size() - 4, 4, ".lua") == 0) name.resize(name.size() - 4);
  return name;
}

// The seed math.random gets before the file runs: --set seed=N if given, else 0.
std::int64_t initial_seed(const std::vector<detail::Override>& overrides) {
  std::int64_t seed = 0;
  for (const detail::Override& o : overrides) {
    if (o.path != "seed") continue;
    const detail::SetValue& v = o.value;
    const bool integral = v.type == detail::SetValue::Type::kInteger ||
                          (v.type == detail::SetValue::Type::kNumber && v.number < 9.2e18 &&
                           v.number == std::floor(v.number));
    if (!integral || v.number < 0.0) {
      throw detail::ConversionError("--set " + o.text + ": seed must be an integer >= 0");
    }
    seed = v.type == detail::SetValue::Type::kInteger ? v.integer : static_cast<std::int64_t>(v.number);
  }
  return seed;
}

std::string finger_label(std::size_t i, const std::string& name) {
  return "fingers[" + std::to_string(i + 1) + "] '" + name + "'";
}

// Whether the Lua function under registry reference `ref` declares a second parameter (or takes
// `...`): then it may read the view. Raw access and lua_getinfo: raises nothing.
bool takes_view(lua_State* state, int ref) {
  if (!lua_checkstack(state, 1)) return true;
  lua_rawgeti(state, LUA_REGISTRYINDEX, ref);
  lua_Debug info;
  if (lua_getinfo(state, ">u", &info) == 0) return true;   // pops the function
  return info.nparams >= 2 || info.isvararg != 0;
}

}  // namespace

Scenario::Scenario() = default;
Scenario::Scenario(Scenario&&) noexcept = default;
Scenario& Scenario::operator=(Scenario&&) noexcept = default;
Scenario::~Scenario() = default;

Scenario Scenario::load(const std::string& path, const LoadOptions& options) {
  return load_source(read_file(path), path, options);
}

Scenario Scenario::load_source(const std::string& source, const std::string& path,
                               const LoadOptions& options) {
  // Declared before the scenario: param() points at it until the Lua state is closed.
  std::vector<detail::Override> overrides;
  Scenario s;
  s.path_ = path;
  s.source_ = source;
  try {
    overrides = detail::parse_overrides(options.sets);
    s.lua_ = std::make_unique<LuaSandbox>(options.limits);
    LuaSandbox& lua = *s.lua_;
    lua_State* state = lua.state();
    lua.register_global("param", detail::param_function, &overrides);
    lua.lock_globals();
    lua.seed_random(initial_seed(overrides));

    // Run the file: it returns the scenario table, and nothing else (a second value would be
    // dropped without a word: a table meant as the scenario, or the sign of a mistake).
    const int top = lua_gettop(state);
    lua.load(s.source_, path);
    lua.call(0, LUA_MULTRET, Budget::kLoad);
    detail::set_param_overrides(lua, nullptr);
    const int root = top + 1;
    const int returned = lua_gettop(state) - top;
    if (returned > 1) {
      throw detail::ConversionError("the scenario must return one table (return { duration = ..., objects = ..., "
                                    "fingers = ... }), but it returned " + std::to_string(returned) +
                                    " values (" + luaL_typename(state, root) + ", " + luaL_typename(state, root + 1) +
                                    (returned > 2 ? ", ..." : "") + "): only one can be the scenario");
    }
    if (returned == 0) lua_pushnil(state);   // a file without a return statement returns nothing
    if (lua_type(state, root) != LUA_TTABLE) {
      throw detail::ConversionError(std::string("the scenario must return a table (return { "
                                    "duration = ..., objects = ..., fingers = ... }), but it "
                                    "returned ") + luaL_typename(state, root));
    }

    // --set overrides that param() did not take go into the table, by path.
    const detail::LuaValue params = detail::read_params(state);
    std::vector<std::string> param_names;
    for (const detail::LuaValue::Entry& entry : params.entries) param_names.push_back(entry.key.str());
    detail::LuaValue copy;
    bool copied = false;
    for (const detail::Override& o : overrides) {
      if (o.used) continue;
      if (!copied) copy = detail::read_value(state, root, nullptr);
      copied = true;
      const std::vector<detail::LuaKey> chain = detail::apply_override(copy, o, param_names);
      detail::set_path(lua, root, chain, o.value);
    }

    // Copy the final table out (functions referenced) and convert it.
    const detail::LuaValue table = detail::read_value(state, root, &lua);
    lua_settop(state, top);
    detail::ScenarioParts parts = detail::convert_scenario(
        table, default_name(path),
        options.base_directory.empty() ? std::filesystem::path(path).parent_path().string()
                                       : options.base_directory);
    s.parameters_ = detail::flatten_parameters(table, params);
    s.name_ = std::move(parts.name);
    s.description_ = std::move(parts.description);
    s.model_ = std::move(parts.model);
    s.duration_ = parts.duration;
    s.seed_ = parts.seed;
    s.refuse_unstable_ = parts.refuse_unstable;
    s.fingers_ = std::move(parts.fingers);
    s.expectations_ = std::move(parts.expectations);
    s.files_ = std::move(parts.files);
    for (detail::TrajectoryParts& t : parts.trajectories) {
      s.trajectories_.push_back(TrajectorySpec{std::move(t.waypoints), t.interpolation, t.function_ref});
      if (t.function_ref != 0) s.uses_view_ = s.uses_view_ || takes_view(state, t.function_ref);
    }
    s.apply_jitter(options.jitter);
    // Trajectory and expectation functions draw from the scenario's own seed.
    lua.seed_random(static_cast<std::int64_t>(s.seed_));
  } catch (const detail::ConversionError& e) {
    throw ScenarioError(path + ": " + e.what());
  } catch (const ScenarioError& e) {
    throw ScenarioError(detail::with_context(e.what(), path, ""));
  }
  return s;
}

void Scenario::apply_jitter(const Jitter& jitter) {
  if (!(jitter.amplitude >= 0.0) || !std::isfinite(jitter.amplitude)) {
    throw detail::ConversionError("--jitter " + detail::format_short(jitter.amplitude) +
                                  ": the amplitude must be a finite length >= 0 m");
  }
  jitter_ = jitter;
  if (jitter.amplitude == 0.0) return;
  for (std::size_t f = 0; f < trajectories_.size(); ++f) {
    TrajectorySpec& spec = trajectories_[f];
    const bool function = spec.function_ref != 0;
    std::vector<Vec3> offsets = detail::jitter_offsets(jitter, f, function ? 1 : spec.waypoints.size());
    if (function) {
      spec.offset_function = true;
      spec.offset = offsets[0];
    } else {
      for (std::size_t k = 0; k < offsets.size(); ++k) spec.waypoints[k].position += offsets[k];
    }
    jitter_offsets_.push_back(std::move(offsets));
  }
}

std::vector<std::string> Scenario::jitter_lines() const {
  std::vector<std::string> lines;
  for (std::size_t f = 0; f < jitter_offsets_.size(); ++f) {
    const bool function = trajectories_[f].function_ref != 0;
    for (std::size_t k = 0; k < jitter_offsets_[f].size(); ++k) {
      const Vec3& o = jitter_offsets_[f][k];
      lines.push_back(model_.fingers[f].name + (function ? " function: " : " waypoint " + std::to_string(k + 1) + ": ") +
                      detail::format_exact(o.x()) + " " + detail::format_exact(o.y()) + " " +
                      detail::format_exact(o.z()));
    }
  }
  return lines;
}

std::unique_ptr<hw::Trajectory> Scenario::make_trajectory(std::size_t finger) const {
  if (finger >= trajectories_.size()) {
    throw std::out_of_range("make_trajectory: no finger " + std::to_string(finger) + " (the scenario has " +
                            std::to_string(trajectories_.size()) + ")");
  }
  const TrajectorySpec& spec = trajectories_[finger];
  if (spec.function_ref == 0) {
    return std::make_unique<hw::WaypointTrajectory>(spec.waypoints, spec.interpolation);
  }
  std::unique_ptr<hw::Trajectory> lua = std::make_unique<detail::LuaTrajectory>(
      *lua_, spec.function_ref, path_, finger_label(finger, model_.fingers[finger].name));
  if (wrapper_) lua = wrapper_(finger, std::move(lua));
  if (spec.offset_function) return std::make_unique<detail::OffsetTrajectory>(std::move(lua), spec.offset);
  return lua;
}

bool Scenario::has_lua_trajectories() const {
  for (const TrajectorySpec& t : trajectories_)
    if (t.function_ref != 0) return true;
  return false;
}

void Scenario::forbid_lua_on(std::thread::id id) const { lua_->forbid_thread(id); }

std::int64_t Scenario::lua_uses_on_forbidden_thread() const { return lua_->forbidden_uses(); }

void Scenario::update_view(const Snapshot& now) const {
  try {
    detail::update_view(*lua_, now);
  } catch (const ScenarioError& e) {
    throw ScenarioError(detail::with_context(e.what(), path_, "updating the simulation view"));
  }
}

ExpectationResult Scenario::check(std::size_t expectation, const Snapshot& now,
                                  const Snapshot& initial) const {
  if (expectation >= expectations_.size()) {
    throw std::out_of_range("check: no expectation " + std::to_string(expectation) + " (the scenario has " +
                            std::to_string(expectations_.size()) + ")");
  }
  lua_->enter();   // before anything touches the state (the thread guard)
  const Expectation& e = expectations_[expectation];
  const std::string label = "expect[" + std::to_string(expectation + 1) + "] '" + e.what + "'";
  lua_State* state = lua_->state();
  const int top = lua_gettop(state);
  if (!lua_checkstack(state, 4)) throw ScenarioError(path_ + ": " + label + ": Lua stack overflow");
  lua_rawgeti(state, LUA_REGISTRYINDEX, e.function_ref);
  try {
    detail::push_sim(*lua_, now, initial);
    lua_->call(1, 2, Budget::kCall);
  } catch (const ScenarioError& error) {
    lua_settop(state, top);
    throw ScenarioError(detail::with_context(error.what(), path_, label));
  }
  ExpectationResult result;
  result.what = e.what;
  std::string problem;
  const bool ok = detail::read_check(state, top + 1, result.passed, result.detail, problem);
  lua_settop(state, top);
  if (!ok) throw ScenarioError(path_ + ": " + label + ": " + problem);
  return result;
}

}  // namespace graspsim::scripting
