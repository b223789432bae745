// Determinism across compilers: the graspsim binary built by GCC and its twin built by Clang from
// the same source (tests/golden/CMakeLists.txt, GRASPSIM_COMPILER_TWIN) write bit-identical
// traces of every library scenario. README.md, "Determinism".
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "graspsim/recordings/trace_reader.hpp"
#include "tests/support/library.hpp"
#include "tests/support/shell.hpp"
#include "tests/support/skip.hpp"

namespace fs = std::filesystem;
using graspsim::test::Outcome;
using graspsim::test::shell;

namespace {

const std::string kSource = GRASPSIM_SOURCE_DIR;
const std::string kTmp = GRASPSIM_TEST_TMP;

using graspsim::test::library_scenarios;

}  // namespace

// Law: IEEE 754 makes each +, -, *, / and sqrt correctly rounded, so two compilers that perform
// the same operations in the same order on the same values give the same bits. The build keeps
// the order fixed for both (-ffp-contract=off: no fused a*b+c; no fast-math: no reassociation;
// EIGEN_DONT_VECTORIZE: one summation order) and both call the same libm for sin, cos, atan2, ...
// So the tolerance is zero: `graspsim compare --bitwise --all-ticks` at every row of every table,
// state_hash included. Swept over every scenario in scenarios/ (each at its own integrator and
// rates) and again under the paper's explicit step, so both integrators' code is compared.
TEST_CASE("a GCC and a Clang build give bit-identical traces of every library scenario", "[determinism][compiler]") {
#ifndef GRASPSIM_CLI_COMPILER_TWIN
  GRASPSIM_SKIP("no compiler twin: " GRASPSIM_COMPILER_TWIN_SKIP);
#else
  const std::string cli = GRASPSIM_CLI, twin = GRASPSIM_CLI_COMPILER_TWIN;
  REQUIRE(fs::exists(twin));
  const auto files = library_scenarios();
  REQUIRE(files.size() >= 13);
  for (const std::string& file : files) {
    for (const std::string integrator : {"", "paper"}) {
      const std::string stem = fs::path(file).stem().string() + (integrator.empty() ? "" : "_" + integrator);
      const std::string set = integrator.empty() ? "" : " --set integrator=" + integrator;
      const std::string a = kTmp + "/compiler_twin_" + stem + "_main.h5";
      const std::string b = kTmp + "/compiler_twin_" + stem + "_twin.h5";
      INFO(file << set);
      const Outcome run_a = shell(cli + " run --quiet " + file + set + " --out " + a);
      const Outcome run_b = shell(twin + " run --quiet " + file + set + " --out " + b);
      INFO(run_a.output << "\n---\n" << run_b.output);
      // Same outcome (every library scenario meets its expectations: 0), and both traces written.
      CHECK(run_a.status == 0);
      CHECK(run_b.status == run_a.status);
      REQUIRE(fs::exists(a));
      REQUIRE(fs::exists(b));
      // The two really are different compilers.
      const std::string compiler_a = graspsim::recordings::read_string_attribute(a, "/", "compiler");
      const std::string compiler_b = graspsim::recordings::read_string_attribute(b, "/", "compiler");
      INFO(compiler_a << " | " << compiler_b);
      CHECK(compiler_a != compiler_b);
      CHECK_THAT(compiler_a + compiler_b, Catch::Contains("g++") && Catch::Contains("clang++"));
      const Outcome compared = shell(cli + " compare --bitwise --all-ticks " + a + " " + b);
      INFO(compared.output);
      CHECK(compared.status == 0);
      fs::remove(a);
      fs::remove(b);
    }
  }
#endif
}
