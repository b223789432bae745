// The live view's options and the server around the run (live.hpp).
#include "cli/live.hpp"

#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "cli/view.hpp"
#include "view/server/scene.hpp"
#include "view/server/server.hpp"

namespace graspsim::cli {

bool parse_live_option(const std::vector<std::string>& args, std::size_t& i, LiveOptions& live, std::string& error) {
  const std::string& a = args[i];
  if (a == "--view") {
    live.view = true;
  } else if (a == "--no-view") {
    live.no_view = true;
  } else if (a == "--open") {
    live.open = true;
  } else if (a == "--port") {
    const std::string v = i + 1 < args.size() ? args[++i] : "";
    char* end = nullptr;
    const long p = std::strtol(v.c_str(), &end, 10);
    if (v.empty() || *end != '\0' || p < 0 || p > 65535)
      error = "--port needs a port number from 0 to 65535 (got '" + v + "')";
    live.port = static_cast<int>(p);
  } else {
    return false;
  }
  return true;
}

std::string check_live_options(const LiveOptions& live, bool paced) {
  if (live.view && live.no_view) return "--view and --no-view contradict each other: give one";
  const bool viewed = live.view || (paced && !live.no_view);
  if (!viewed && (live.port >= 0 || live.open))
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
    const int port = live.port >= 0 ? live.port : kDefaultViewPort;
    try {
      server_ = std::make_unique<view::LiveServer>(scenario, *channel_, web, port);
    } catch (const view::ViewError&) {
      if (asked || live.port >= 0) throw;
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
