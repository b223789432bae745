// `graspsim run ... --view`: the live view of a run (view/README.md, "Live"). Its options, and
// the server's life around run_scenario.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/live_channel.hpp"
#include "app/run.hpp"
#include "cli/options.hpp"
#include "cli/view.hpp"
#include "view/server/live.hpp"

namespace graspsim::cli {

struct LiveOptions {
  bool view = false;         // --view
  bool no_view = false;      // --no-view
  bool open = false;         // --open
  int port = kDefaultViewPort;   // --port N
  bool port_given = false;
};

// --view, --no-view, --open and --port N, for a command's table (options.hpp).
std::vector<Option> live_options(LiveOptions& live);

// The combinations refused: --view with --no-view; --port or --open without a view. "" when fine.
std::string check_live_options(const LiveOptions& live, bool paced);

class LiveSession {
 public:
  // Serves the live view of `scenario` when asked (--view), or for a paced run (a hand on a
  // device) unless --no-view, and points `options.live` at its channel. Asked for: a port in use
  // or the page's files missing is an error ("" none; exit 2 before anything is written). Paced
  // without --view: the default port, else any free one, else a warning and no view.
  std::string start(const scripting::Scenario& scenario, const LiveOptions& live, bool paced, app::RunOptions& options);
  // The run is over: the pages are told how it ended and which trace it wrote (`trace` "" none).
  void end(const app::RunResult& result, const std::string& trace);

 private:
  std::optional<app::LiveChannel> channel_;
  std::unique_ptr<view::LiveServer> server_;
};

}  // namespace graspsim::cli
