// The graspsim command line: run a scenario, write its trace, report its expectations.
#include <atomic>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <cmath>
#include <iostream>
#include <optional>
#include <string>
#include <unistd.h>
#include <vector>

#include "app/compare.hpp"
#include "app/devices.hpp"
#include "app/pacer.hpp"
#include "app/run.hpp"
#include "app/run_budget.hpp"
#include "app/run_trace.hpp"
#include "app/sweep_row.hpp"
#include "cli/repair.hpp"
#include "cli/replay.hpp"
#include "cli/live.hpp"
#include "cli/sweep.hpp"
#include "cli/view.hpp"
#include "cli/report.hpp"
#include "graspsim_version.hpp"
#include "graspsim/recordings/record_selection.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "graspsim/scripting/scenario.hpp"


namespace {

// Exit codes, as documented in --help.
using graspsim::cli::kExitBadInput;
using graspsim::cli::kExitFailed;
using graspsim::cli::kExitOk;
using graspsim::cli::kExitTraceFault;

constexpr const char* kUsage =
    "usage: graspsim run SCENARIO.lua [--out FILE.h5] [--duration S] [--set NAME=VALUE]...\n"
    "                [--device FINGER=SPEC]... [--jitter A [--jitter-seed N]] [--refuse-unstable]\n"
    "                [--no-trace | --record LOOP[:EVERY],...] [--summary FILE] [--pace]\n"
    "                [--view [--port N] [--open] | --no-view]\n"
    "       graspsim sweep SCENARIO.lua --grid NAME=V1,V2,... [--grid ...] [--seeds N] [--jobs N]\n"
    "                --out DIR [--keep-traces] [--slurm] [--resume]\n"
    "       graspsim replay TRACE.h5 [--out NEW.h5] [--set NAME=VALUE]...\n"
    "       graspsim repair TRACE.h5\n"
    "       graspsim view TRACE.h5 [B.h5] [--port N] [--open]\n"
    "       graspsim compare A.h5 B.h5 [--atol X] [--rtol X] [--tol PATTERN=ATOL[,RTOL]]...\n"
    "                [--bitwise] [--attributes] [--all-ticks] [--all] [--only LOOP]... [--json] [--view]\n"
    "       graspsim --help | --version\n";

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

constexpr const char* kCompareHelp =
    "usage: graspsim compare A.h5 B.h5 [options]\n"
    "\n"
    "Compares two graspsim traces. The rows of each loop (/servo, /haptic, /physics) are\n"
    "aligned by their tick column, not by row index, so a shorter, cut or decimated trace\n"
    "still compares where ticks match (ticks in one trace only are counted and reported).\n"
    "Every dataset is compared element by element; for each one that differs it reports the\n"
    "first tick and time where the tolerance is exceeded, the object or finger, the quantity\n"
    "and component (x/y/z, w/x/y/z), the two values there, and the largest absolute and\n"
    "relative errors. Differing datasets are listed by first divergence.\n"
    "\n"
    "An element pair (a, b) is within tolerance when |a - b| <= atol + rtol * max(|a|, |b|);\n"
    "NaN equals NaN, an infinity only the same infinity; integer columns (contact state, body\n"
    "index, counts) are compared as integers. The default tolerance is 0: equal values.\n"
    "\n"
    "options:\n"
    "  --atol X             absolute tolerance for every dataset (default 0)\n"
    "  --rtol X             relative tolerance for every dataset (default 0)\n"
    "  --tol PATTERN=ATOL[,RTOL]\n"
    "                       tolerance for the datasets whose path matches PATTERN, instead of\n"
    "                       --atol/--rtol (RTOL defaults to 0). Paths look like\n"
    "                       physics/objects/box/position or haptic/fingers/thumb/force; PATTERN\n"
    "                       is a glob where * also crosses '/': 'servo/*', '*/position',\n"
    "                       'physics/objects/box/*'. Repeatable; the last matching one wins; a\n"
    "                       pattern that matches no dataset is an error.\n"
    "  --bitwise            equal only if the stored bits are equal (NaN equals a NaN with the\n"
    "                       same bits; -0 differs from 0); no tolerances\n"
    "  --attributes         count differing root attributes (scenario source, parameters,\n"
    "                       seed, version, compiler, status ...) as differences; by default\n"
    "                       they are only notes, since wall-clock, status and version\n"
    "                       legitimately differ. Rates and schema version must always match.\n"
    "  --all-ticks          ticks present in one trace only count as differences\n"
    "  --all                also list the datasets within tolerance, with their largest error\n"
    "  --only LOOP[,LOOP...]\n"
    "                       compare only these loops (repeatable): servo, haptic, physics,\n"
    "                       devices (every /devices/FINGER) or devices/FINGER; a loop neither\n"
    "                       trace holds is an error\n"
    "  --json               one JSON object on stdout instead of the table (fields:\n"
    "                       recordings/README.md, \"Comparing traces\")\n"
    "  --view               then show both runs in the browser, as `graspsim view A.h5 B.h5`\n"
    "                       does (B ghosted, the first divergence marked), until Ctrl-C; exit\n"
    "                       status then that of the view. The mark is the first divergence at\n"
    "                       tolerance 0 over every loop: no --atol, --rtol, --tol, --bitwise\n"
    "                       or --only with it\n"
    "\n"
    "Tables one trace holds and the other does not (/devices/FINGER of a device session\n"
    "against its scripted run, a loop one trace did not --record) are listed as \"only in A\"\n"
    "or \"only in B\" and not compared; the loops both hold are. Ticks one trace did not keep\n"
    "(--record LOOP:EVERY) are counted as ticks in one trace only.\n"
    "\n"
    "exit status: 0 same: every compared element within tolerance (tables in one trace only do\n"
    "not count; ticks in one trace only count only with --all-ticks, root attributes only with\n"
    "--attributes); 1 different: some element outside the tolerance (or a counted tick or\n"
    "attribute); 2 unusable input: a missing, truncated or non-HDF5 file, not a graspsim trace,\n"
    "schema versions or rates that differ, no loop both traces hold, a loop a trace records\n"
    "missing or not a table (a /physics that is absent or a scalar), a column of a shared loop\n"
    "in one trace only, different shapes, bad options (an --only loop neither trace holds).\n"
    "\n"
    "Why not h5diff: with the box's height changed by 1e-9 m at one physics tick of the\n"
    "two-finger lift, `h5diff -r A.h5 B.h5` prints, between blocks for every other dataset,\n"
    "  dataset: </physics/objects/box/position> and </physics/objects/box/position>\n"
    "  [ 60 2 ]          0.03019         0.03019         1e-09\n"
    "an element index (row 60, column 2) and values cut to 4 digits; it pairs rows by index,\n"
    "so a decimated trace differs everywhere. graspsim compare prints\n"
    "  DIFFERENT: 1 of 36 datasets exceed the tolerance; first at physics tick 3600\n"
    "  (t = 1.2 s): object box position z\n"
    "with both values in full (0.030189999999999998, 0.030190000999999998), and lists every\n"
    "differing dataset by the tick where it first parts, so a cause comes before its\n"
    "consequences.\n"
    "\n"
    "example: graspsim compare golden.h5 new.h5 --rtol 1e-12 --tol 'servo/*=1e-9'\n";

std::atomic<bool> g_interrupt{false};
std::atomic<int> g_signal{0};   // the signal that set g_interrupt
extern "C" void on_stop_signal(int signal) {
  g_signal.store(signal);
  g_interrupt.store(true);
}

// SIGINT, SIGTERM and SIGHUP end a run at its next check, its trace closed and marked (exit
// 128 + signal). SIGXFSZ (a file-size limit, `ulimit -f`) is ignored, so that the write fails
// with EFBIG and ends the run like a full disk instead of killing it.
void handle_stop_signals() {
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) std::signal(s, on_stop_signal);
  std::signal(SIGXFSZ, SIG_IGN);
}

