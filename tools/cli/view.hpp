// `graspsim view TRACE.h5`: serves the trace as a 3D page on 127.0.0.1 (view/README.md).
#pragma once

#include <string>
#include <vector>

namespace graspsim::cli {

// args: what follows "view". Serves until SIGINT, SIGTERM or SIGHUP, then exits 0; 2 on bad
// input (arguments, a missing file, a file that is not a trace, a port in use, the page's files
// missing), before anything is served.
int view_command(const std::vector<std::string>& args);

// The port both views serve on unless --port says otherwise: one page address to remember.
constexpr int kDefaultViewPort = 8717;

// Starts xdg-open on `url` for --open, not waiting for the browser. The starter is reaped at once
// (xdg-open is left to init), so no zombie stays for the session. When xdg-open is not there,
// says so on stderr, prefixed by `who` ("graspsim view").
void open_browser(const std::string& url, const std::string& who);

}  // namespace graspsim::cli
