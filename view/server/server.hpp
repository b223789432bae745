// The viewer's HTTP server (cpp-httplib, view/README.md): the page's files from a folder, the
// scene's JSON and blob from memory, on 127.0.0.1 only.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "view/server/pack.hpp"

namespace graspsim::view {

// The folder the page is served from: $GRASPSIM_VIEW_WEB if set, else the build's copy
// (<build>/view/web). Throws ViewError naming the folder when the page's files are not there.
std::string web_folder();

class ViewServer {
 public:
  // Binds 127.0.0.1:`port` (0: any free port). Throws ViewError when the port cannot be bound
  // (in use, or privileged), naming it.
  ViewServer(Packed packed, std::string web, int port);
  ~ViewServer();
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  // Serves a second run beside the first: its scene and blob at /b/scene.json and /b/trace.bin,
  // and `compare_json` (overlay.hpp) at /compare.json. Before serve().
  void add_overlay(Packed b, std::string compare_json);

  int port() const { return port_; }
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port_) + "/"; }
  // Serves until stop() (from another thread). Returns false if listening failed.
  bool serve();
  // Returns once serve() has returned; a stop that comes before serve() has started listening is
  // not lost. Only while serve() runs or is sure to be called.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int port_ = 0;
};

}  // namespace graspsim::view
