// scene.hpp (Eigen) before httplib.h: Eigen does not compile after httplib.h.
#include "view/server/scene.hpp"
//
#include "view/server/http.hpp"

#include <chrono>
#include <thread>

namespace graspsim::view {

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
