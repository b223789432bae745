// Perturbed waypoints: the offsets of one finger (see jitter.hpp).
#include "jitter.hpp"

namespace graspsim::scripting::detail {

std::vector<Vec3> jitter_offsets(const Jitter& jitter, std::size_t finger, std::size_t count) {
  SplitMix64 keys(jitter.seed);
  std::uint64_t key = keys.next();
  for (std::size_t i = 0; i < finger; ++i) key = keys.next();
  SplitMix64 rng(key);
  std::vector<Vec3> offsets(count);
  for (Vec3& o : offsets) {
    // One statement per axis: the order of the draws is x, y, z (arguments of one call would be
    // evaluated in an unspecified order).
    const double x = rng.symmetric(jitter.amplitude);
    const double y = rng.symmetric(jitter.amplitude);
    const double z = rng.symmetric(jitter.amplitude);
    o = Vec3(x, y, z);
  }
  return offsets;
}

}  // namespace graspsim::scripting::detail
