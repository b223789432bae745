// The graspsim command line: one table of subcommands, each with its own options, usage and help
// (cli/options.hpp), dispatched by name.
#include <iostream>
#include <string>
#include <vector>

#include "cli/compare.hpp"
#include "cli/repair.hpp"
#include "cli/replay.hpp"
#include "cli/report.hpp"
#include "cli/run.hpp"
#include "cli/stop.hpp"
#include "cli/sweep.hpp"
#include "cli/view.hpp"
#include "graspsim_version.hpp"

namespace {

using namespace graspsim::cli;

struct Subcommand {
  const char* name;
  const char* usage;   // its first usage line, for `graspsim` alone and an unknown command
  int (*run)(const std::vector<std::string>& args);
};

int replay(const std::vector<std::string>& args) {
  handle_stop_signals();
  return replay_command(args, &stop_flags().interrupt, &stop_flags().signal);
}

// Every subcommand; each parses its own arguments (`graspsim NAME --help`). sweep-task is a
// sweep's Slurm array task, not for people (`graspsim sweep --slurm` submits it).
const Subcommand kSubcommands[] = {
    {"run", "graspsim run SCENARIO.lua [--out FILE.h5] [--set NAME=VALUE]... [options]", run_command},
    {"sweep", "graspsim sweep SCENARIO.lua --grid NAME=V1,V2,... --out DIR [options]", sweep_command},
    {"replay", "graspsim replay TRACE.h5 [--out NEW.h5] [--set NAME=VALUE]... [options]", replay},
    {"repair", "graspsim repair TRACE.h5", repair_command},
    {"view", "graspsim view TRACE.h5 [B.h5] [--port N] [--open]", view_command},
    {"compare", "graspsim compare A.h5 B.h5 [--atol X] [--rtol X] [--bitwise] [--view [--port N]] [options]",
     compare_command},
    {"sweep-task", nullptr, sweep_task_command},
};

std::string usage() {
  std::string text;
  for (const Subcommand& c : kSubcommands)
    if (c.usage) text += std::string(text.empty() ? "usage: " : "       ") + c.usage + "\n";
  return text + "       graspsim --help | --version   (graspsim COMMAND --help: a command's options)\n";
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::cerr << usage() << "Try 'graspsim --help'.\n";
    return kExitBadInput;
  }
  const std::string& command = args.front();
  if (command == "-h" || command == "--help" || command == "help") {
    std::cout << run_help();
    return kExitOk;
  }
  if (command == "--version") {
    std::cout << "graspsim " << GRASPSIM_VERSION << "\n";
    return kExitOk;
  }
  for (const Subcommand& c : kSubcommands)
    if (command == c.name) return c.run({args.begin() + 1, args.end()});
  std::cerr << "graspsim: unknown command '" << command << "'\n" << usage() << "Try 'graspsim --help'.\n";
  return kExitBadInput;
}
