// The first divergence of two traces, from the comparison `graspsim compare` prints.
#include "view/server/overlay.hpp"

#include "app/json.hpp"
#include "graspsim/recordings/trace_compare.hpp"
#include "view/server/pack.hpp"
#include "view/server/scene.hpp"

namespace graspsim::view {

using app::json_string;

Divergence first_divergence(const std::string& a, const std::string& b) {
  recordings::CompareResult r;
  try {
    r = recordings::compare_traces(a, b);
  } catch (const std::exception& e) {
    throw ViewError("cannot compare " + a + " with " + b + ": " + e.what());
  }
  // compare_traces lists the differing datasets first, by first divergence (tick, time, path).
  Divergence d;
  if (!r.datasets.empty() && r.datasets.front().differs() && r.datasets.front().first) {
    d.tick = r.datasets.front().first->tick;
    d.loop = r.datasets.front().loop;
    d.dataset = r.datasets.front().path;
  }
  return d;
}

std::string divergence_json(const std::string& a, const std::string& b, const Divergence& d) {
  return "{\"a\": " + json_string(a) + ", \"b\": " + json_string(b) +
         ", \"divergent_tick\": " + (d.tick ? std::to_string(*d.tick) : std::string("null")) +
         ", \"loop\": " + json_string(d.loop) + ", \"dataset\": " + json_string(d.dataset) + "}\n";
}

}  // namespace graspsim::view
