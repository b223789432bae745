// Reproducible random inputs for property tests: built from the raw output of std::mt19937_64,
// whose sequence the standard fixes for a seed (the <random> distributions are not fixed across
// standard libraries), so a sweep is the same sweep on every machine.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <random>

namespace graspsim::test {

// Uniform in [0, 1): the top 53 bits of one draw, times 2^-53.
inline double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// A unit vector uniform on the sphere (Archimedes: z uniform in [-1, 1], azimuth uniform).
inline Eigen::Vector3d random_direction(std::mt19937_64& rng) {
  constexpr double kPi = 3.141592653589793;
  const double z = 2.0 * uniform01(rng) - 1.0;
  const double phi = 2.0 * kPi * uniform01(rng);
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
}

}  // namespace graspsim::test