int bad_input(const std::string& message) {
  std::cerr << "graspsim: " << message << "\n";
  return kExitBadInput;
}

std::string human_bytes(std::uintmax_t n) {
  char buf[32];
  if (n >= 1024 * 1024) std::snprintf(buf, sizeof buf, "%.1f MB", n / (1024.0 * 1024.0));
  else std::snprintf(buf, sizeof buf, "%.1f kB", n / 1024.0);
  return buf;
}

bool parse_number(const std::string& text, double& out) {
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return !text.empty() && end && *end == '\0' && std::isfinite(out);
}

// A decimal integer from 0 to 2^63 - 1 (the trace stores it as int64), nothing else.
bool parse_seed(const std::string& text, std::uint64_t& out) {
  if (text.empty() || text.size() > 19 || text.find_first_not_of("0123456789") != std::string::npos) return false;
  out = std::strtoull(text.c_str(), nullptr, 10);
  return out <= static_cast<std::uint64_t>(INT64_MAX);
}

int run_command(const std::vector<std::string>& args) {
  std::string scenario_path, out;
  graspsim::scripting::LoadOptions load;
  int compression = 0;
  bool quiet = false, refuse_unstable = false, no_trace = false, out_given = false, compress_given = false;
  std::optional<graspsim::recordings::RecordSelection> record;
  std::vector<std::string> device_options;
  std::string summary;   // --summary FILE: the expectations, one line each
  bool jitter_seed_given = false, pace = false;
  graspsim::cli::LiveOptions live;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const auto value = [&]() -> const std::string* {
      if (i + 1 >= args.size()) return nullptr;
      return &args[++i];
    };
    if (a == "-h" || a == "--help") {
      std::cout << kHelp;
      return kExitOk;
    } else if (a == "--device") {
      const std::string* v = value();
      if (!v || v->empty() || v->front() == '-')
        return bad_input("--device needs FINGER=SPEC" + (v ? " (got '" + *v + "')" : std::string()));
      device_options.push_back(*v);
    } else if (a == "--out") {
      const std::string* v = value();
      if (!v || v->empty() || v->front() == '-')
        return bad_input("--out needs a file name" + (v ? " (got '" + *v + "')" : std::string()));
      out = *v;
      out_given = true;
    } else if (a == "--no-trace") {
      no_trace = true;
    } else if (a == "--record") {
      if (record) return bad_input("--record given twice: name every loop in one, e.g. --record physics,servo:10");
      const std::string* v = value();
      if (!v || v->empty() || v->front() == '-')
        return bad_input("--record needs LOOP[:EVERY],... (loops: servo, haptic, physics, devices, contacts)" +
                         (v ? " (got '" + *v + "')" : std::string()));
      try {
        record = graspsim::recordings::RecordSelection::parse(*v);
      } catch (const std::invalid_argument& e) {
        return bad_input("--record " + *v + ": " + e.what());
      }
    } else if (a == "--duration") {
      const std::string* v = value();
      double d = 0.0;
      if (!v || !parse_number(*v, d) || !(d > 0.0))
        return bad_input("--duration needs a positive number of seconds" + (v ? " (got '" + *v + "')" : std::string()));
      load.sets.push_back("duration=" + *v);
    } else if (a == "--set") {
      const std::string* v = value();
      if (!v || v->find('=') == std::string::npos || v->front() == '=')
        return bad_input("--set needs NAME=VALUE" + (v ? " (got '" + *v + "')" : std::string()));
      load.sets.push_back(*v);
    } else if (a == "--jitter") {
      const std::string* v = value();
      if (!v || !parse_number(*v, load.jitter.amplitude) || !(load.jitter.amplitude >= 0.0))
        return bad_input("--jitter needs an amplitude in m, a number >= 0" + (v ? " (got '" + *v + "')" : std::string()));
    } else if (a == "--jitter-seed") {
      const std::string* v = value();
      if (!v || !parse_seed(*v, load.jitter.seed))
        return bad_input("--jitter-seed needs an integer from 0 to 2^63 - 1" + (v ? " (got '" + *v + "')" : std::string()));
      jitter_seed_given = true;
    } else if (a == "--compress") {
      const std::string* v = value();
      double level = 0.0;
      if (!v || !parse_number(*v, level) || level < 1 || level > 9 || level != std::floor(level))
        return bad_input("--compress needs a level from 1 to 9");
      compression = static_cast<int>(level);
      compress_given = true;
    } else if (a == "--quiet") {
      quiet = true;
    } else if (a == "--summary") {
      const std::string* v = value();
      if (!v || v->empty() || v->front() == '-')
        return bad_input("--summary needs a file name" + (v ? " (got '" + *v + "')" : std::string()));
      summary = *v;
    } else if (a == "--refuse-unstable") {
      refuse_unstable = true;
    } else if (a == "--pace") {
      pace = true;
    } else if (std::string error; graspsim::cli::parse_live_option(args, i, live, error)) {
      if (!error.empty()) return bad_input(error);
    } else if (a.rfind("-", 0) == 0) {
      return bad_input("unknown option '" + a + "'\n" + kUsage);
    } else if (scenario_path.empty()) {
      scenario_path = a;
    } else {
      return bad_input("one scenario at a time (got '" + scenario_path + "' and '" + a + "')");
    }
  }
  if (scenario_path.empty()) return bad_input(std::string("run needs a scenario file\n") + kUsage);
  if (jitter_seed_given && !(load.jitter.amplitude > 0.0))
    return bad_input("--jitter-seed needs --jitter A with A > 0 (without an amplitude nothing is drawn)");
  if (no_trace && (record || out_given || compress_given))
    return bad_input(std::string("--no-trace writes no trace, so it takes no ") +
                     (record ? "--record" : out_given ? "--out" : "--compress"));
  // Only a regular file is replaced: a device, FIFO, socket or directory at an output path is
  // refused before anything runs (the run's claim on its trace checks it again).
  try {
    if (out_given) graspsim::app::refuse_unreplaceable(out, {});
    if (!summary.empty()) graspsim::app::refuse_unreplaceable(summary, {"--summary", "leave out --summary to write none"});
  } catch (const graspsim::app::OutputError& e) {
    return bad_input(e.what());
  }

  std::optional<graspsim::scripting::Scenario> scenario;
  try {
    scenario.emplace(graspsim::scripting::Scenario::load(scenario_path, load));
  } catch (const graspsim::scripting::ScenarioError& e) {
    return bad_input(e.what());
  }

  // Each finger's device: the scenario's default, then --device; bad specs exit 2 before any
  // device opens or any trace is written.
  const graspsim::app::DeviceRegistry registry = graspsim::app::default_registry();
  graspsim::app::DevicePlan plan;
  try {
    plan = graspsim::app::plan_devices(*scenario, device_options, registry);
  } catch (const graspsim::app::DeviceError& e) {
    return bad_input(e.what());
  }

  graspsim::app::RunOptions options;
  options.out = out;
  options.inputs = plan.files;
  options.trace.compression = compression;
  options.trace.write = !no_trace;
  if (record) options.trace.record = *record;
  options.overrides = load.sets;
  options.stop.interrupt = &g_interrupt;
  options.stop.signal = &g_signal;
  options.devices.record = plan.recorded();
  options.devices.script_alongside = plan.script_alongside;
  // Devices are built when the run starts (run_scenario), so that every one built is released
  // however the run ends; a device that cannot be built ends the run with its error (exit 2).
  options.devices.make = [&](std::size_t f) { return graspsim::app::make_device(plan, registry, *scenario, f); };
  // A hand on a real device: pace the loop in real time on a SCHED_FIFO thread if allowed.
  graspsim::app::SteadyClock steady;
  std::optional<graspsim::app::Pacer> pacer;
  if (plan.any_real() || pace) {
    pacer.emplace(steady, scenario->model().rates.servo, graspsim::app::kStallTimeout);
    options.pacing.pacer = &*pacer;
    const std::string why = graspsim::app::probe_realtime();
    options.pacing.realtime = why.empty();
    if (!why.empty()) std::cerr << "graspsim: warning: " << why << "\n";
  }
  const bool tty = isatty(STDERR_FILENO) && !quiet && !pacer;
  if (tty) {
    options.report.progress = [](double t, double duration) {
      std::fprintf(stderr, "\r  running: %5.1f%%  t = %.2f of %.2f s", 100.0 * t / duration, t, duration);
      std::fflush(stderr);
    };
  }
  handle_stop_signals();
  options.report.refuse_unstable = refuse_unstable;
  // Each stability warning as it is found (the progress line, if any, is cleared first).
  options.report.on_warning = [tty](const std::string& w) {
    if (tty) std::fprintf(stderr, "\r%60s\r", "");
    std::cerr << "graspsim: warning: " << w << "\n";
  };

  // The summary may be none of the run's inputs, nor its trace; its partial is never a file
  // already there (checked before anything runs).
  if (!summary.empty()) {
    std::vector<graspsim::app::InputFile> inputs = graspsim::app::run_inputs(*scenario, options);
    if (!no_trace) {
      const std::string trace = out.empty() ? graspsim::app::default_trace_name(scenario->name()) : out;
      inputs.push_back({trace, "the trace"});
      inputs.push_back({graspsim::app::partial_name(trace), "the trace"});
    }
    try {
      graspsim::app::refuse_input_as_output(summary, inputs, "--summary");
    } catch (const graspsim::app::OutputError& e) {
      return bad_input(e.what());
    }
    std::error_code ec;
    if (std::filesystem::symlink_status(summary + ".partial", ec).type() != std::filesystem::file_type::not_found)
      return bad_input("--summary " + summary + " is written as " + summary + ".partial, and a file of that name is "
                       "there: move it away (it is not written over)");
  }

  // A run that will not fit (memory for its trace buffers, disk for its trace) is refused
  // before anything is written (README.md "Run length and rates").
  std::string size_warning;
  const std::string too_big = graspsim::app::check_run_fits(*scenario, options, &size_warning);
  if (!too_big.empty()) return bad_input(too_big);
  if (!size_warning.empty()) std::cerr << "graspsim: warning: " << size_warning << "\n";

  // The live view, asked for, or of a paced run started from a terminal (a person at a device;
  // a script or a test that paces a run gets none unless it asks): started last, so that nothing
  // above waits for it.
  const bool view_by_default = pacer.has_value() && isatty(STDOUT_FILENO) == 1;
  if (const std::string e = graspsim::cli::check_live_options(live, view_by_default); !e.empty()) return bad_input(e);
  graspsim::cli::LiveSession live_view;
  if (const std::string e = live_view.start(*scenario, live, view_by_default, options); !e.empty())
    return bad_input(e);

  graspsim::app::RunResult result;
  try {
    result = graspsim::app::run_scenario(*scenario, options);
  } catch (const graspsim::app::OutputError& e) {
    return bad_input(e.what());
  } catch (const graspsim::recordings::TraceError& e) {
    return bad_input(std::string("cannot write the trace: ") + e.what());
  }
  live_view.end(result, no_trace || result.not_started ? "" : result.trace_path);
  if (tty) std::fprintf(stderr, "\r%60s\r", "");
  if (result.not_started) {
    return bad_input("the run could not start: " + result.error +
                     "\n  (nothing was written; a file already at the output path is as it was)");
  }

  const auto& model = scenario->model();
  std::error_code ec;
  const auto size = std::filesystem::file_size(result.trace_path, ec);
  if (!quiet) {
    std::printf("graspsim %s: %s\n", scenario->name().c_str(), scenario->path().c_str());
    std::printf("  rates       %d / %d / %d Hz (servo / haptic / physics)\n", model.rates.servo,
                model.rates.haptic, model.rates.physics);
    std::printf("  simulated   %.3f s: %lld servo, %lld haptic, %lld physics ticks\n", result.simulated,
                static_cast<long long>(result.servo_ticks), static_cast<long long>(result.haptic_ticks),
                static_cast<long long>(result.physics_ticks));
    std::printf("  wall time   %.3g s (%.0fx real time)\n", result.wall,
                result.wall > 0 ? result.simulated / result.wall : 0.0);
    if (no_trace) std::printf("  trace       none (--no-trace)\n");
    else std::printf("  trace       %s (%s)%s\n", result.trace_path.c_str(), ec ? "?" : human_bytes(size).c_str(),
                     options.trace.record.everything() ? "" : (", record " + options.trace.record.text()).c_str());
    if (scenario->jitter().amplitude > 0.0)
      std::printf("  jitter      waypoints moved by up to %g m per axis, seed %llu (trace: jitter_offsets)\n",
                  scenario->jitter().amplitude, static_cast<unsigned long long>(scenario->jitter().seed));
    if (pacer) std::printf("  pacing      %s%s\n", result.pacing.c_str(), options.pacing.realtime ? ", SCHED_FIFO" : "");
  }
  if (!result.trace_error.empty()) {
    std::fprintf(stderr, "graspsim: the trace could not be written to its end: %s\n", result.trace_error.c_str());
  } else if (!result.error.empty()) {
    std::fprintf(stderr, "graspsim: the run stopped early: %s\n%s", result.error.c_str(),
                 no_trace ? "" : "  (the trace keeps every tick up to there)\n");
  }
  const int failed = graspsim::cli::print_expectations(result, quiet);
  // A summary that cannot be written is an output fault, as a trace that cannot: exit 3, so that
  // a sweep records the run as an error instead of a pass with no expectation read.
  bool summary_fault = false;
  if (!summary.empty()) {
    const std::string e = graspsim::app::sweep::write_summary(summary, graspsim::app::sweep::summary_text(result.expectations));
    if (!e.empty()) {
      std::fprintf(stderr, "graspsim: --summary: %s\n", e.c_str());
      summary_fault = true;
    }
  }
  if (!result.trace_error.empty() || summary_fault) return kExitTraceFault;
  if (result.interrupted) return graspsim::cli::exit_interrupted(&g_signal);
  if (!result.error.empty()) return kExitBadInput;
  if (!quiet) {
    if (failed) std::printf("  result      %d of %zu expectations failed\n", failed, result.expectations.size());
    else std::printf("  result      all %zu expectations met\n", result.expectations.size());
  }
  return failed ? kExitFailed : kExitOk;
}

