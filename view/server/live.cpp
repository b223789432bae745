// cpp-httplib serving a running scenario: a pump thread takes the newest snapshot from the live
// channel every display frame and turns it into one SSE message; every /live stream sends the
// newest message it has not sent yet. The pump and the streams share that message under a mutex
// the run loop never touches.
#include "view/server/live.hpp"

#include <httplib.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <thread>

#include "app/json.hpp"
#include "view/server/http.hpp"
#include "view/server/pack.hpp"
#include "view/server/scene.hpp"

namespace graspsim::view {
namespace {

// s: the pump's period, the display's rate (about 60 Hz); the page draws each message once.
constexpr auto kFrame = std::chrono::microseconds(16667);

void vec(std::string& out, const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.17g,%.17g,%.17g]", v.x(), v.y(), v.z());
  out += buf;
}

// The scene the page draws, from the scenario's model: no rows (the stream brings them).
ViewScene live_scene(const scripting::Scenario& scenario) {
  const Model& m = scenario.model();
  ViewScene s;
  s.live = true;
  s.trace = "(live) " + scenario.path();
  s.scenario_name = scenario.name();
  s.status = "running";
  s.rate_servo = m.rates.servo;
  s.rate_haptic = m.rates.haptic;
  s.rate_physics = m.rates.physics;
  s.duration = scenario.duration();
  add_model(m, s);   // the shapes only: the poses come over /live
  return s;
}

}  // namespace

std::string LiveServer::snapshot_json(const app::LiveSnapshot& s) {
  std::string j = "{\"tick\":" + std::to_string(s.tick) + ",\"physics_tick\":" + std::to_string(s.physics_tick) +
                  ",\"haptic_tick\":" + std::to_string(s.haptic_tick) + ",\"bodies\":[";
  char buf[200];
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    const Vec3& p = s.bodies[i].position;
    const Quat& q = s.bodies[i].orientation;
    std::snprintf(buf, sizeof buf, "%s[%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g]", i ? "," : "", p.x(), p.y(), p.z(),
                  q.w(), q.x(), q.y(), q.z());
    j += buf;
  }
  j += "],\"fingers\":[";
  for (std::size_t f = 0; f < s.fingers.size(); ++f) {
    const app::LiveFinger& x = s.fingers[f];
    j += f ? ",{\"hip\":" : "{\"hip\":";
    vec(j, x.hip);
    j += ",\"god_object\":";
    vec(j, x.god_object);
    j += ",\"force\":";
    vec(j, x.force);
    j += ",\"surface_point\":";
    vec(j, x.surface_point);
    std::snprintf(buf, sizeof buf, ",\"friction_radius\":%.17g,\"state\":%d}", x.friction_radius, x.state);
    j += buf;
  }
  return j + "]}";
}

struct LiveServer::Impl {
  httplib::Server http;
  app::LiveChannel& channel;
  std::string scene_json;
  int port = 0;
  std::thread server, pump;
  std::atomic<bool> listen_returned{false};   // the server thread's listen has returned

  std::mutex mutex;                 // guards what follows, between the pump and the streams
  std::condition_variable changed;
  std::string message;              // the newest snapshot's SSE message ("" none yet)
  std::uint64_t sequence = 0;       // counts messages
  std::string end_message;          // set once the run is over
  bool pump_done = false;           // the pump returns (the run is over)
  bool stopping = false;            // the pump and every stream return
  int unended = 0;                  // open /live streams that have not sent the end yet

  explicit Impl(app::LiveChannel& c) : channel(c) {}

  void take_newest() {
    if (const app::LiveSnapshot* s = channel.take()) {
      std::string m = "data: " + snapshot_json(*s) + "\n\n";
      std::lock_guard<std::mutex> lock(mutex);
      message = std::move(m);
      ++sequence;
      changed.notify_all();
    }
  }

