// The Python module's session: a scenario loaded with its overrides, the run's options, and the
// run stepped through app::RunSession. Plain C++ (no pybind11): module.cpp binds it.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/devices.hpp"
#include "app/program_finger.hpp"
#include "app/run.hpp"
#include "app/session.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::python {

// A servo tick ended the run (a script error, a device fault, a divergence): the message the CLI
// prints as "the run stopped early: ...". The run is finished, its trace marked "error: ...".
class RunError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What load() takes, as the CLI's `run` options.
struct LoadArgs {
  std::string path;                        // the scenario file
  std::vector<std::string> sets;           // "NAME=VALUE", as --set
  std::optional<std::string> trace;        // the trace's path (--out); none: no trace (--no-trace)
  std::optional<std::string> record;       // "LOOP[:EVERY],..." as --record (needs a trace)
  int compression = 0;                     // 0 none, 1..9 deflate (needs a trace)
  std::vector<std::string> drive;          // fingers whose HIP the program sets (ProgramFinger)
};

class Session {
 public:
  // Throws scripting::ScenarioError (file and line, or the field), app::DeviceError (a bad
  // device spec, or a device that cannot be built: nothing written),
  // std::invalid_argument (an argument of load(), named), app::OutputError or
  // recordings::TraceError (the trace cannot be written; nothing is).
  explicit Session(const LoadArgs& args);

  const scripting::Scenario& scenario() const { return scenario_; }
  const Model& model() const { return scenario_.model(); }
  app::RunSession& run() { return *run_; }
  const app::RunSession& run() const { return *run_; }
  std::size_t finger(const std::string& name) const;   // its index; std::invalid_argument naming the fingers
  // The program-driven device of finger f; std::invalid_argument when the finger is not in `drive`.
  app::ProgramFinger& driven(std::size_t f);
  const app::RunOptions& options() const { return options_; }

  // step() runs with the GIL released: while it does, every other method is refused (busy), since
  // nothing else serialises the run. Read and written only with the GIL held.
  bool busy = false;

 private:
  scripting::Scenario scenario_;
  app::RunOptions options_;
  app::DeviceRegistry registry_;
  app::DevicePlan plan_;
  std::vector<bool> drive_;                    // per finger: its HIP is set by the program
  std::vector<app::ProgramFinger*> program_;   // per finger: its device once built when driven, else null
  std::unique_ptr<app::RunSession> run_;
};

}  // namespace graspsim::python
