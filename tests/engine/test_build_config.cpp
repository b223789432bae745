// build_config: what a program built on graspsim checks to know it compiles the engine's headers
// as the libraries were compiled (engine/build_config.hpp). The expected values are the settings
// the top CMakeLists.txt gives every target: Eigen's alignment 16 bytes, no Eigen SIMD, no
// fast-math, no fused multiply-add (-ffp-contract=off). This file is compiled with them too, so
// it must match; a setting changed by hand must be named, with both values.
#include <catch2/catch.hpp>

#include <string>

#include "graspsim/engine/build_config.hpp"

using namespace graspsim;

TEST_CASE("build config: the engine library has graspsim's settings, this unit matches, a differing one is named",
          "[build_config]") {
  const BuildConfig lib = library_build_config();
  CHECK(lib.eigen_max_align_bytes == 16);
  CHECK(lib.eigen_max_static_align_bytes == 16);
  CHECK_FALSE(lib.eigen_vectorized);
  CHECK_FALSE(lib.fast_math);
  CHECK_FALSE(lib.contracts_multiply_add);
  CHECK(build_config_mismatch() == "");

  BuildConfig other = lib;
  other.eigen_max_align_bytes = 0;   // what EIGEN_DONT_VECTORIZE alone gives
  other.eigen_vectorized = true;
  const std::string why = build_config_mismatch(other);
  CHECK(why.find("EIGEN_MAX_ALIGN_BYTES = 0 here, 16 in graspsim") != std::string::npos);
  CHECK(why.find("EIGEN_VECTORIZE on here, off in graspsim") != std::string::npos);
  CHECK(why.find("EIGEN_MAX_STATIC_ALIGN_BYTES") == std::string::npos);   // equal: not named
  CHECK(why.find("graspsim::engine") != std::string::npos);               // the fix
}
