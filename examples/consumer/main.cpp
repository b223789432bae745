// A program that embeds graspsim: loads a scenario, steps its run tick by tick to the end writing
// its trace (app::RunSession, as an application that acts between ticks would), and reports its
// expectations. Its trace equals `graspsim run SCENARIO --out OUT` bit for bit.
// usage: graspsim_consumer SCENARIO.lua OUT.h5
// exit status: 0 every expectation held, 1 one failed or the run stopped early, 2 bad input.
#include <cstdio>
#include <exception>
#include <string>

// session.hpp first: the install test builds this file, so the header is checked to compile alone.
#include <graspsim/app/session.hpp>
//
#include <graspsim/app/run.hpp>
#include <graspsim/engine/build_config.hpp>
#include <graspsim/recordings/trace_writer.hpp>
#include <graspsim/scripting/scenario.hpp>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s SCENARIO.lua OUT.h5\n", argv[0]);
    return 2;
  }
  // This file is compiled as the libraries were (the definitions and flags graspsim::app passes
  // on), or the engine's headers would mean other layouts and other arithmetic here.
  if (const std::string why = graspsim::build_config_mismatch(); !why.empty()) {
    std::fprintf(stderr, "graspsim_consumer: %s\n", why.c_str());
    return 2;
  }
  const std::string scenario_path = argv[1], out = argv[2];
  try {
    const graspsim::scripting::Scenario scenario = graspsim::scripting::Scenario::load(scenario_path);
    graspsim::app::RunOptions options;   // the defaults: scripted fingers, every tick of every loop
    options.out = out;
    graspsim::app::RunSession session(scenario, options);
    while (session.step()) {
      // An application reads session.simulation() or session.record() here, between ticks.
    }
    const graspsim::app::RunResult result = session.finish();
    if (result.not_started) {
      std::fprintf(stderr, "graspsim_consumer: %s: the run could not start: %s\n", scenario_path.c_str(),
                   result.error.c_str());
      return 2;
    }
    int failed = 0;
    for (const auto& e : result.expectations) {
      failed += !e.passed;
      std::printf("%s  %s%s%s\n", e.passed ? "PASS" : "FAIL", e.what.c_str(), e.detail.empty() ? "" : ": ",
                  e.detail.c_str());
    }
    std::printf("%lld physics ticks, %.3f s simulated, trace %s\n", static_cast<long long>(result.physics_ticks),
                result.simulated, result.trace_path.c_str());
    if (!result.error.empty()) std::fprintf(stderr, "graspsim_consumer: the run stopped: %s\n", result.error.c_str());
    if (!result.trace_error.empty()) std::fprintf(stderr, "graspsim_consumer: trace: %s\n", result.trace_error.c_str());
    return result.passed() && result.trace_error.empty() ? 0 : 1;
  } catch (const graspsim::scripting::ScenarioError& e) {   // the scenario: names the file and line
    std::fprintf(stderr, "graspsim_consumer: %s\n", e.what());
  } catch (const graspsim::app::OutputError& e) {           // the output path: names it
    std::fprintf(stderr, "graspsim_consumer: %s\n", e.what());
  } catch (const graspsim::recordings::TraceError& e) {     // the trace could not be created
    std::fprintf(stderr, "graspsim_consumer: cannot write the trace %s: %s\n", out.c_str(), e.what());
  }
  return 2;
}
