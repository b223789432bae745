// graspsim replay TRACE.h5: its arguments and its report. The replay itself, and its comparison
// with the recording, is app::run_replay (app/replay.hpp; README.md, "Replaying a trace").
#include "cli/replay.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "app/replay.hpp"
#include "app/run_budget.hpp"
#include "app/run.hpp"
#include "cli/options.hpp"
#include "cli/report.hpp"
#include "graspsim/recordings/trace_compare.hpp"

namespace graspsim::cli {
namespace {

constexpr const char* kReplayHelp =
    "usage: graspsim replay TRACE.h5 [--out NEW.h5] [--set NAME=VALUE]... [options]\n"
    "\n"
    "Reruns the scenario recorded in TRACE.h5 (its own scenario_source text and overrides, so\n"
    "it works when the scenario file has changed or moved) with every finger fed, servo tick by\n"
    "servo tick, from the recorded device samples (/servo/fingers/<finger>/hip and gimbal)\n"
    "instead of its script, writes a new trace, checks the scenario's expectations, and\n"
    "compares the new trace with the recording bit for bit (every dataset, including the\n"
    "/physics/state_hash of every physics tick).\n"
    "\n"
    "Without --set the replay must reproduce the recording: it says so, or names the first\n"
    "tick and quantity where it does not. With --set it answers 'what if' (the same hand\n"
    "motion, another mu: --set mu=0.4) and names where the two runs part; `graspsim compare\n"
    "TRACE.h5 NEW.h5` lists every difference.\n"
    "\n"
    "options:\n"
    "  --out FILE.h5        the new trace (default: <TRACE stem>.replay.h5 in this directory);\n"
    "                       never the trace replayed\n"
    "  --set NAME=VALUE     override a scenario value, after the recorded overrides (rates\n"
    "                       cannot change: the samples are one per recorded servo tick;\n"
    "                       a longer duration replays up to the last recorded tick)\n"
    "  --scenario-dir DIR   read the scenario's relative file names (meshes) from DIR instead\n"
    "                       of the recorded scenario_path's directory\n"
    "  --compress N         deflate the new trace at level N (1..9)\n"
    "  --quiet              print only errors, failed expectations and differences\n"
    "\n"
    "A trace cut by a crash (status running, cut: repaired) or stopped by an error is replayed\n"
    "up to its last recorded servo tick; expectations due later are reported as not checked.\n"
    "\n"
    "exit status: 0 reproduced (with --set: ran) and every expectation held, 1 an expectation\n"
    "failed or a replay without --set differs from the recording, 2 bad input (not a graspsim\n"
    "trace, a schema 1 trace without device inputs, a scenario finger the trace lacks, rates\n"
    "changed by --set, a scenario that does not load, an unwritable output), 3 the new trace\n"
    "could not be written to its end (a full disk), 128 + the signal when stopped by SIGINT,\n"
    "SIGHUP or SIGTERM. The new trace is written, locked and renamed as `graspsim run` does\n"
    "(graspsim --help).\n";

int bad_input(const std::string& message) {
  std::cerr << "graspsim: " << message << "\n";
  return kExitBadInput;
}


}  // namespace

int replay_command(const std::vector<std::string>& args, const std::atomic<bool>* interrupt,
                   const std::atomic<int>* signal) {
  std::string trace, out;
  app::ReplayOptions replay;
  long long compression = 0;
  bool quiet = false;
  CommandLine line{"replay", "usage: graspsim replay TRACE.h5 [--out NEW.h5] [--set NAME=VALUE]... [--scenario-dir DIR]\n"
                             "                [--compress N] [--quiet]\n",
                   kReplayHelp,
                   {text("--out", "a file name", out), set_option(replay.sets),
                    text("--scenario-dir", "a directory", replay.scenario_dir),
                    count("--compress", "a level from 1 to 9", 1, 9, compression), flag("--quiet", quiet)},
                   {}};
  line.operand = [&trace](const std::string& v) -> std::string {
    if (!trace.empty()) return "one trace at a time (got '" + trace + "' and '" + v + "')";
    trace = v;
    return "";
  };
  switch (parse_command_line(line, args)) {
    case Parsed::kHelp: return kExitOk;
    case Parsed::kError: return kExitBadInput;
    case Parsed::kGo: break;
  }
  if (trace.empty()) return usage_error(line, "replay needs a trace file");
  if (out.empty()) out = app::default_replay_out(trace);
  std::error_code ec;
  if (std::filesystem::equivalent(trace, out, ec) || std::filesystem::absolute(trace) == std::filesystem::absolute(out)) {
    return bad_input("--out " + out + " is the trace being replayed: it would be written over");
  }

  app::ReplayPlan plan;
  try {
    plan = app::load_replay(trace, replay);
  } catch (const app::ReplayError& e) {
    return bad_input(std::string("replay: ") + e.what());
  }
  for (const std::string& note : plan.notes) std::cerr << "graspsim: replay: " << note << "\n";

  app::RunOptions options = plan.run_options(out);
  options.trace.compression = static_cast<int>(compression);
  options.stop.interrupt = interrupt;
  options.stop.signal = signal;
  // The replay's trace is as large as the recording: refused if it will not fit.
  std::string size_warning;
  const std::string too_big = app::check_run_fits(*plan.scenario, options, &size_warning);
  if (!too_big.empty()) return bad_input("replay: " + too_big);
  if (!size_warning.empty()) std::cerr << "graspsim: warning: " << size_warning << "\n";
  app::ReplayOutcome outcome;
  try {
    outcome = app::run_replay(plan, options);
  } catch (const app::OutputError& e) {
    return bad_input(e.what());
  } catch (const recordings::TraceError& e) {
    return bad_input(std::string("cannot write the trace: ") + e.what());
  }
  const app::RunResult& result = outcome.run;
  if (result.not_started) return bad_input("the replay could not start: " + result.error + " (nothing was written)");

  const auto& scenario = *plan.scenario;
  if (!quiet) {
    std::printf("graspsim replay of %s: %s (recorded from %s, %s)\n", trace.c_str(), scenario.name().c_str(),
                plan.scenario_path.c_str(), plan.scenario_source_hash.c_str());
    if (plan.what_if) {
      std::string sets;
      for (const std::string& s : replay.sets) sets += (sets.empty() ? "" : ", ") + s;
      std::printf("  what if     %s (same recorded hand motion)\n", sets.c_str());
    }
    std::printf("  simulated   %.3f s: %lld servo, %lld haptic, %lld physics ticks\n", result.simulated,
                static_cast<long long>(result.servo_ticks), static_cast<long long>(result.haptic_ticks),
                static_cast<long long>(result.physics_ticks));
    std::printf("  trace       %s\n", result.trace_path.c_str());
  }
  if (!result.trace_error.empty()) {
    std::fprintf(stderr, "graspsim: the trace could not be written to its end: %s\n", result.trace_error.c_str());
  } else if (!result.error.empty()) {
    std::fprintf(stderr, "graspsim: the replay stopped early: %s\n  (the trace keeps every tick up to there)\n",
                 result.error.c_str());
  }

  // The new trace against the recording, bit for bit, on the ticks both hold.
  if (!outcome.comparison) {
    std::fprintf(stderr, "graspsim: cannot compare the replay with the recording: %s\n", outcome.compare_error.c_str());
  } else if (outcome.reproduced()) {
    if (!quiet && outcome.state_hashes() > 0)
      std::printf("  reproduced  bit for bit: %zu datasets, state_hash equal at all %lld physics ticks\n",
                  outcome.comparison->datasets.size(), static_cast<long long>(outcome.state_hashes()));
    else if (!quiet)
      std::printf("  reproduced  bit for bit: %zu datasets (the recording keeps no /physics state_hash)\n",
                  outcome.comparison->datasets.size());
  } else {
    const recordings::CompareResult& c = *outcome.comparison;
    const recordings::DatasetResult& d = c.datasets.front();   // the first to part
    const recordings::ElementPoint& p = *d.first;
    const std::string component = d.components.size() > 1 ? " " + d.components[p.component] : "";
    std::printf("  %s %s tick %lld (t = %.9g s): %s%s%s %s%s (%.17g, replay %.17g); %lld of %zu datasets "
                "differ (graspsim compare %s %s)\n",
                plan.what_if ? "parts       from the recording at" : "DIFFERS     from the recording at",
                d.loop.c_str(), static_cast<long long>(p.tick), p.time, d.kind.c_str(),
                d.kind.empty() ? "" : " ", d.name.c_str(), d.quantity.c_str(), component.c_str(), p.a, p.b,
                static_cast<long long>(c.differing_datasets()), c.datasets.size(), trace.c_str(),
                result.trace_path.c_str());
  }

  const int failed = print_expectations(result, quiet);
  if (!result.trace_error.empty()) return kExitTraceFault;
  if (result.interrupted) return exit_interrupted(signal);
  if (!result.error.empty()) return kExitBadInput;
  if (!plan.what_if && !outcome.reproduced()) return kExitFailed;
  return failed ? kExitFailed : kExitOk;
}

}  // namespace graspsim::cli
