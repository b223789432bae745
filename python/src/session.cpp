#include "session.hpp"

#include <stdexcept>

#include "app/run_budget.hpp"
#include "graspsim/recordings/record_selection.hpp"

namespace graspsim::python {
namespace {

scripting::Scenario load_scenario(const LoadArgs& args) {
  scripting::LoadOptions load;
  load.sets = args.sets;
  return scripting::Scenario::load(args.path, load);
}

std::string finger_list(const Model& model) {
  std::string s;
  for (const auto& f : model.fingers) s += (s.empty() ? "" : ", ") + f.name;
  return s;
}

}  // namespace

Session::Session(const LoadArgs& args) : scenario_(load_scenario(args)), registry_(app::default_registry()) {
  const Model& m = model();
  if (!args.trace && (args.record || args.compression != 0))
    throw std::invalid_argument(std::string("trace=None writes no trace, so it takes no ") +
                                (args.record ? "record" : "compression"));
  if (args.compression < 0 || args.compression > 9)
    throw std::invalid_argument("compression: a deflate level from 0 (none) to 9, got " +
                                std::to_string(args.compression));
  if (args.trace && args.trace->empty()) throw std::invalid_argument("trace: an empty file name (None: no trace)");

  drive_.assign(m.fingers.size(), false);
  for (const std::string& name : args.drive) {
    const std::size_t f = finger(name);
    if (drive_[f]) throw std::invalid_argument("drive: finger '" + name + "' named twice");
    drive_[f] = true;
  }
  const std::vector<bool>& drive = drive_;
  // Each finger's device: the scenario's default (as `graspsim run` with no --device), or the
  // program's. Real devices pace the run in real time, which a stepping program cannot keep.
  plan_ = app::plan_devices(scenario_, {}, registry_);
  for (std::size_t f = 0; f < drive.size(); ++f)
    if (plan_.real[f] && !drive[f])
      throw app::DeviceError("finger '" + m.fingers[f].name + "': its device '" + scenario_.fingers()[f].device +
                             "' is paced in real time, which a program stepping the run cannot keep; "
                             "drive it from the program (drive=[...]) or run it with `graspsim run`");

  options_.out = args.trace.value_or("");
  options_.trace.write = args.trace.has_value();
  options_.trace.naming = {"trace", "trace=None writes no trace"};
  options_.trace.compression = args.compression;
  if (args.record) {
    try {
      options_.trace.record = recordings::RecordSelection::parse(*args.record);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("record '" + *args.record + "': " + e.what());
    }
  }
  options_.overrides = args.sets;
  options_.inputs = plan_.files;
  options_.devices.record = plan_.recorded();
  options_.devices.script_alongside = plan_.script_alongside;
  program_.assign(drive.size(), nullptr);
  for (std::size_t f = 0; f < drive.size(); ++f) {
    if (!drive[f]) continue;
    // Its samples go to /devices/<finger>, as any device's that is not the scenario's script, so
    // that `graspsim replay` can run the session again. It samples the script itself.
    options_.devices.record.resize(drive.size(), false);
    options_.devices.record[f] = true;
    if (f < options_.devices.script_alongside.size()) options_.devices.script_alongside[f] = false;
  }
  options_.devices.make = [this](std::size_t f) -> std::unique_ptr<hw::Device> {
    if (!drive_[f]) return app::make_device(plan_, registry_, scenario_, f);
    auto device = std::make_unique<app::ProgramFinger>(scenario_.make_trajectory(f), scenario_.fingers()[f].limits);
    program_[f] = device.get();
    return device;
  };
  std::string warning;
  const std::string too_big = app::check_run_fits(scenario_, options_, &warning);
  if (!too_big.empty()) throw std::invalid_argument(too_big);
  run_ = std::make_unique<app::RunSession>(scenario_, options_);
  // A device that could not be built (or a run that could not be prepared): nothing was
  // written, as `graspsim run` exits 2 with "the run could not start".
  if (!run_->error().empty()) {
    const std::string error = run_->finish().error;
    throw app::DeviceError("the run could not start: " + error +
                           " (nothing was written; a file already at the trace's path is as it was)");
  }
}

std::size_t Session::finger(const std::string& name) const {
  const Model& m = model();
  for (std::size_t f = 0; f < m.fingers.size(); ++f)
    if (m.fingers[f].name == name) return f;
  throw std::invalid_argument("no finger '" + name + "' in scenario " + scenario_.path() + " (fingers: " +
                          finger_list(m) + ")");
}

app::ProgramFinger& Session::driven(std::size_t f) {
  if (!drive_.at(f))
    throw std::invalid_argument("finger '" + model().fingers[f].name +
                                "' follows its scenario's device; name it in load(..., drive=[...]) to set its HIP");
  if (!program_[f]) throw std::logic_error("the run did not start: " + run_->error());
  return *program_[f];
}

}  // namespace graspsim::python
