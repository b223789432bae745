// `graspsim run ... --view`: the live view of a run (view/README.md, "Live"). Its options, and
// the server's life around run_scenario.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/live_channel.hpp"
#include "app/run.hpp"
#include "view/server/live.hpp"

namespace graspsim::cli {

struct LiveOptions {
  bool view = false;      // --view
  bool no_view = false;   // --no-view
  bool open = false;      // --open
  int port = -1;          // --port N (-1: not given)
};

// Takes args[i] (and its value, advancing i) if it is --view, --no-view, --open or --port N:
// true when taken; `error` set when its value is bad.
bool parse_live_option(const std::vector<std::string>& args, std::size_t& i, LiveOptions& live, std::string& error);

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