// Parses "A,B" or "A" into two non-negative numbers (B = 0 when missing).
bool parse_tolerance(const std::string& text, graspsim::recordings::Tolerance& out) {
  const auto comma = text.find(',');
  out = {};
  if (!parse_number(text.substr(0, comma), out.atol) || out.atol < 0) return false;
  if (comma != std::string::npos && (!parse_number(text.substr(comma + 1), out.rtol) || out.rtol < 0))
    return false;
  return true;
}

int compare_command(const std::vector<std::string>& args) {
  namespace rec = graspsim::recordings;
  std::vector<std::string> files;
  rec::CompareOptions options;
  bool json = false, all = false, tolerances = false, view = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const auto value = [&]() -> const std::string* {
      if (i + 1 >= args.size()) return nullptr;
      return &args[++i];
    };
    if (a == "-h" || a == "--help") {
      std::cout << kCompareHelp;
      return kExitOk;
    } else if (a == "--atol" || a == "--rtol") {
      const std::string* v = value();
      double x = 0.0;
      if (!v || !parse_number(*v, x) || x < 0)
        return bad_input(a + " needs a number >= 0" + (v ? " (got '" + *v + "')" : std::string()));
      (a == "--atol" ? options.tolerance.atol : options.tolerance.rtol) = x;
      tolerances = true;
    } else if (a == "--tol") {
      const std::string* v = value();
      const auto eq = v ? v->rfind('=') : std::string::npos;
      rec::ToleranceRule rule;
      if (!v || eq == std::string::npos || eq == 0 || !parse_tolerance(v->substr(eq + 1), rule.tolerance))
        return bad_input("--tol needs PATTERN=ATOL or PATTERN=ATOL,RTOL with numbers >= 0" +
                         (v ? " (got '" + *v + "')" : std::string()));
      rule.pattern = v->substr(0, eq);
      options.rules.push_back(rule);
      tolerances = true;
    } else if (a == "--bitwise") {
      options.bitwise = true;
    } else if (a == "--attributes") {
      options.attributes = true;
    } else if (a == "--all-ticks") {
      options.all_ticks = true;
    } else if (a == "--all") {
      all = true;
    } else if (a == "--only") {
      // LOOP or LOOP,LOOP,...; repeatable. (Not a list of words up to the files: a loop and a
      // file name cannot be told apart.)
      const std::string* v = value();
      if (!v || v->empty() || v->front() == '-')
        return bad_input("--only needs a loop (servo, haptic, physics, devices or devices/<finger>)" +
                         (v ? " (got '" + *v + "')" : std::string()));
      for (std::size_t start = 0; start <= v->size();) {
        const std::size_t comma = std::min(v->find(',', start), v->size());
        const std::string loop = v->substr(start, comma - start);
        if (loop.empty()) return bad_input("--only " + *v + ": an empty loop name");
        options.only.push_back(loop);
        start = comma + 1;
      }
    } else if (a == "--json") {
      json = true;
    } else if (a == "--view") {
      view = true;
    } else if (a.rfind("-", 0) == 0) {
      return bad_input("unknown option '" + a + "'\n" + kUsage);
    } else {
      files.push_back(a);
    }
  }
  const auto input_error = [&](const std::string& message) {
    if (json) std::cout << graspsim::app::compare_error_json(message);
    return bad_input(message);
  };
  if (files.size() != 2)
    return input_error("compare needs two trace files (got " + std::to_string(files.size()) + ")\n" +
                       kUsage);
  if (options.bitwise && tolerances)
    return input_error("--bitwise compares exact bits: it takes no --atol, --rtol or --tol");
  if (view && (tolerances || options.bitwise || !options.only.empty()))
    return input_error("--view marks the first divergence at tolerance 0 over every loop: it takes no --atol, --rtol, "
                       "--tol, --bitwise or --only");
  rec::CompareResult result;
  try {
    result = rec::compare_traces(files[0], files[1], options);
    // Loops a trace records that are no table of it are never "the same": refused.
    for (const std::string& f : files)
      if (const std::string missing = graspsim::app::missing_loop_tables(f); !missing.empty()) return input_error(missing);
  } catch (const rec::TraceError& e) {
    return input_error(e.what());
  }
  std::cout << (json ? graspsim::app::compare_json(result) : graspsim::app::compare_table(result, all));
  if (view) {
    std::cout.flush();
    return graspsim::cli::view_command({files[0], files[1]});
  }
  return result.same() ? kExitOk : kExitFailed;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::cerr << kUsage << "Try 'graspsim --help'.\n";
    return kExitBadInput;
  }
  const std::string command = args.front();
  if (command == "-h" || command == "--help" || command == "help") {
    std::cout << kHelp;
    return kExitOk;
  }
  if (command == "--version") {
    std::cout << "graspsim " << GRASPSIM_VERSION << "\n";
    return kExitOk;
  }
  if (command == "run") return run_command({args.begin() + 1, args.end()});
  if (command == "replay") {
    handle_stop_signals();
    return graspsim::cli::replay_command({args.begin() + 1, args.end()}, &g_interrupt, &g_signal);
  }
  if (command == "sweep") return graspsim::cli::sweep_command({args.begin() + 1, args.end()});
  if (command == "sweep-task") return graspsim::cli::sweep_task_command({args.begin() + 1, args.end()});
  if (command == "repair") return graspsim::cli::repair_command({args.begin() + 1, args.end()});
  if (command == "compare") return compare_command({args.begin() + 1, args.end()});
  if (command == "view") return graspsim::cli::view_command({args.begin() + 1, args.end()});
  return bad_input("unknown command '" + command + "'\n" + kUsage + "Try 'graspsim --help'.");
}
