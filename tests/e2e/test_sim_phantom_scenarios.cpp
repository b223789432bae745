// Library scenarios with every finger on the simulated Phantom: the ones
// a Phantom can physically perform meet their expectations; one it cannot fails for the stated
// reason, the device's continuous (thermal) force limit. hw/README.md, "Simulated Phantom", has
// the whole table and the reason for every scenario left out.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "app/devices.hpp"
#include "app/run.hpp"
#include "graspsim/hw/mapped_device.hpp"
#include "graspsim/hw/sim_phantom.hpp"
#include "graspsim/scripting/scenario.hpp"

using namespace graspsim;

namespace {

const std::string kSource = GRASPSIM_SOURCE_DIR;
const std::string kTmp = GRASPSIM_TEST_TMP;

// What each simulated Phantom saw over a run, gathered by a pass-through device (the run loop
// owns and destroys the devices).
struct Watch {
  double peak_request = 0.0;       // N: largest force the run asked of the device
  double cut = 0.0;                // N: largest (request - the device's force limit) after the ramp
  double cut_time = -1.0;          // s: first time the limit cut a request by more than 0.1 N, after the ramp
  double thermal_at_cut = 0.0;     // N: the thermal limit then
  double thermal_end = 0.0;        // N: the thermal limit at the last render
  double stop_time = -1.0;         // s: first time the tip sat on a workspace face
};

class Watched final : public hw::Device {
 public:
  Watched(std::unique_ptr<hw::Device> inner, Watch* watch) : inner_(std::move(inner)), watch_(watch) {
    sim_ = dynamic_cast<hw::SimPhantom*>(inner_.get());
    if (auto* mapped = dynamic_cast<hw::MappedDevice*>(inner_.get()))
      sim_ = dynamic_cast<hw::SimPhantom*>(&mapped->inner());
  }
  hw::DeviceSample read(std::int64_t tick, double time) override {
    time_ = time;
    return inner_->read(tick, time);
  }
  hw::DeviceLimits limits() const override { return inner_->limits(); }
  std::string describe() const override { return inner_->describe(); }

 protected:
  void output(const hw::Vec3& force) override {
    inner_->render(force);
    if (sim_ == nullptr) return;
    const hw::ForceSafety& s = sim_->safety();
    const double asked = force.norm(), limit = s.limit(time_);
    const double p = s.config().peak_force, c = s.config().continuous_force;
    const double thermal = std::sqrt(std::max(0.0, p * p - (p * p - c * c) * s.heat() / (c * c)));
    watch_->thermal_end = thermal;
    const hw::Vec3& x = sim_->tip_position();
    if (watch_->stop_time < 0.0 &&
        ((x.array() == sim_->workspace_min().array()).any() || (x.array() == sim_->workspace_max().array()).any()))
      watch_->stop_time = time_;
    watch_->peak_request = std::max(watch_->peak_request, asked);
    if (time_ > s.config().rise_time) {
      watch_->cut = std::max(watch_->cut, asked - limit);
      if (asked - limit > 0.1 && watch_->cut_time < 0.0) {
        watch_->cut_time = time_;
        watch_->thermal_at_cut = thermal;
      }
    }
  }

 private:
  std::unique_ptr<hw::Device> inner_;
  hw::SimPhantom* sim_ = nullptr;
  Watch* watch_;
  double time_ = 0.0;
};

struct Outcome {
  app::RunResult result;
  std::vector<Watch> watch;   // per finger
};

// `test`: the calling test's own name for its traces, so that tests ctest runs in parallel never
// write the same file (two writing sim_phantom_two_finger_lift.h5 at once fail).
Outcome run_on_sim_phantom(const std::string& scenario_name, const std::string& spec, const std::string& test) {
  const auto scenario = scripting::Scenario::load(kSource + "/scenarios/" + scenario_name + ".lua");
  const app::DeviceRegistry registry = app::default_registry();
  std::vector<std::string> options;
  for (const auto& f : scenario.model().fingers) options.push_back(f.name + "=" + spec);
  const app::DevicePlan plan = app::plan_devices(scenario, options, registry);
  Outcome out;
  out.watch.resize(scenario.model().fingers.size());
  app::RunOptions o;
  std::string device = spec;
  std::replace(device.begin(), device.end(), ':', '_');
  o.out = kTmp + "/sim_phantom_" + test + "_" + scenario_name + "_" + device + ".h5";
  o.devices.make = [&](std::size_t f) -> std::unique_ptr<hw::Device> {
    return std::make_unique<Watched>(app::make_device(plan, registry, scenario, f), &out.watch[f]);
  };
  out.result = app::run_scenario(scenario, o);
  return out;
}

}  // namespace

