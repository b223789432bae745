// `graspsim run SCENARIO.lua`: its command table, its checks, the run, its report.
#include "cli/run.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "app/devices.hpp"
#include "app/output_file.hpp"
#include "app/pacer.hpp"
#include "app/run.hpp"
#include "app/run_budget.hpp"
#include "app/run_trace.hpp"
#include "app/sweep_row.hpp"
#include "cli/live.hpp"
#include "cli/options.hpp"
#include "cli/report.hpp"
#include "cli/stop.hpp"
#include "graspsim/recordings/record_selection.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::cli {
namespace {

constexpr const char* kRunUsage =
    "usage: graspsim run SCENARIO.lua [--out FILE.h5] [--duration S] [--set NAME=VALUE]...\n"
    "                [--device FINGER=SPEC]... [--jitter A [--jitter-seed N]] [--refuse-unstable]\n"
    "                [--no-trace | --record LOOP[:EVERY],...] [--compress N] [--summary FILE]\n"
    "                [--pace [--stall-timeout S] [--lag-limit S]]\n"
    "                [--view [--port N] [--open] | --no-view] [--quiet]\n";

constexpr const char* kHelp =
    "graspsim: a deterministic multi-rate simulator of multi-finger haptic grasping\n"
    "(after Melder, Harwin & Sharkey: god-objects with friction cones, residual force and\n"
    "torque, penalty object contact).\n"
    "\n"
    "usage: graspsim run SCENARIO.lua [options]\n"
    "\n"
    "Runs a Lua scenario to its end, writes every tick of every loop (servo, haptic, physics)\n"
    "to an HDF5 trace (or what --record chooses, or nothing with --no-trace), and checks the\n"
    "scenario's expectations.\n"
    "\n"
    "options:\n"
    "  --out FILE.h5        trace file (default: <scenario name>.h5 in this directory, any\n"
    "                       byte of the name outside [A-Za-z0-9_.-] made '_')\n"
    "  --duration S         simulated seconds, overriding the scenario's duration\n"
    "  --set NAME=VALUE     override a scenario value, e.g. --set rates.physics=500,\n"
    "                       --set objects.box.mass=0.5, --set fingers.thumb.stiffness=600,\n"
    "                       --set gravity=0,0,-1.62, or a param() the scenario declares\n"
    "  --device FINGER=SPEC drive FINGER by SPEC instead of the scenario's default device\n"
    "                       (repeatable): scripted, replay:TRACE.h5 (that finger's recorded\n"
    "                       hip and gimbal), sim-phantom[:MODEL], udp:HOST:PORT, phantom:NAME.\n"
    "                       With udp or phantom the run is paced in real time at the servo\n"
    "                       rate; every non-scripted device's samples go to /devices/FINGER\n"
    "  --jitter A           move every waypoint of every finger's trajectory by its own\n"
    "                       random offset, each of x, y, z uniform in [-A, A) m (A >= 0); a\n"
    "                       trajectory given as a function (a feedback controller) is moved\n"
    "                       by one constant offset per finger. The offsets go to the trace's\n"
    "                       root attributes (jitter_amplitude, jitter_seed, jitter_offsets),\n"
    "                       and a replay uses them again. Example: --jitter 0.5e-3\n"
    "  --jitter-seed N      the jitter's seed, an integer 0 to 2^63 - 1 (default 0): the same\n"
    "                       seed gives the same offsets on every machine\n"
    "  --compress N         deflate the trace at level N (1..9; default none)\n"
    "  --no-trace           write no trace at all (no file, no writer thread); the summary\n"
    "                       and the expectations are as with one, and set the exit status\n"
    "  --record LOOP[:EVERY],...\n"
    "                       record only these loops (servo, haptic, physics, devices,\n"
    "                       contacts), each at every EVERY-th tick of its own loop (default\n"
    "                       1; contacts: of the physics loop), e.g. --record physics or\n"
    "                       --record physics,servo:10; default: every loop at every tick but\n"
    "                       contacts (every contact point of the bodies with its force, a\n"
    "                       row per point: servo,haptic,physics,devices,contacts adds it).\n"
    "                       Written to the trace's root attribute `record`;\n"
    "                       `graspsim replay` needs servo (and devices) at every tick\n"
    "  --refuse-unstable    stop the run at the first unstable mode the stability check\n"
    "                       finds (as the scenario field stability = \"refuse\"), exit 2;\n"
    "                       without it each one is a warning on stderr, with its time\n"
    "  --pace               pace the run in real time at the servo rate, as a udp or phantom\n"
    "                       device does, with simulated devices too (a rehearsal of a session:\n"
    "                       the same deadlines, stall and lag limits and overrun counts)\n"
    "  --stall-timeout S    a rehearsal's stall limit instead of 0.02 s (with --pace and\n"
    "                       simulated devices only: a hand on a real device is always released\n"
    "                       after 20 ms without a fresh force); for a machine that cannot keep\n"
    "                       20 ms (a loaded VM), so that the rehearsal runs on and counts its gaps\n"
    "  --lag-limit S        the same for the lag limit, instead of 0.1 s\n"
    "  --view               serve a live 3D view of the run on 127.0.0.1 while it goes (the\n"
    "                       page of `graspsim view`, fed about 60 times a second; the run never\n"
    "                       waits for it, the trace is the same); prints its URL. On by default\n"
    "                       in a paced run (a hand on a device) started from a terminal, where\n"
    "                       the default port being taken means any free one\n"
    "  --port N             the live view's port (default 8717; 0: any free port)\n"
    "  --open               open the live view with xdg-open as well\n"
    "  --no-view            no live view in a paced run\n"
    "  --quiet              print only errors and failed expectations\n"
    "  --summary FILE       also write each expectation checked as a line of FILE,\n"
    "                       PASS|FAIL<tab>what<tab>measured (tab, newline, backslash as \\t \\n \\\\;\n"
    "                       what `graspsim sweep` reads)\n"
    "  -h, --help           this help\n"
    "  --version            the build's version\n"
    "\n"
    "stability: before the run and whenever the contact set changes, the check analyses the\n"
    "one-step map of every body and group of touching bodies on all its springs (fingers,\n"
    "floor, other bodies) under the scheme in use, and warns of a mode that grows from one\n"
    "physics step to the next, naming its motion, its springs and the rate that holds it.\n"
    "\n"
    "exit status: 0 every expectation held, 1 an expectation failed, 2 bad input (arguments,\n"
    "scenario, output path, a device that cannot be opened or a sample out of its workspace,\n"
    "an error in the script while it ran, a refused unstable mode, or a blow-up: bodies no\n"
    "finger touches gaining energy), 3 the trace could not be written to its end (a full\n"
    "disk: it keeps every tick up to its last flush, marked \"error: ...\"), 128 + the signal\n"
    "when stopped by SIGINT (130), SIGHUP (129) or SIGTERM (143).\n"
    "The trace is written as FILE.h5.partial, locked (a second run on the same output refuses),\n"
    "and renamed to FILE.h5 when the run ends, complete or marked: an earlier FILE.h5 is replaced\n"
    "only then. A run that stops early keeps its trace, with root attribute status = \"error: ...\";\n"
    "a device that cannot be opened at the start writes nothing. The output may not be an input\n"
    "(the scenario, a mesh file, a replay recording), nor a link to one, nor anything but a\n"
    "regular file (a device such as /dev/null, a FIFO, a socket, a directory): --no-trace\n"
    "writes no trace.\n"
    "A run killed outright leaves FILE.h5.partial, status \"running\", with every tick up to\n"
    "its last flush but one (less than 0.25 s of simulated time lost): h5py opens it with\n"
    "swmr=True; after `graspsim repair FILE.h5.partial` (see `graspsim repair --help`) every\n"
    "HDF5 tool does.\n"
    "\n"
    "usage: graspsim sweep SCENARIO.lua --grid NAME=V1,V2,... --out DIR [options]\n"
    "       (graspsim sweep --help for more)\n"
    "\n"
    "Runs a scenario over the cross product of --set values (and jitter seeds), locally in\n"
    "parallel or as a Slurm job array, into one summary table (CSV, HDF5) and a plot.\n"
    "\n"
    "usage: graspsim replay TRACE.h5 [options]   (graspsim replay --help for more)\n"
    "\n"
    "Reruns a trace's scenario with every finger fed from its recorded device samples; the\n"
    "new trace equals the recording bit for bit, or, with --set, shows where 'what if' parts.\n"
    "\n"
    "usage: graspsim compare A.h5 B.h5 [options]   (graspsim compare --help for more)\n"
    "\n"
    "Compares two traces tick by tick and names the first tick, time, quantity, object or\n"
    "finger and component where they part. Exit status 0 same, 1 different, 2 bad input.\n"
    "\n"
    "usage: graspsim view TRACE.h5 [B.h5] [--port N] [--open]   (graspsim view --help for more)\n"
    "\n"
    "Shows a trace in 3D in the browser, served on 127.0.0.1 until Ctrl-C.\n";


// What the command line asked for.
struct RunArgs {
  std::string scenario, out, summary;   // summary: --summary FILE, the expectations one a line
  scripting::LoadOptions load;
  long long compression = 0;
  bool quiet = false, refuse_unstable = false, no_trace = false, pace = false;
  double stall_timeout = 0.0, lag_limit = 0.0;   // s: a rehearsal's own limits (0: the defaults)
  bool jitter_seed_given = false, record_given = false;
  std::optional<recordings::RecordSelection> record;
  std::vector<std::string> devices;   // --device FINGER=SPEC
  LiveOptions live;
};

// A decimal integer from 0 to 2^63 - 1 (the trace stores it as int64), nothing else.
bool parse_seed(const std::string& text, std::uint64_t& out) {
  if (text.empty() || text.size() > 19 || text.find_first_not_of("0123456789") != std::string::npos) return false;
  out = std::strtoull(text.c_str(), nullptr, 10);
  return out <= static_cast<std::uint64_t>(INT64_MAX);
}

Option record_option(RunArgs& a) {
  return {"--record", "LOOP[:EVERY],... (loops: servo, haptic, physics, devices, contacts)",
          [&a](const std::string& v, std::string& why) {
            if (a.record_given) {
              why = "--record given twice: name every loop in one, e.g. --record physics,servo:10";
              return false;
            }
            try {
              a.record = recordings::RecordSelection::parse(v);
            } catch (const std::invalid_argument& e) {
              why = "--record " + v + ": " + e.what();
              return false;
            }
            return a.record_given = true;
          }};
}

CommandLine run_line(RunArgs& a) {
  CommandLine line{"run", kRunUsage, kHelp, {}, {}};
  line.options.push_back(text("--out", "a file name", a.out));
  line.options.push_back({"--duration", "a positive number of seconds", [&a](const std::string& v, std::string&) {
                            double d = 0.0;
                            if (!parse_number(v, d) || !(d > 0.0)) return false;
                            a.load.sets.push_back("duration=" + v);
                            return true;
                          },
                          true});
  line.options.push_back(set_option(a.load.sets));
  line.options.push_back(texts("--device", "FINGER=SPEC", a.devices));
  line.options.push_back(number("--jitter", "an amplitude in m, a number >= 0", a.load.jitter.amplitude,
                                [](double x) { return x >= 0.0; }));
  line.options.push_back({"--jitter-seed", "an integer from 0 to 2^63 - 1", [&a](const std::string& v, std::string&) {
                            return a.jitter_seed_given = parse_seed(v, a.load.jitter.seed);
                          },
                          true});
  line.options.push_back(count("--compress", "a level from 1 to 9", 1, 9, a.compression));
  line.options.push_back(flag("--no-trace", a.no_trace));
  line.options.push_back(record_option(a));
  line.options.push_back(flag("--refuse-unstable", a.refuse_unstable));
  line.options.push_back(flag("--pace", a.pace));
  // Up to a day (a run's longest duration): the pacer holds them in integer ns.
  const auto limit = [](double s) { return s > 0.0 && s <= 86400.0; };
  line.options.push_back(number("--stall-timeout", "a time in s, more than 0 and at most 86400", a.stall_timeout, limit));
  line.options.push_back(number("--lag-limit", "a time in s, more than 0 and at most 86400", a.lag_limit, limit));
  line.options.push_back(flag("--quiet", a.quiet));
  line.options.push_back(text("--summary", "a file name", a.summary));
  for (Option& o : live_options(a.live)) line.options.push_back(std::move(o));
  line.operand = [&a](const std::string& v) -> std::string {
    if (!a.scenario.empty()) return "one scenario at a time (got '" + a.scenario + "' and '" + v + "')";
    a.scenario = v;
    return "";
  };
  return line;
}

// What the command line may not ask for together: "" when fine.
std::string check_combinations(const RunArgs& a) {
  if ((a.stall_timeout > 0.0 || a.lag_limit > 0.0) && !a.pace)
    return std::string(a.stall_timeout > 0.0 ? "--stall-timeout" : "--lag-limit") +
           " is a limit of a rehearsal: it needs --pace";
  if (a.jitter_seed_given && !(a.load.jitter.amplitude > 0.0))
    return "--jitter-seed needs --jitter A with A > 0 (without an amplitude nothing is drawn)";
  if (a.no_trace && (a.record || !a.out.empty() || a.compression != 0))
    return std::string("--no-trace writes no trace, so it takes no ") +
           (a.record ? "--record" : !a.out.empty() ? "--out" : "--compress");
  return "";
}

// The output paths, checked before anything is loaded or written: "" when fine.
std::string check_outputs(const RunArgs& a) {
  // Only a regular file is replaced: a device, FIFO, socket or directory at an output path is
  // refused before anything runs (the run's claim on its trace checks it again).
  try {
    if (!a.out.empty()) app::refuse_unreplaceable(a.out, {});
    if (!a.summary.empty()) app::refuse_unreplaceable(a.summary, {"--summary", "leave out --summary to write none"});
  } catch (const app::OutputError& e) {
    return e.what();
  }
  return "";
}

// The run's options from the command line and the devices' plan; a pacer when a device is real
// or --pace asks (on `steady`).
app::RunOptions run_options(const RunArgs& a, const app::DevicePlan& plan, const app::DeviceRegistry& registry,
                            const scripting::Scenario& scenario) {
  app::RunOptions options;
  options.out = a.out;
  options.inputs = plan.files;
  options.trace.compression = static_cast<int>(a.compression);
  options.trace.write = !a.no_trace;
  if (a.record) options.trace.record = *a.record;
  options.overrides = a.load.sets;
  options.stop.interrupt = &stop_flags().interrupt;
  options.stop.signal = &stop_flags().signal;
  options.devices.record = plan.recorded();
  options.devices.script_alongside = plan.script_alongside;
  // Devices are built when the run starts (run_scenario), so that every one built is released
  // however the run ends; a device that cannot be built ends the run with its error (exit 2).
  options.devices.make = [&plan, &registry, &scenario](std::size_t f) {
    return app::make_device(plan, registry, scenario, f);
  };
  options.report.refuse_unstable = a.refuse_unstable;
  return options;
}

// The summary may be none of the run's inputs, nor its trace; its partial is never a file
// already there. "" when fine.
std::string check_summary(const RunArgs& a, const scripting::Scenario& scenario, const app::RunOptions& options) {
  if (a.summary.empty()) return "";
  std::vector<app::InputFile> inputs = app::run_inputs(scenario, options);
  if (!a.no_trace) {
    const std::string trace = a.out.empty() ? app::default_trace_name(scenario.name()) : a.out;
    inputs.push_back({trace, "the trace"});
    inputs.push_back({app::partial_name(trace), "the trace"});
  }
  try {
    app::refuse_input_as_output(a.summary, inputs, "--summary");
  } catch (const app::OutputError& e) {
    return e.what();
  }
  std::error_code ec;
  if (std::filesystem::symlink_status(a.summary + ".partial", ec).type() != std::filesystem::file_type::not_found)
    return "--summary " + a.summary + " is written as " + a.summary + ".partial, and a file of that name is "
           "there: move it away (it is not written over)";
  return "";
}

// The progress line on a terminal, and each stability warning as it is found (the progress
// line, if any, cleared first).
void report_as_it_goes(app::RunOptions& options, bool tty) {
  if (tty) {
    options.report.progress = [](double t, double duration) {
      std::fprintf(stderr, "\r  running: %5.1f%%  t = %.2f of %.2f s", 100.0 * t / duration, t, duration);
      std::fflush(stderr);
    };
  }
  options.report.on_warning = [tty](const std::string& w) {
    if (tty) std::fprintf(stderr, "\r%60s\r", "");
    std::cerr << "graspsim: warning: " << w << "\n";
  };
}

std::string human_bytes(std::uintmax_t n) {
  char buf[32];
  if (n >= 1024 * 1024) std::snprintf(buf, sizeof buf, "%.1f MB", n / (1024.0 * 1024.0));
  else std::snprintf(buf, sizeof buf, "%.1f kB", n / 1024.0);
  return buf;
}

// The summary of what ran: rates, ticks, wall time, the trace, jitter and pacing.
void print_summary(const RunArgs& a, const scripting::Scenario& scenario, const app::RunOptions& options,
                   const app::RunResult& result, bool paced) {
  const auto& model = scenario.model();
  std::error_code ec;
  const auto size = std::filesystem::file_size(result.trace_path, ec);
  std::printf("graspsim %s: %s\n", scenario.name().c_str(), scenario.path().c_str());
  std::printf("  rates       %d / %d / %d Hz (servo / haptic / physics)\n", model.rates.servo, model.rates.haptic,
              model.rates.physics);
  std::printf("  simulated   %.3f s: %lld servo, %lld haptic, %lld physics ticks\n", result.simulated,
              static_cast<long long>(result.servo_ticks), static_cast<long long>(result.haptic_ticks),
              static_cast<long long>(result.physics_ticks));
  std::printf("  wall time   %.3g s (%.0fx real time)\n", result.wall,
              result.wall > 0 ? result.simulated / result.wall : 0.0);
  if (a.no_trace) std::printf("  trace       none (--no-trace)\n");
  else std::printf("  trace       %s (%s)%s\n", result.trace_path.c_str(), ec ? "?" : human_bytes(size).c_str(),
                   options.trace.record.everything() ? "" : (", record " + options.trace.record.text()).c_str());
  if (scenario.jitter().amplitude > 0.0)
    std::printf("  jitter      waypoints moved by up to %g m per axis, seed %llu (trace: jitter_offsets)\n",
                scenario.jitter().amplitude, static_cast<unsigned long long>(scenario.jitter().seed));
  if (paced) std::printf("  pacing      %s%s\n", result.pacing.c_str(), options.pacing.realtime ? ", SCHED_FIFO" : "");
}

// What the run ended with: the summary, the error, the expectations, the --summary file; the
// exit status.
int report(const RunArgs& a, const scripting::Scenario& scenario, const app::RunOptions& options,
           const app::RunResult& result, bool paced) {
  if (!a.quiet) print_summary(a, scenario, options, result, paced);
  if (!result.trace_error.empty()) {
    std::fprintf(stderr, "graspsim: the trace could not be written to its end: %s\n", result.trace_error.c_str());
  } else if (!result.error.empty()) {
    std::fprintf(stderr, "graspsim: the run stopped early: %s\n%s", result.error.c_str(),
                 a.no_trace ? "" : "  (the trace keeps every tick up to there)\n");
  }
  const int failed = print_expectations(result, a.quiet);
  // A summary that cannot be written is an output fault, as a trace that cannot: exit 3, so that
  // a sweep records the run as an error instead of a pass with no expectation read.
  bool summary_fault = false;
  if (!a.summary.empty()) {
    const std::string e = app::sweep::write_summary(a.summary, app::sweep::summary_text(result.expectations));
    if (!e.empty()) {
      std::fprintf(stderr, "graspsim: --summary: %s\n", e.c_str());
      summary_fault = true;
    }
  }
  if (!result.trace_error.empty() || summary_fault) return kExitTraceFault;
  if (result.interrupted) return exit_interrupted(&stop_flags().signal);
  if (!result.error.empty()) return kExitBadInput;
  if (!a.quiet) {
    if (failed) std::printf("  result      %d of %zu expectations failed\n", failed, result.expectations.size());
    else std::printf("  result      all %zu expectations met\n", result.expectations.size());
  }
  return failed ? kExitFailed : kExitOk;
}

int bad_input(const std::string& message) {
  std::cerr << "graspsim: " << message << "\n";
  return kExitBadInput;
}

// Runs the scenario once its arguments are checked: devices planned, options built, the run
// fitted to the machine, the live view started, then the run and its report.
int run_checked(const RunArgs& a) {
  std::optional<scripting::Scenario> scenario;
  try {
    scenario.emplace(scripting::Scenario::load(a.scenario, a.load));
  } catch (const scripting::ScenarioError& e) {
    return bad_input(e.what());
  }
  // Each finger's device: the scenario's default, then --device; bad specs exit 2 before any
  // device opens or any trace is written.
  const app::DeviceRegistry registry = app::default_registry();
  app::DevicePlan plan;
  try {
    plan = app::plan_devices(*scenario, a.devices, registry);
  } catch (const app::DeviceError& e) {
    return bad_input(e.what());
  }
  app::RunOptions options = run_options(a, plan, registry, *scenario);
  // A hand on a real device: pace the loop in real time on a SCHED_FIFO thread if allowed.
  app::SteadyClock steady;
  std::optional<app::Pacer> pacer;
  if (plan.any_real() || a.pace) {
    // A rehearsal's own limits; never with a hand on a real device.
    if (plan.any_real() && (a.stall_timeout > 0.0 || a.lag_limit > 0.0))
      return bad_input(std::string(a.stall_timeout > 0.0 ? "--stall-timeout" : "--lag-limit") +
                       " is for a rehearsal (--pace with simulated devices): a device with a hand on it is released "
                       "after 20 ms without a fresh force, and when the loop falls 100 ms behind");
    pacer.emplace(steady, scenario->model().rates.servo, a.stall_timeout > 0.0 ? a.stall_timeout : app::kStallTimeout,
                  a.lag_limit > 0.0 ? a.lag_limit : app::kLagLimit);
    options.pacing.pacer = &*pacer;
    const std::string why = app::probe_realtime();
    options.pacing.realtime = why.empty();
    if (!why.empty()) std::cerr << "graspsim: warning: " << why << "\n";
  }
  const bool tty = isatty(STDERR_FILENO) && !a.quiet && !pacer;
  report_as_it_goes(options, tty);
  handle_stop_signals();
  if (const std::string e = check_summary(a, *scenario, options); !e.empty()) return bad_input(e);
  // A run that will not fit (memory for its trace buffers, disk for its trace) is refused
  // before anything is written (README.md "Run length and rates").
  std::string size_warning;
  if (const std::string too_big = app::check_run_fits(*scenario, options, &size_warning); !too_big.empty())
    return bad_input(too_big);
  if (!size_warning.empty()) std::cerr << "graspsim: warning: " << size_warning << "\n";
  // The live view, asked for, or of a paced run started from a terminal (a person at a device;
  // a script or a test that paces a run gets none unless it asks): started last, so that nothing
  // above waits for it.
  const bool view_by_default = pacer.has_value() && isatty(STDOUT_FILENO) == 1;
  if (const std::string e = check_live_options(a.live, view_by_default); !e.empty()) return bad_input(e);
  LiveSession live_view;
  if (const std::string e = live_view.start(*scenario, a.live, view_by_default, options); !e.empty())
    return bad_input(e);
  app::RunResult result;
  try {
    result = app::run_scenario(*scenario, options);
  } catch (const app::OutputError& e) {
    return bad_input(e.what());
  } catch (const recordings::TraceError& e) {
    return bad_input(std::string("cannot write the trace: ") + e.what());
  }
  live_view.end(result, a.no_trace || result.not_started ? "" : result.trace_path);
  if (tty) std::fprintf(stderr, "\r%60s\r", "");
  if (result.not_started)
    return bad_input("the run could not start: " + result.error +
                     "\n  (nothing was written; a file already at the output path is as it was)");
  return report(a, *scenario, options, result, pacer.has_value());
}

}  // namespace

const char* run_help() { return kHelp; }

int run_command(const std::vector<std::string>& args) {
  RunArgs a;
  const CommandLine line = run_line(a);
  switch (parse_command_line(line, args)) {
    case Parsed::kHelp: return kExitOk;
    case Parsed::kError: return kExitBadInput;
    case Parsed::kGo: break;
  }
  if (a.scenario.empty()) return usage_error(line, "run needs a scenario file");
  if (const std::string e = check_combinations(a); !e.empty()) return usage_error(line, e);
  if (const std::string e = check_outputs(a); !e.empty()) return bad_input(e);
  return run_checked(a);
}

}  // namespace graspsim::cli
