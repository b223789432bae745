// `graspsim compare A.h5 B.h5`: two traces compared tick by tick (README.md, "Comparing traces").
#pragma once

#include <string>
#include <vector>

namespace graspsim::cli {

// args: what follows "compare". Exit codes: 0 same, 1 different, 2 unusable input; with --view,
// that of the view after the report.
int compare_command(const std::vector<std::string>& args);

}  // namespace graspsim::cli