// Every library scenario with fingers that meets its expectations with every finger on the
// default sim-phantom (Phantom Premium 1.5, hand with its correction): hw/README.md "Simulated
// Phantom" has the table and why each other one does not. All of them: about 1 s of CPU.
TEST_CASE("Library scenarios a Phantom can perform meet their expectations with every finger on sim-phantom",
          "[e2e][devices][sim_phantom]") {
  for (const char* name : {"gimbal_twist", "handle_lift", "heavy_hold", "mesh_grasp", "pole_balance",
                           "push_along_floor", "stack_lift", "stack_mass_ratio", "two_finger_lift"}) {
    const Outcome o = run_on_sim_phantom(name, "sim-phantom", "library");
    INFO(name << " with every finger on sim-phantom: " << o.result.error);
    for (const auto& e : o.result.expectations) {
      INFO((e.passed ? "PASS " : "FAIL ") << e.what << ": " << e.detail);
      CHECK(e.passed);
    }
    CHECK(o.result.error.empty());
    CHECK(o.result.passed());
  }
}

// The grip the engine computes is the coupling spring's, k (god-object - HIP); the hand's
// correction brings the HIP to the scripted point, so the box is gripped as in the scripted run
// even when the device cannot push back as hard: then the user feels less than the box does.
// The two-finger lift squeezes 4 to 5.8 N per finger, above the Premium 1.5's continuous 1.4 N.
// Thermal law (force_safety.hpp): L^2 = P^2 - (P^2 - C^2) H / C^2 with H relaxing to |F|^2 at
// tau = 10 s; at F = 4 N held from cold, L falls under F when H = C^2 (P^2 - F^2) / (P^2 - C^2)
// = 1.57 N^2, i.e. after -tau ln(1 - 1.57 / 16) = 1.03 s of grip: the grip starts about 0.8 s,
// so the cut comes between 1.5 and 2.5 s; by the end (4 s) L has fallen toward C (under 3 N).
// So the scenario passes, but it is not faithful haptically: checked here as "the continuous
// limit cut the force the user feels" (the stated reason for the Premium 1.5 column).
TEST_CASE("sim-phantom: the two-finger lift passes but the Premium 1.5's continuous limit cuts what the hand feels",
          "[e2e][devices][sim_phantom]") {
  const Outcome o = run_on_sim_phantom("two_finger_lift", "sim-phantom", "limit");
  CHECK(o.result.passed());
  for (const Watch& w : o.watch) {
    INFO("peak request " << w.peak_request << " N, first cut at " << w.cut_time << " s (thermal limit "
                         << w.thermal_at_cut << " N), largest cut " << w.cut << " N, thermal limit at the end "
                         << w.thermal_end << " N");
    CHECK(w.peak_request > 4.0);
    CHECK(w.cut_time > 1.5);
    CHECK(w.cut_time < 2.5);
    CHECK(w.thermal_at_cut < w.peak_request);
    CHECK(w.thermal_end < 3.0);
    CHECK(w.cut > 1.0);
  }
  // On the High Force model (C = 6.2 N) the same grip is never cut after the ramp.
  const Outcome hf = run_on_sim_phantom("two_finger_lift", "sim-phantom:premium-1.5-hf", "limit");
  for (const Watch& w : hf.watch) {
    INFO("High Force: largest cut " << w.cut << " N");
    CHECK(w.cut <= 0.0);
  }
}

// One that cannot: lift_and_place carries the box 26 cm along x (from -0.15 to 0.11 m), but
// the Premium 1.5's workspace is 381 mm wide, centred on where the hand starts: it reaches only
// 190.5 mm to +x, to x = 0.0405 m. The stylus sits on the workspace's face from the carry on and
// the box is left there, short of the base: the carry expectation fails, with the box at
// x = -0.15 + 0.1905 m (within the fingers' hold, 1 mm).
TEST_CASE("sim-phantom: lift_and_place fails because the carry leaves the Premium 1.5's workspace",
          "[e2e][devices][sim_phantom]") {
  const Outcome o = run_on_sim_phantom("lift_and_place", "sim-phantom", "workspace");
  CHECK(o.result.error.empty());
  CHECK_FALSE(o.result.passed());
  bool carry_failed = false;
  for (const auto& e : o.result.expectations) {
    INFO((e.passed ? "PASS " : "FAIL ") << e.what << ": " << e.detail);
    if (e.what.find("carried over the base") != std::string::npos) {
      carry_failed = !e.passed;
      CHECK_THAT(e.detail, Catch::Contains("x 0.040"));
    }
    if (e.what.find("grip the box before the lift") != std::string::npos) CHECK(e.passed);
  }
  CHECK(carry_failed);
  for (const Watch& w : o.watch) {
    INFO("the tip first sat on a workspace face at " << w.stop_time << " s");
    CHECK(w.stop_time > 2.0);   // during the carry (2.0 to 3.3 s), not before
    CHECK(w.stop_time < 3.3);
  }
}
