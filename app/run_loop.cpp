// The stages of one run (run_loop.hpp), in the order run_scenario calls them.
#include "app/run_loop.hpp"

#include <cmath>
#include <exception>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "app/run_errors.hpp"
#include "graspsim/hw/force_safety.hpp"
#include "graspsim/hw/scripted_finger.hpp"

namespace graspsim::app {
namespace {

double seconds_since(RunClock::time_point start) {
  return std::chrono::duration<double>(RunClock::now() - start).count();
}

// Wall-clock checks (interrupt and progress) every this many ticks: the only clock reads of an
// unpaced loop besides the flush's.
constexpr std::int64_t kWallCheckInterval = 3000;

}  // namespace

Run::Run(const scripting::Scenario& scenario, const RunOptions& options, const RunSeams& seams, RunTrace& trace,
         RunResult& result)
    : scenario_(scenario),
      model_(scenario.model()),
      options_(options),
      seams_(seams),
      trace_(trace),
      result_(result),
      paced_(options.pacing.pacer != nullptr),
      start_(RunClock::now()),
      last_progress_(start_),
      stability_(model_, options.report.refuse_unstable || scenario.refuse_unstable(), options.report.on_warning),
      energy_(model_),
      slip_(scenario.model().fingers.size(), 0.0) {}

void Run::check_stability_before() {
  // Written now and again at the end with the run's own, so a trace cut by a crash still has
  // the model's.
  stability_.before_run();
  trace_.set_attribute("warnings", stability_.text());
}

void Run::open_devices() {
  std::ostringstream device_list;
  {
    // Paced: every Lua trajectory a device asks for is fed by the script thread.
    struct Unwrap {
      const scripting::Scenario& s;
      ~Unwrap() { s.set_trajectory_wrapper({}); }
    } unwrap{scenario_};
    if (paced_ && scenario_.has_lua_trajectories()) {
      ScriptThreadOptions so;
      so.rate_servo = model_.rates.servo;
      so.physics_divisor = divisors(model_.rates).physics;
      so.end_tick = static_cast<std::int64_t>(std::llround(scenario_.duration() * model_.rates.servo));
      so.view = scenario_.uses_view();
      so.wait_for_samples = seams_.wait_for_script;
      script_.emplace(scenario_, so);
      scenario_.set_trajectory_wrapper(
          [this](std::size_t, std::unique_ptr<hw::Trajectory> lua) { return script_->wrap(std::move(lua)); });
    }
    for (std::size_t f = 0; f < model_.fingers.size(); ++f) {
      if (options_.devices.make) devices_.push_back(options_.devices.make(f));
      else devices_.push_back(std::make_unique<hw::ScriptedFinger>(scenario_.make_trajectory(f),
                                                                   scenario_.fingers()[f].limits));
      device_list << model_.fingers[f].name << ": " << devices_.back()->describe()
                  << " (max force " << devices_.back()->limits().max_force << " N)\n";
    }
  }
  started_ = true;
  trace_.set_attribute("devices", device_list.str());
  // Every sample is checked (finite, inside the device's workspace) before the engine sees it.
  for (std::size_t f = 0; f < devices_.size(); ++f) checks_.emplace_back(*devices_[f], model_.fingers[f].name);
  samples_.resize(devices_.size());
  // The scripts of fingers whose device does not run them (RunOptions::Devices::script_alongside).
  side_scripts_.resize(devices_.size());
  for (std::size_t f = 0; f < options_.devices.script_alongside.size() && f < devices_.size(); ++f)
    if (options_.devices.script_alongside[f]) side_scripts_[f] = scenario_.make_trajectory(f);
}

void Run::prepare() {
  if (options_.live && (options_.live->bodies() != model_.bodies.size() || options_.live->fingers() != model_.fingers.size()))
    throw std::invalid_argument("the live view's snapshots are sized for " + std::to_string(options_.live->bodies()) +
                                " bodies and " + std::to_string(options_.live->fingers()) + " fingers; the scenario has " +
                                std::to_string(model_.bodies.size()) + " and " + std::to_string(model_.fingers.size()));
  Simulation& sim = sim_.emplace(model_);
  stability_.use_contacts(sim.contacts());   // one contact gather, one FCL world, for the run
  energy_.use_contacts(sim.contacts());
  sim.record_contacts(options_.trace.write && options_.trace.record.records(recordings::RecordedLoop::kContacts));
  trace_.open_tables(model_, options_.trace.block_rows, start_);
  const std::int64_t device_every = options_.trace.record.of(recordings::RecordedLoop::kDevices);
  if (trace_.writer() && device_every > 0)
    device_tables_.open(*trace_.writer(), model_, devices_, options_.devices.record, trace_.block_rows(),
                        options_.devices.counters, device_every);
  input_ = make_input(model_);
  record_ = make_tick_record(model_);
  rendered_.assign(model_.fingers.size(), Vec3::Zero());
  const auto ticks = static_cast<std::int64_t>(std::llround(scenario_.duration() * model_.rates.servo));
  run_ticks_ = options_.stop.max_ticks >= 0 ? std::min(ticks, options_.stop.max_ticks) : ticks;
  expectations_.emplace(scenario_, ticks, paced_, result_.expectations);
  // The view trajectory functions read: before the first tick, the initial state, fingers at
  // zero and free. Updated only when a physics tick ran, and only if some function takes it.
  view_ = scenario_.uses_view();
  if (view_) {
    scripting::fill_snapshot(sim, record_, slip_, view_state_);
    scenario_.update_view(view_state_);
  }
  if (paced_) {
    // Room for every snapshot the loop will copy, so that copying allocates nothing.
    scripting::Snapshot prototype;
    scripting::fill_snapshot(sim, record_, slip_, prototype);
    presize_snapshot(prototype);
    expectations_->presize(prototype);
    if (script_ && script_->has_feeds()) {
      if (view_) script_->prepare_views(prototype);
      script_->start();
    }
  }
  script_feeds_ = script_ && script_->has_feeds();
}

void Run::start_pacing() {
  if (!paced_) return;
  // The writer thread exists already (the TraceWriter started it), so only this thread becomes
  // real-time; the CLI has warned if the system does not allow it.
  if (options_.pacing.realtime) realtime_ = enter_realtime().empty();
  scenario_.forbid_lua_on(std::this_thread::get_id());
  options_.pacing.pacer->start();
}

void Run::read_devices(std::int64_t n) {
  const double t = tick_time_ = sim_->time();
  for (std::size_t f = 0; f < devices_.size(); ++f) {
    if (side_scripts_[f]) side_scripts_[f]->sample(t);   // for what the script keeps; output unused
    samples_[f] = devices_[f]->read(n, t);
    checks_[f].check(samples_[f], n, t);   // throws: the run stops with the device's fault
    input_.fingers[f].hip = samples_[f].position;
    input_.fingers[f].gimbal = samples_[f].gimbal;
  }
}

void Run::capture_initial(std::int64_t n) {
  if (n != 0) return;
  // Before the first step no finger record exists yet: a finger is where its device is.
  for (std::size_t f = 0; f < devices_.size(); ++f)
    record_.servo[f].hip = record_.haptic[f].god_object = input_.fingers[f].hip;
  expectations_->capture_initial(*sim_, record_, slip_);
}

void Run::render() {
  // The step's forces leave now; each device clamps them to its limits, and a device with a
  // motor model ramps them in and derates them (force safety, force_safety.hpp).
  for (std::size_t f = 0; f < devices_.size(); ++f)
    rendered_[f] = devices_[f]->render(record_.servo[f].force);
}

void Run::pace(std::int64_t n) {
  tick_pace_ = TickPace{};
  if (!paced_) return;
  // The forces are out: wait for this tick's deadline (or count it late). A stall releases
  // every device at once, before anything else runs, and ends the run.
  tick_pace_ = options_.pacing.pacer->end_tick(n);
  if (tick_pace_.stalled || tick_pace_.lagging) {
    release_all();
    throw std::runtime_error(pacing_message(tick_pace_, *options_.pacing.pacer, n, model_.rates.servo));
  }
}

void Run::record(std::int64_t n) {
  device_tables_.record(n, tick_time_, samples_, rendered_, tick_pace_.overrun);
  trace_.record(record_, rendered_, input_, sim_->state());
}

void Run::watch(std::int64_t n) {
  ++result_.servo_ticks;
  if (record_.diverged_body >= 0)
    throw std::runtime_error(divergence_message(model_, sim_->state(), record_.diverged_body, tick_time_, n));
  if (record_.physics_ran) {
    stability_.after_physics(sim_->state(), n, tick_time_);   // throws to refuse
    if (const std::optional<EnergyGain> gain = energy_.after_physics(sim_->state(), tick_time_))
      throw std::runtime_error(energy_gain_message(model_, *gain, tick_time_, n));
  }
}

void Run::count() {
  if (record_.haptic_ran) {
    ++result_.haptic_ticks;
    for (std::size_t f = 0; f < slip_.size(); ++f) slip_[f] += record_.haptic[f].slip;
  }
  result_.physics_ticks += record_.physics_ran;
}

void Run::feed_script(std::int64_t n) {
  if (view_ && record_.physics_ran && !paced_) {
    scripting::fill_snapshot(*sim_, record_, slip_, view_state_);
    scenario_.update_view(view_state_);
  }
  if (!script_feeds_) return;
  // Paced: the view goes to the script thread (a copy into a preallocated slot), then the tick
  // is done: the script thread may compute the sample that needed it.
  if (view_ && record_.physics_ran) {
    if (scripting::Snapshot* v = script_->view_slot()) {
      scripting::fill_snapshot(*sim_, record_, slip_, *v);
      script_->commit_view(n);
    }
  }
  script_->tick_done(n);
}

void Run::check_interrupt(std::int64_t n) {
  // Paced (a hand on a device): Ctrl-C is seen at the next tick; unpaced at the wall-clock check.
  if (!paced_ && n % kWallCheckInterval != kWallCheckInterval - 1) return;
  if (options_.stop.interrupt && options_.stop.interrupt->load()) {
    result_.interrupted = true;
    const int signal = options_.stop.signal ? options_.stop.signal->load() : 0;
    throw std::runtime_error(interrupted_message(signal, sim_->time()));
  }
}

void Run::report_progress(std::int64_t n) {
  // The first progress line after 2 s: a quick run prints none. Never paced.
  if (n % kWallCheckInterval != kWallCheckInterval - 1 || !options_.report.progress || paced_) return;
  if (seconds_since(start_) > 2.0 && seconds_since(last_progress_) > 0.25) {
    last_progress_ = RunClock::now();
    options_.report.progress(sim_->time(), scenario_.duration());
  }
}

void Run::publish_live(std::int64_t n) {
  LiveChannel* live = options_.live;
  if (!live || !(record_.haptic_ran || record_.physics_ran)) return;
  if (record_.physics_ran) live_physics_tick_ = n;
  if (record_.haptic_ran) live_haptic_tick_ = n;
  // Copies into the snapshot's preallocated vectors: element assignments, nothing allocated.
  LiveSnapshot& s = live->back();
  s.tick = n;
  s.physics_tick = live_physics_tick_;
  s.haptic_tick = live_haptic_tick_;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    s.bodies[i].position = record_.physics[i].position;
    s.bodies[i].orientation = record_.physics[i].orientation;
  }
  for (std::size_t f = 0; f < s.fingers.size(); ++f) {
    const HapticFingerRecord& h = record_.haptic[f];
    LiveFinger& out = s.fingers[f];
    out.hip = record_.servo[f].hip;
    out.god_object = h.god_object;
    out.force = h.force;
    out.surface_point = h.surface_point;
    out.friction_radius = h.friction_radius;
    out.state = static_cast<std::int8_t>(h.phase);
  }
  live->publish();
}

