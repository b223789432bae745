// Two runs in one view (`graspsim view A.h5 B.h5`): B is drawn ghosted over A, and the timeline
// marks the first tick where they differ, as `graspsim compare A B` finds it
// (recordings::compare_traces with its default options: every loop, tolerance 0).
#pragma once

#include <optional>
#include <string>

namespace graspsim::view {

struct Divergence {
  std::optional<long long> tick;   // servo tick of the first differing element; none: the same
  std::string loop;                // "physics", "haptic", "servo"; "" when the same
  std::string dataset;             // "physics/objects/box/position"; "" when the same
};

// compare_traces(a, b) reduced to its first divergence. Throws ViewError naming the files when
// they cannot be compared.
Divergence first_divergence(const std::string& a, const std::string& b);

// /compare.json: {"a": ..., "b": ..., "divergent_tick": N or null, "loop": ..., "dataset": ...}.
std::string divergence_json(const std::string& a, const std::string& b, const Divergence& d);

}  // namespace graspsim::view
