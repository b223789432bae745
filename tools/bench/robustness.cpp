// The robustness harness: run a perturbed scenario through the run loop, then read its trace
// back for the checks (see robustness.hpp).
#include "bench/robustness.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <stdexcept>

#include "app/devices.hpp"
#include "app/run.hpp"
#include "graspsim/recordings/trace_reader.hpp"

namespace graspsim::robustness {
namespace {

// The first non-finite value of any column of the trace: "/physics/objects/rod/velocity row 42".
std::string first_nonfinite(const std::string& trace) {
  for (const std::string& path : recordings::list_datasets(trace)) {
    const recordings::Dataset d = recordings::read_dataset(trace, path);
    const std::size_t width = d.shape.size() > 1 ? d.shape[1] : 1;
    for (std::size_t i = 0; i < d.values.size(); ++i)
      if (!std::isfinite(d.values[i])) return path + " row " + std::to_string(i / width);
  }
  return "";
}

std::vector<BodyPath> body_paths(const std::string& trace, const Model& model) {
  const std::vector<double> time = recordings::read_dataset(trace, "/physics/time").values;
  std::vector<BodyPath> out;
  for (const BodyParams& body : model.bodies) {
    BodyPath b;
    b.name = body.name;
    b.lowest = std::numeric_limits<double>::infinity();
    const std::string at = "/physics/objects/" + body.name;
    const std::vector<double> p = recordings::read_dataset(trace, at + "/position").values;
    const std::vector<double> q = recordings::read_dataset(trace, at + "/quaternion").values;
    const Quat q0 = body.orientation;
    for (std::size_t row = 0; 4 * row + 3 < q.size(); ++row) {
      // The angle of q q0^-1: 2 acos |w| of the relative quaternion (|w| because q and -q are one
      // rotation); NaN stays NaN.
      const Quat rel = Quat(q[4 * row], q[4 * row + 1], q[4 * row + 2], q[4 * row + 3]) * q0.conjugate();
      const double turn = 2.0 * std::acos(std::min(1.0, std::abs(rel.w())));
      if (!(turn <= b.max_turn)) b.max_turn = turn;
    }
    if (p.size() >= 3) b.final_position = Vec3(p[p.size() - 3], p[p.size() - 2], p[p.size() - 1]);
    // Period-2 cycles: per component, the run of consecutive rows that each reverse the
    // previous row's sign with both above the threshold.
    for (const char* quantity : {"velocity", "angular_velocity"}) {
      const bool spin = std::string(quantity) == "angular_velocity";
      const double threshold = spin ? kFlipSpin : kFlipSpeed;
      const std::vector<double> v = recordings::read_dataset(trace, at + "/" + quantity).values;
      for (int axis = 0; axis < 3; ++axis) {
        int run = 0;
        double peak = 0.0;
        for (std::size_t row = 1; 3 * row + 2 < v.size(); ++row) {
          const double before = v[3 * (row - 1) + axis], now = v[3 * row + axis];
          const bool flip = before * now < 0.0 && std::abs(before) > threshold && std::abs(now) > threshold;
          run = flip ? run + 1 : 0;
          peak = flip ? std::max(peak, std::max(std::abs(before), std::abs(now))) : 0.0;
          if (run > b.flips) {
            b.flips = run;
            b.flip_at = row < time.size() ? time[row] : 0.0;
            b.flip_peak = peak;
            b.flip_what = std::string(quantity) + " " + "xyz"[axis];
          }
        }
      }
    }
    for (std::size_t row = 0; 3 * row + 2 < p.size(); ++row) {
      const Vec3 x(p[3 * row], p[3 * row + 1], p[3 * row + 2]);
      const double excursion = (x - body.position).norm();
      const double height = model.floor.enabled ? x.z() - model.floor.height : std::numeric_limits<double>::infinity();
      // NaN compares false: a non-finite centre counts as out of the scene.
      const bool inside = excursion <= kSceneRadius && height >= -kFloorMargin;
      if (!(excursion <= b.excursion)) b.excursion = excursion;
      if (!(height >= b.lowest)) b.lowest = height;
      if (!inside && b.left_at < 0.0) b.left_at = row < time.size() ? time[row] : 0.0;
    }
    out.push_back(b);
  }
  return out;
}

// The largest number of fingers on one body at one haptic tick (/haptic/fingers/<f>/body: the
// contacted body's index, kFloor or kNoBody).
int most_fingers_on_a_body(const std::string& trace, const Model& model) {
  std::vector<std::vector<double>> bodies;
  for (const FingerParams& f : model.fingers)
    bodies.push_back(recordings::read_dataset(trace, "/haptic/fingers/" + f.name + "/body").values);
  int most = 0;
  const std::size_t rows = bodies.empty() ? 0 : bodies.front().size();
  for (std::size_t r = 0; r < rows; ++r) {
    std::map<int, int> count;
    for (const auto& column : bodies)
      if (r < column.size() && column[r] >= 0.0) most = std::max(most, ++count[static_cast<int>(column[r])]);
  }
  return most;
}

}  // namespace

std::string Perturbation::describe() const {
  std::string out;
  const auto add = [&out](const std::string& part) { out += (out.empty() ? "" : "; ") + part; };
  if (jitter > 0.0) {
    char text[80];
    std::snprintf(text, sizeof text, "jitter %g mm seed %llu", jitter * 1e3, static_cast<unsigned long long>(seed));
    add(text);
  }
  if (!sim_phantom.empty()) {
    std::string fingers;
    for (const std::string& f : sim_phantom) fingers += (fingers.empty() ? "" : ",") + f;
    add("sim-phantom on " + fingers);
  }
  for (const std::string& s : sets) add(s);
  return out.empty() ? "unperturbed" : out;
}

double Outcome::worst_excursion() const {
  double worst = 0.0;
  for (const BodyPath& b : bodies)
    if (!(b.excursion <= worst)) worst = b.excursion;
  return worst;
}

bool Outcome::left_scene() const {
  return std::any_of(bodies.begin(), bodies.end(), [](const BodyPath& b) { return b.left_at >= 0.0; });
}

std::string Outcome::left_scene_detail() const {
  std::string out;
  for (const BodyPath& b : bodies) {
    if (b.left_at < 0.0) continue;
    char text[200];
    std::snprintf(text, sizeof text, "%s left at %.3g s (up to %.3g m from its start, centre down to %.3g m above the floor)",
                  b.name.c_str(), b.left_at, b.excursion, b.lowest);
    out += (out.empty() ? "" : "; ") + std::string(text);
  }
  return out;
}

const scripting::ExpectationResult& Outcome::expectation(const std::string& what) const {
  for (const scripting::ExpectationResult& e : expectations)
    if (e.what.find(what) != std::string::npos) return e;
  throw std::out_of_range(scenario + ": no expectation contains '" + what + "'");
}

bool Outcome::period_two() const {
  return std::any_of(bodies.begin(), bodies.end(), [](const BodyPath& b) { return b.flips >= kFlipSteps; });
}

std::string Outcome::period_two_detail() const {
  std::string out;
  for (const BodyPath& b : bodies) {
    if (b.flips < kFlipSteps) continue;
    char text[200];
    std::snprintf(text, sizeof text, "%s %s reversed at %d physics steps in a row, up to %.3g, until %.3g s",
                  b.name.c_str(), b.flip_what.c_str(), b.flips, b.flip_peak, b.flip_at);
    out += (out.empty() ? "" : "; ") + std::string(text);
  }
  return out;
}

const BodyPath& Outcome::body(const std::string& name) const {
  for (const BodyPath& b : bodies)
    if (b.name == name) return b;
  throw std::out_of_range(scenario + ": no body '" + name + "'");
}

Outcome run(const std::string& scenario_path, const Perturbation& p, const std::string& trace, bool keep_trace) {
  scripting::LoadOptions load;
  load.sets = p.sets;
  load.jitter = scripting::Jitter{p.jitter, p.seed};
  const scripting::Scenario scenario = scripting::Scenario::load(scenario_path, load);
  const app::DeviceRegistry registry = app::default_registry();
  std::vector<std::string> devices;
  for (const std::string& f : p.sim_phantom) devices.push_back(f + "=sim-phantom");
  const app::DevicePlan plan = app::plan_devices(scenario, devices, registry);

  app::RunOptions options;
  options.out = trace;
  options.overrides = p.sets;
  options.devices.record = plan.recorded();
  options.devices.script_alongside = plan.script_alongside;
  options.devices.make = [&](std::size_t f) { return app::make_device(plan, registry, scenario, f); };
  const app::RunResult result = app::run_scenario(scenario, options);

  Outcome out;
  out.scenario = scenario.name();
  out.label = p.describe();
  out.expectations = result.expectations;
  out.error = result.error;
  out.nonfinite = first_nonfinite(trace);
  out.bodies = body_paths(trace, scenario.model());
  out.most_fingers_on_a_body = most_fingers_on_a_body(trace, scenario.model());
  out.jitter_offsets = scenario.jitter_offsets();
  if (!keep_trace) std::filesystem::remove(trace);
  return out;
}

std::vector<std::string> scenarios_with_fingers(const std::string& directory) {
  std::vector<std::string> out;
  for (const auto& entry : std::filesystem::directory_iterator(directory)) {
    if (entry.path().extension() != ".lua") continue;
    const scripting::Scenario s = scripting::Scenario::load(entry.path().string());
    if (!s.model().fingers.empty()) out.push_back(entry.path().stem().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace graspsim::robustness
