// The servers' start and stop (view/server/http.hpp): a server destroyed or stopped right after
// it started must return. cpp-httplib 0.11's stop() is lost when it comes before the listening
// thread has marked itself running; before the servers repeated it, about 1 in 40 `run --view`
// that failed at once hung on exit. 200 rounds each make a lost stop a hang (ctest's timeout),
// not a rare flake. Each round binds port 0 (any free one) on 127.0.0.1.
#include <catch2/catch.hpp>

#include <thread>

#include "app/live_channel.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "view/server/live.hpp"
#include "view/server/server.hpp"

namespace {

constexpr int kRounds = 200;
const std::string kWeb = GRASPSIM_SOURCE_DIR "/view/web";   // what is served is not asked for here

}  // namespace

TEST_CASE("live server: constructed and destroyed at once, 200 times, every destructor returns") {
  using namespace graspsim;
  const auto scenario = scripting::Scenario::load(GRASPSIM_SOURCE_DIR "/scenarios/two_finger_lift.lua");
  app::LiveChannel channel(scenario.model().bodies.size(), scenario.model().fingers.size());
  int ended = 0;
  for (int i = 0; i < kRounds; ++i) {
    view::LiveServer server(scenario, channel, kWeb, 0);
    CHECK(server.port() > 0);
    ++ended;   // counted before the destructor: the test's end is reached only if all returned
  }
  CHECK(ended == kRounds);
}

TEST_CASE("view server: stopped as serve() starts, 200 times, serve() returns and stop() returns") {
  using namespace graspsim;
  int served = 0;
  for (int i = 0; i < kRounds; ++i) {
    view::ViewServer server(view::Packed{}, kWeb, 0);
    std::thread t([&] { served += server.serve() ? 1 : 0; });
    server.stop();
    t.join();
  }
  CHECK(served == kRounds);   // serve() says true: it listened, and was stopped
}
