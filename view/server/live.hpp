// The live view's server (view/README.md, "Live"): the page's files, /scene.json (the scenario's
// floor, bodies and fingers, marked live) and /live, a Server-Sent Events stream of the run's
// newest snapshot at about 60 Hz. A pump thread of its own is the live channel's one reader; the
// run loop never waits for it, nor for any page.
#pragma once

#include <memory>
#include <string>

#include "app/live_channel.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::view {

// What the page is told when the run is over.
struct LiveEnd {
  std::string status;   // "complete", or what stopped the run
  std::string trace;    // the trace written ("" none)
};

class LiveServer {
 public:
  // The scene of `scenario` (shapes as its model has them) and a stream read from `channel`,
  // which must outlive the server. Binds 127.0.0.1:`port` (0: any free port); throws ViewError
  // naming the port when it cannot. Serves on threads of its own from construction on.
  LiveServer(const scripting::Scenario& scenario, app::LiveChannel& channel, const std::string& web, int port);
  ~LiveServer();   // stops serving (end() first, if the pages should be told)
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  int port() const;
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port()) + "/"; }

  // The run is over: the last snapshot and then `end` go to every connected page, waiting up to
  // `wait_s` seconds for them to be sent; the server then stops.
  void end(const LiveEnd& end, double wait_s = 1.0);

  // One snapshot as the JSON of a /live message (m, N, ticks; %.17g, so a pose is the trace's
  // to the last bit): {"tick", "physics_tick", "haptic_tick", "bodies": [[x, y, z, qw, qx, qy,
  // qz], ...], "fingers": [{"hip", "god_object", "force", "surface_point", "friction_radius",
  // "state"}, ...]}.
  static std::string snapshot_json(const app::LiveSnapshot& s);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspsim::view
