// `graspsim view TRACE.h5`: serves the trace as a 3D page on 127.0.0.1 (view/README.md).
#pragma once

#include <string>
#include <vector>

namespace graspsim::cli {

// args: what follows "view". Serves until SIGINT, SIGTERM or SIGHUP, then exits 0; 2 on bad
// input (arguments, a missing file, a file that is not a trace, a port in use, the page's files
// missing), before anything is served.
int view_command(const std::vector<std::string>& args);

}  // namespace graspsim::cli
