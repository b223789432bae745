// cpp-httplib serving the page, /scene.json and /trace.bin.
#include "view/server/server.hpp"

#include "view/server/http.hpp"

#include <cstdlib>
#include <filesystem>

namespace graspsim::view {

std::string web_folder() {
  const char* env = std::getenv("GRASPSIM_VIEW_WEB");
  const std::string dir = env && *env ? env : GRASPSIM_VIEW_WEB_DIR;
  namespace fs = std::filesystem;
  for (const char* file : {"index.html", "main.js", "draw.js", "live.js", "three/three.module.js", "three/OrbitControls.js"}) {
    if (!fs::is_regular_file(fs::path(dir) / file))
      throw ViewError("the page's files are missing: no " + (fs::path(dir) / file).string() +
                      " (run ./tools/graspsim once: it runs `npm ci` in view/web and builds the page)");
  }
  return dir;
}

struct ViewServer::Impl {
  httplib::Server http;
  Packed packed;
  Packed overlay;            // the second run of `graspsim view A B`
  std::string compare;       // /compare.json
  std::atomic<bool> listen_returned{false};   // serve() has returned
};

ViewServer::ViewServer(Packed packed, std::string web, int port) : impl_(std::make_unique<Impl>()) {
  impl_->packed = std::move(packed);
  httplib::Server& http = impl_->http;
  const Packed& p = impl_->packed;
  http.Get("/scene.json", [&p](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(p.json, "application/json");
  });
  http.Get("/trace.bin", [&p](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(p.blob, "application/octet-stream");
  });
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
    port_ = http.bind_to_any_port("127.0.0.1");
    if (port_ <= 0) throw ViewError("cannot listen on 127.0.0.1: no free port");
  } else {
    if (!http.bind_to_port("127.0.0.1", port))
      throw ViewError("cannot listen on 127.0.0.1:" + std::to_string(port) +
                      " (the port is in use, or needs privileges): choose another with --port N, or --port 0 for any free one");
    port_ = port;
  }
}

void ViewServer::add_overlay(Packed b, std::string compare_json) {
  impl_->overlay = std::move(b);
  impl_->compare = std::move(compare_json);
  const Impl& i = *impl_;
  const auto bytes = [](const std::string& body, const char* type) {
    return [&body, type](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-store");
      res.set_content(body, type);
    };
  };
  impl_->http.Get("/b/scene.json", bytes(i.overlay.json, "application/json"));
  impl_->http.Get("/b/trace.bin", bytes(i.overlay.blob, "application/octet-stream"));
  impl_->http.Get("/compare.json", bytes(i.compare, "application/json"));
}

ViewServer::~ViewServer() = default;

bool ViewServer::serve() { return listen_marking(impl_->http, impl_->listen_returned); }

void ViewServer::stop() { stop_until_returned(impl_->http, impl_->listen_returned); }

}  // namespace graspsim::view