  void run_pump() {
    auto next = std::chrono::steady_clock::now();
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex);
        if (stopping || pump_done) return;
      }
      take_newest();
      next += kFrame;
      std::this_thread::sleep_until(next);
    }
  }

  struct Stream {
    std::uint64_t sent = 0;   // the sequence of the last message sent
    bool ended = false;       // the end was sent
  };

  // One /live stream: the newest message whenever there is one it has not sent, then the end.
  bool stream(httplib::DataSink& sink, Stream& st) {
    std::uint64_t& sent = st.sent;
    std::unique_lock<std::mutex> lock(mutex);
    changed.wait_for(lock, std::chrono::milliseconds(100),
                     [&] { return sequence != sent || !end_message.empty() || stopping; });
    if (stopping) return false;
    if (sequence != sent) {
      const std::string m = message;
      const bool last = !end_message.empty();
      sent = sequence;
      lock.unlock();
      if (!sink.write(m.data(), m.size())) return false;
      if (!last) return true;
      lock.lock();
    }
    if (!end_message.empty()) {
      const std::string m = end_message;
      lock.unlock();
      const bool ok = sink.write(m.data(), m.size());
      if (ok) sink.done();
      lock.lock();
      st.ended = true;
      --unended;
      changed.notify_all();
      return ok;
    }
    return true;
  }
};

LiveServer::LiveServer(const scripting::Scenario& scenario, app::LiveChannel& channel, const std::string& web, int port)
    : impl_(std::make_unique<Impl>(channel)) {
  Impl& im = *impl_;
  im.scene_json = pack_scene(live_scene(scenario)).json;
  httplib::Server& http = im.http;
  http.Get("/scene.json", [&im](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(im.scene_json, "application/json");
  });
  http.Get("/live", [&im](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    {
      std::lock_guard<std::mutex> lock(im.mutex);
      ++im.unended;
    }
    auto st = std::make_shared<Impl::Stream>();
    // text/event-stream is not one httplib compresses, so every message leaves as it is made.
    res.set_chunked_content_provider(
        "text/event-stream", [&im, st](std::size_t, httplib::DataSink& sink) { return im.stream(sink, *st); },
        [&im, st](bool) {   // the stream is over (ended, or the page went)
          std::lock_guard<std::mutex> lock(im.mutex);
          if (!st->ended) --im.unended;
          im.changed.notify_all();
        });
  });
  im.port = configure_and_bind(http, web, port);
  im.server = std::thread([&im] { listen_marking(im.http, im.listen_returned); });
  // s: how long the listening thread may take to start before the view is given up.
  constexpr double kStartLimit = 2.0;
  if (!wait_running(http, im.listen_returned, kStartLimit)) {
    stop_until_returned(http, im.listen_returned);
    im.server.join();
    throw ViewError("cannot serve on 127.0.0.1:" + std::to_string(im.port) + ": the server did not start within " +
                    std::to_string(static_cast<int>(kStartLimit)) + " s");
  }
  im.pump = std::thread([&im] { im.run_pump(); });
}

int LiveServer::port() const { return impl_->port; }

void LiveServer::end(const LiveEnd& end, double wait_s) {
  Impl& im = *impl_;
  {
    std::lock_guard<std::mutex> lock(im.mutex);
    if (!im.end_message.empty() || im.stopping) return;
    im.pump_done = true;
  }
  if (im.pump.joinable()) im.pump.join();
  im.take_newest();   // the run's last snapshot, if the pump had not taken it: the channel's reader now
  std::unique_lock<std::mutex> lock(im.mutex);
  im.end_message = "event: end\ndata: {\"status\":" + app::json_string(end.status) + ",\"trace\":" + app::json_string(end.trace) + "}\n\n";
  im.changed.notify_all();
  im.changed.wait_for(lock, std::chrono::duration<double>(wait_s), [&] { return im.unended == 0; });
}

LiveServer::~LiveServer() {
  Impl& im = *impl_;
  {
    std::lock_guard<std::mutex> lock(im.mutex);
    im.stopping = true;
    im.changed.notify_all();
  }
  if (im.pump.joinable()) im.pump.join();
  stop_until_returned(im.http, im.listen_returned);
  if (im.server.joinable()) im.server.join();
}

}  // namespace graspsim::view
