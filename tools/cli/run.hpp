// `graspsim run SCENARIO.lua`: runs a scenario to its end, writes its trace, reports its
// expectations (README.md, "What a run prints and writes").
#pragma once

#include <string>
#include <vector>

namespace graspsim::cli {

// args: what follows "run". Exit codes: 0 every expectation held, 1 one failed, 2 bad input, 3
// the trace or the --summary could not be written to its end, 128 + the signal when stopped.
int run_command(const std::vector<std::string>& args);

// The help of `graspsim run`, which is the program's too (`graspsim --help`).
const char* run_help();

}  // namespace graspsim::cli
