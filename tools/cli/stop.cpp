// Stop signals (stop.hpp).
#include "cli/stop.hpp"

#include <csignal>

namespace graspsim::cli {
namespace {

StopFlags g_stop;

void on_stop_signal(int signal) {
  g_stop.signal.store(signal);
  g_stop.interrupt.store(true);
}

}  // namespace

StopFlags& stop_flags() { return g_stop; }

void handle_stop_signals() {
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) std::signal(s, on_stop_signal);
  std::signal(SIGXFSZ, SIG_IGN);
}

}  // namespace graspsim::cli
