// The engine library's own compile settings (build_config.hpp).
#include "graspsim/engine/build_config.hpp"

namespace graspsim {

BuildConfig library_build_config() { return build_config_detail::this_unit(); }

std::string build_config_mismatch(const BuildConfig& here) {
  const BuildConfig lib = library_build_config();
  if (here == lib) return "";
  std::string out = "this program is compiled with other settings than the graspsim libraries:";
  const auto number = [&](const char* name, int program, int library) {
    if (program != library)
      out += std::string("\n  ") + name + " = " + std::to_string(program) + " here, " + std::to_string(library) + " in graspsim";
  };
  const auto flag = [&](const char* name, bool program, bool library) {
    if (program != library)
      out += std::string("\n  ") + name + (program ? " on" : " off") + " here, " + (library ? "on" : "off") + " in graspsim";
  };
  number("EIGEN_MAX_ALIGN_BYTES", here.eigen_max_align_bytes, lib.eigen_max_align_bytes);
  number("EIGEN_MAX_STATIC_ALIGN_BYTES", here.eigen_max_static_align_bytes, lib.eigen_max_static_align_bytes);
  flag("EIGEN_VECTORIZE", here.eigen_vectorized, lib.eigen_vectorized);
  flag("-ffast-math", here.fast_math, lib.fast_math);
  flag("fused multiply-add (-ffp-contract)", here.contracts_multiply_add, lib.contracts_multiply_add);
  out += "\n  (link graspsim's CMake targets, which carry its definitions and flags: "
         "find_package(graspsim) and target_link_libraries(... graspsim::engine), or graspsim::app)";
  return out;
}

}  // namespace graspsim
