// scene.hpp (Eigen) before httplib.h: Eigen does not compile after httplib.h.
#include "view/server/scene.hpp"
//
#include "view/server/http.hpp"

#include <chrono>
#include <thread>

namespace graspsim::view {

int configure_and_bind(httplib::Server& http, const std::string& web, int port) {
  // A page left open holds its keep-alive connections on the pool's threads, and stop() waits for
  // them: 1 s of idle keeps Ctrl-C prompt (httplib's default is 5 s).
  http.set_keep_alive_timeout(1);
  http.Get("/favicon.ico", [](const httplib::Request&, httplib::Response& res) { res.status = 204; });
  // Debian's httplib compresses text/*, application/javascript and application/json replies
  // with brotli at its highest quality when the browser accepts it: 3.3 s for three.core.js
  // (1.5 MB) on this machine, for a page served over loopback. application/x-javascript, a
  // JavaScript MIME type browsers accept for modules (HTML standard, "JavaScript MIME type"),
  // is one it leaves alone.
  http.set_file_extension_and_mimetype_mapping("js", "application/x-javascript");
  http.set_mount_point("/", web);
  // httplib's default socket sets SO_REUSEPORT, which lets a second listener bind a port one
  // already holds (another graspsim view) and the kernel then shares the connections between
  // them: a page could load one trace's scene and another's columns. SO_REUSEADDR alone still
  // rebinds a port a closed server left in TIME_WAIT, and refuses one that is listened on.
  http.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  if (port == 0) {
    const int bound = http.bind_to_any_port("127.0.0.1");
    if (bound <= 0) throw ViewError("cannot listen on 127.0.0.1: no free port");
    return bound;
  }
  if (!http.bind_to_port("127.0.0.1", port))
    throw ViewError("cannot listen on 127.0.0.1:" + std::to_string(port) +
                    " (the port is in use, or needs privileges): choose another with --port N, or --port 0 for any free one");
  return port;
}

bool listen_marking(httplib::Server& http, std::atomic<bool>& returned) {
  const bool ok = http.listen_after_bind();
  returned = true;
  return ok;
}

bool wait_running(const httplib::Server& http, const std::atomic<bool>& returned, double limit_s) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  while (!http.is_running()) {
    if (returned || std::chrono::steady_clock::now() > give_up) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

void stop_until_returned(httplib::Server& http, const std::atomic<bool>& returned) {
  while (!returned) {
    http.stop();
    if (returned) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

}  // namespace graspsim::view
