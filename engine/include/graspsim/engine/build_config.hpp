// The compile settings that decide the engine's memory layout and arithmetic, and a check that a
// program built on graspsim compiles its headers as the libraries were compiled (top
// CMakeLists.txt says why each one matters). find_package(graspsim) passes them on as usage
// requirements (graspsim::determinism); a build that drops one mixes two layouts of the same
// Eigen types (undefined behaviour) or gives other bits.
#pragma once

#include <string>

#include <Eigen/Core>

namespace graspsim {

struct BuildConfig {
  int eigen_max_align_bytes = 0;          // bytes: EIGEN_MAX_ALIGN_BYTES (graspsim: 16)
  int eigen_max_static_align_bytes = 0;   // bytes: EIGEN_MAX_STATIC_ALIGN_BYTES (graspsim: 16)
  bool eigen_vectorized = false;          // EIGEN_VECTORIZE: Eigen's SIMD paths (graspsim: off)
  bool fast_math = false;                 // __FAST_MATH__: -ffast-math (graspsim: off)
  bool contracts_multiply_add = false;    // a*b-c fused into one rounding (graspsim: off, -ffp-contract=off)
  bool operator==(const BuildConfig&) const = default;
};

namespace build_config_detail {
// Internal linkage (an unnamed namespace) on purpose: each translation unit gets its own copy,
// evaluated as that unit was compiled. One inline function shared by the libraries and the
// program would leave the linker to keep either body, and the check would compare one with itself.
namespace {
// a = 1 + 2^-30, b = 1 - 2^-30: a*b = 1 - 2^-60 exactly, which rounds to 1, so a*b - 1 is 0 with
// two roundings and -2^-60 when the compiler fuses it into one (an FMA). volatile: the values are
// not known when compiling, so the compiler cannot fold the expression either way.
inline bool contracts_multiply_add() {
  volatile double a = 1.0 + 0x1p-30, b = 1.0 - 0x1p-30, c = 1.0;
  const double x = a, y = b, z = c;
  return x * y - z != 0.0;
}
inline BuildConfig this_unit() {
  BuildConfig config;
  config.eigen_max_align_bytes = EIGEN_MAX_ALIGN_BYTES;
  config.eigen_max_static_align_bytes = EIGEN_MAX_STATIC_ALIGN_BYTES;
#ifdef EIGEN_VECTORIZE
  config.eigen_vectorized = true;
#endif
#ifdef __FAST_MATH__
  config.fast_math = true;
#endif
  config.contracts_multiply_add = contracts_multiply_add();
  return config;
}
}  // namespace
}  // namespace build_config_detail

// The settings the engine library was compiled with.
BuildConfig library_build_config();

// "" when `here` (by default: the calling translation unit's settings) equals the library's;
// otherwise one line naming each setting that differs, with both values, and what to do.
std::string build_config_mismatch(const BuildConfig& here = build_config_detail::this_unit());

}  // namespace graspsim
