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
  port_ = configure_and_bind(http, web, port);
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
