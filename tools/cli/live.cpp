// The live view's options and the server around the run (live.hpp).
#include "cli/live.hpp"

#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "cli/view.hpp"
#include "view/server/scene.hpp"
#include "view/server/server.hpp"

namespace graspsim::cli {

std::vector<Option> live_options(LiveOptions& live) {
  return {flag("--view", live.view), flag("--no-view", live.no_view), flag("--open", live.open),
          port(live.port, live.port_given)};
}

std::string check_live_options(const LiveOptions& live, bool paced) {
  if (live.view && live.no_view) return "--view and --no-view contradict each other: give one";
  const bool viewed = live.view || (paced && !live.no_view);
  if (!viewed && (live.port_given || live.open))
    return std::string(live.open ? "--open" : "--port") + " is for the live view: add --view" +
           (paced ? " (or drop --no-view)" : "");
  return "";
}

std::string LiveSession::start(const scripting::Scenario& scenario, const LiveOptions& live, bool paced,
                               app::RunOptions& options) {
  const bool asked = live.view;
  if (!asked && !(paced && !live.no_view)) return "";
  const Model& model = scenario.model();
  channel_.emplace(model.bodies.size(), model.fingers.size());
  try {
    const std::string web = view::web_folder();
    try {
      server_ = std::make_unique<view::LiveServer>(scenario, *channel_, web, live.port);
    } catch (const view::ViewError&) {
      if (asked || live.port_given) throw;
      server_ = std::make_unique<view::LiveServer>(scenario, *channel_, web, 0);   // the default port is taken
    }
  } catch (const view::ViewError& e) {
    channel_.reset();
    if (asked) return "--view: " + std::string(e.what());
    std::cerr << "graspsim: warning: no live view of this session: " << e.what() << "\n";
    return "";
  }
  options.live = &*channel_;
  std::printf("graspsim: live view  %s  (the run does not wait for it%s)\n", server_->url().c_str(),
              asked ? "" : "; --no-view leaves it out");
  std::fflush(stdout);
  if (live.open) open_browser(server_->url(), "graspsim");
  return "";
}

void LiveSession::end(const app::RunResult& result, const std::string& trace) {
  if (!server_) return;
  view::LiveEnd e;
  e.status = result.error.empty() ? "complete" : "error: " + result.error;
  e.trace = trace;
  server_->end(e);
  server_.reset();
}

}  // namespace graspsim::cli
