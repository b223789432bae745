// `graspsim repair FILE`: makes a trace cut by a crash readable without SWMR.
#pragma once

#include <string>
#include <vector>

namespace graspsim::cli {

// args: what follows "repair". Exit codes: 0 repaired (or not cut: nothing to do), 2 bad input.
int repair_command(const std::vector<std::string>& args);

}  // namespace graspsim::cli
