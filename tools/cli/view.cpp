// `graspsim view`: reads the trace, packs it, serves the page until a stop signal.
#include "cli/view.hpp"

#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <thread>
#include <utility>

#include "cli/options.hpp"
#include "cli/report.hpp"
#include "view/server/overlay.hpp"
#include "view/server/server.hpp"

extern char** environ;

namespace graspsim::cli {
namespace {

constexpr const char* kViewHelp =
    "usage: graspsim view TRACE.h5 [B.h5] [--port N] [--open]\n"
    "\n"
    "Shows a trace in 3D in the browser: serves a page on 127.0.0.1, prints its URL and runs\n"
    "until Ctrl-C. The page draws the floor, every body with its shape (from the trace's own\n"
    "scenario), and per finger the HIP, the god-object (a sphere of the pad radius) coloured\n"
    "free / stick / slip, the friction circle in contact (radius mu depth about the surface\n"
    "point) and the force on the finger as an arrow (1 cm per N), the grasp axis and its\n"
    "torsion where the grasp rule holds a body; a timeline plays, pauses,\n"
    "changes speed (0.1x to 10x), scrubs and steps one physics, haptic or servo tick. Drag to\n"
    "orbit, right-drag to pan, wheel to zoom. A cut trace (a run killed or stopped early) is\n"
    "shown up to its last tick, with a note. Nothing is fetched beyond 127.0.0.1.\n"
    "Beside the scene, time series linked to the timeline (click one to go there): per finger\n"
    "the normal force, the tangential force and mu f_n, each body's height, the contact state.\n"
    "With a second trace B, both runs are drawn, B ghosted (transparent), and the timeline marks\n"
    "the first tick where they differ, as `graspsim compare TRACE B` finds it.\n"
    "\n"
    "options:\n"
    "  --port N   port on 127.0.0.1 (default 8717; 0: any free port, printed)\n"
    "  --open     open the page with xdg-open as well\n"
    "  -h, --help this help\n"
    "\n"
    "exit status: 0 stopped by Ctrl-C (SIGINT), SIGTERM or SIGHUP; 2 bad input: bad arguments,\n"
    "a missing file, a file that is not a graspsim trace or holds no physics tick, a port that\n"
    "is in use, two traces that cannot be compared (rates or schema that differ), or the\n"
    "page's files missing from the build (nothing is served then).\n";

int bad(const std::string& message) {
  std::cerr << "graspsim view: " << message << "\n";
  return kExitBadInput;
}

// B of `graspsim view A B`: its scene packed, and where it first differs from A (/compare.json).
std::pair<view::Packed, std::string> load_ghost(const std::string& a, const std::string& b) {
  const view::ViewScene scene = view::load_scene(b);
  if (!scene.note.empty()) std::cerr << "graspsim view: note: " << b << ": " << scene.note << "\n";
  const view::Divergence d = view::first_divergence(a, b);
  if (d.tick)
    std::printf("graspsim view: %s first differs from %s at servo tick %lld (%s)\n", b.c_str(), a.c_str(), *d.tick,
                d.dataset.c_str());
  else
    std::printf("graspsim view: %s and %s do not differ\n", a.c_str(), b.c_str());
  return {view::pack_scene(scene), view::divergence_json(a, b, d)};
}

}  // namespace

int view_command(const std::vector<std::string>& args) {
  std::string trace, ghost;
  int port = kDefaultViewPort;
  bool open = false, port_given = false;
  CommandLine line{"view", "usage: graspsim view TRACE.h5 [B.h5] [--port N] [--open]\n", kViewHelp,
                   {cli::port(port, port_given), flag("--open", open)}, {}};
  line.operand = [&](const std::string& v) -> std::string {
    if (trace.empty()) trace = v;
    else if (ghost.empty()) ghost = v;
    else return "at most two traces (got '" + trace + "', '" + ghost + "' and '" + v + "')";
    return "";
  };
  switch (parse_command_line(line, args)) {
    case Parsed::kHelp: return kExitOk;
    case Parsed::kError: return kExitBadInput;
    case Parsed::kGo: break;
  }
  if (trace.empty()) return usage_error(line, "view needs a trace file");

  // Stop signals are taken by one thread (sigwait), blocked in every other, the server's
  // workers included: they are created after this.
  sigset_t stop;
  sigemptyset(&stop);
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&stop, s);
  pthread_sigmask(SIG_BLOCK, &stop, nullptr);

  const auto t0 = std::chrono::steady_clock::now();
  std::unique_ptr<view::ViewServer> server;
  view::Packed packed;
  std::size_t physics_rows = 0;
  double shown = 0.0;
  try {
    const std::string web = view::web_folder();
    const view::ViewScene scene = view::load_scene(trace);
    physics_rows = scene.physics_tick.size();
    shown = static_cast<double>(scene.physics_tick.back()) / scene.rate_servo;
    packed = view::pack_scene(scene);
    if (!scene.note.empty()) std::cerr << "graspsim view: note: " << scene.note << "\n";
    const std::size_t blob_bytes = packed.blob.size();
    std::pair<view::Packed, std::string> overlay;   // read before the port is taken
    if (!ghost.empty()) overlay = load_ghost(trace, ghost);
    server = std::make_unique<view::ViewServer>(std::move(packed), web, port);
    if (!ghost.empty()) server->add_overlay(std::move(overlay.first), std::move(overlay.second));
    const double read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("graspsim view: %s: %zu physics ticks, t = 0 to %.3f s (%.1f MB for the page, read in %.2f s)\n",
                trace.c_str(), physics_rows, shown, blob_bytes / 1e6, read_s);
  } catch (const view::ViewError& e) {
    return bad(e.what());
  }
  std::printf("  url  %s  (Ctrl-C to stop)\n", server->url().c_str());
  std::fflush(stdout);
  if (open) open_browser(server->url(), "graspsim view");

  std::thread waiter([&] {
    int signal = 0;
    sigwait(&stop, &signal);
    server->stop();
  });
  const bool served = server->serve();
  if (!served) pthread_kill(waiter.native_handle(), SIGTERM);   // let the waiter return
  waiter.join();
  if (!served) return bad("serving " + server->url() + " failed");
  return kExitOk;
}

void open_browser(const std::string& url, const std::string& who) {
  // sh starts xdg-open in the background and exits: waiting for sh is immediate, and xdg-open,
  // orphaned, is reaped by init. 127: no xdg-open on PATH.
  const char* argv[] = {"sh", "-c", "command -v xdg-open >/dev/null 2>&1 || exit 127; xdg-open \"$1\" &", "sh",
                        url.c_str(), nullptr};
  // With no signal blocked: the caller may block the stop signals, and a mask is inherited.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK);
  pid_t pid = 0;
  int status = 0;
  const bool started = posix_spawnp(&pid, "sh", nullptr, &attr, const_cast<char* const*>(argv), environ) == 0;
  posix_spawnattr_destroy(&attr);
  if (started)
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  if (!started || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    std::cerr << who << ": --open: xdg-open could not be started; open " << url << " yourself\n";
}

}  // namespace graspsim::cli