void Run::after_last_tick(std::int64_t n) {
  if (n == 0) expectations_->capture_initial(*sim_, record_, slip_);
  expectations_->at_tick(n, *sim_, record_, slip_);
}

void Run::release_all() {
  // Zero force on every device, even if one of them fails to take it (its error is kept for
  // the result when the run has none: a device that may still push is worth reporting).
  for (auto& d : devices_) {
    try {
      d->release();
    } catch (const std::exception& e) {
      if (release_error_.empty()) release_error_ = "releasing " + d->describe() + ": " + e.what();
    }
  }
}

void Run::stop() {
  if (sim_) result_.simulated = sim_->time();
  result_.warnings = stability_.lines();
  release_all();   // at the end, on error, on interrupt: no device keeps a force
  if (result_.error.empty() && !release_error_.empty()) result_.error = release_error_;
  if (realtime_) leave_realtime();
  if (paced_) {
    result_.pacing = options_.pacing.pacer->summary();
    result_.overruns = options_.pacing.pacer->overruns();
    // The loop is over and this thread ordinary again: Lua may run here once the script thread
    // has stopped. The expectations that fell due are checked now, in due order, from the
    // snapshots the loop copied; a script error stops them as it stops an unpaced run.
    if (script_) script_->stop();
    scenario_.forbid_lua_on(std::thread::id{});
    if (script_feeds_) {
      result_.script_holds = script_->holds();
      result_.pacing += "; " + script_->summary();
      trace_.set_attribute("script_thread", script_->summary());
    }
    try {
      if (expectations_) expectations_->check_deferred();
    } catch (const std::exception& e) {
      if (result_.error.empty()) result_.error = e.what();
    }
  }
  result_.wall = seconds_since(start_);
}

}  // namespace graspsim::app
