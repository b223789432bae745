// `graspsim sweep`: the cross product of --set values (times jitter seeds), each one child
// `graspsim run`, locally in parallel or as a Slurm job array; one summary table (README.md "Sweeps").
#include "cli/sweep.hpp"
#include "cli/sweep_slurm.hpp"

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

#include "app/output_file.hpp"
#include "app/sweep_exec.hpp"
#include "app/sweep_table.hpp"
#include "cli/options.hpp"
#include "cli/report.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::cli {
namespace {

namespace fs = std::filesystem;
using namespace app::sweep;

constexpr const char* kSweepHelp =
    "usage: graspsim sweep SCENARIO.lua --grid NAME=V1,V2,... [--grid ...] [--set NAME=VALUE]...\n"
    "                [--seeds N [--jitter A]] [--jobs N] --out DIR [--keep-traces] [--slurm] [--resume]\n"
    "\n"
    "Runs SCENARIO once for every combination of the --grid values (each given to the run as\n"
    "--set NAME=V), and with --seeds N once more for each seed 0 .. N-1 of jittered waypoints\n"
    "(--jitter A --jitter-seed S; A in m, default 0.5e-3). Each run is its own `graspsim run`\n"
    "process. Writes DIR/sweep.csv and DIR/sweep.h5 (one row per run: the grid values, the seed,\n"
    "status, exit status, wall time, every expectation's pass (1/0, -1 not checked) and measured\n"
    "text) and DIR/sweep.png (pass/fail over the first two grid axes); each run's output is in\n"
    "DIR/runs/. The runs are deterministic: the table, wall_s aside, is the same for any --jobs\n"
    "and on Slurm.\n"
    "\n"
    "options:\n"
    "  --grid NAME=V1,V2,...  a scenario field or param() and its values (repeatable; the first\n"
    "                       axis changes slowest); NAME=V1;V2 when a value holds commas\n"
    "  --set NAME=VALUE     an override for every run\n"
    "  --seeds N            N jitter seeds per grid point (1 .. 1000000)\n"
    "  --jitter A           the seeds' jitter amplitude in m (default 0.5e-3)\n"
    "  --jobs N             runs at once (default: the number of processors)\n"
    "  --out DIR            the sweep's folder (made if missing; one holding another sweep, or\n"
    "                       files and no sweep.plan, is refused; one holding this sweep needs\n"
    "                       --resume)\n"
    "  --keep-traces        each run writes DIR/runs/<run>.h5 (default: --no-trace)\n"
    "  --resume             keep the rows of finished runs in DIR and run only the others\n"
    "  --slurm              submit the runs as a Slurm job array (sbatch --array; sbatch's own\n"
    "                       SBATCH_* variables choose partition, account, time), wait for it to\n"
    "                       end, then write the same table; with --resume only the missing runs\n"
    "                       are submitted (none missing: the table is written at once)\n"
    "\n"
    "exit status: 0 every run ended and is in the table (whatever its expectations), 1 some run\n"
    "ended in an error (exit 2 or 3; the table's `error` says why) or left no row, 2 bad input\n"
    "(arguments, an unknown or bad --grid or --set field, an --out that cannot be written), 128 +\n"
    "the signal when stopped (the finished rows are kept: --resume goes on).\n";

std::atomic<bool> g_stop{false};
std::atomic<int> g_stop_signal{0};
extern "C" void on_sweep_signal(int s) {
  g_stop_signal.store(s);
  g_stop.store(true);
}

// Without SA_RESTART, so that waiting for a run returns when a signal comes.
void handle_signals() {
  struct sigaction action {};
  action.sa_handler = on_sweep_signal;
  sigemptyset(&action.sa_mask);
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) sigaction(s, &action, nullptr);
}

int bad_input(const std::string& message) {
  std::cerr << "graspsim sweep: " << message << "\n";
  return kExitBadInput;
}

std::string self_program() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("graspsim") : self.string();
}

// Every axis value, and the fixed sets, as the runs will get them: the scenario's own --set
// errors (an unknown field, a bad value) before anything runs. Each value is tried once, with the
// other axes at their first value.
std::string check_overrides(const Plan& plan) {
  for (std::size_t a = 0; a <= plan.grid.size(); ++a) {
    const std::size_t count = a < plan.grid.size() ? plan.grid[a].values.size() : 1;
    for (std::size_t v = 0; v < count; ++v) {
      scripting::LoadOptions load;
      load.sets = plan.sets;
      for (std::size_t b = 0; b < plan.grid.size(); ++b)
        load.sets.push_back(plan.grid[b].name + "=" + plan.grid[b].values[b == a ? v : 0]);
      try {
        scripting::Scenario::load(plan.scenario, load);
      } catch (const scripting::ScenarioError& e) {
        return (a < plan.grid.size() ? "--grid " + plan.grid[a].name + "=" + plan.grid[a].values[v] + ": "
                                     : std::string()) + e.what();
      }
    }
  }
  return {};
}

// Prints "runs done / total" and the time left: one line rewritten on a terminal, else a line
// per run.
struct Progress {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  bool tty = isatty(STDERR_FILENO);
  std::size_t kept = 0, total = 0;   // rows already there; runs in the sweep
  void operator()(std::size_t done, std::size_t of) const {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double left = done > 0 ? elapsed / done * (of - done) : 0.0;
    std::fprintf(stderr, "%sgraspsim sweep: %zu / %zu runs done, about %.0f s left%s", tty ? "\r" : "",
                 kept + done, total, left, tty ? "   " : "\n");
    if (tty && done == of) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }
};

// DIR/sweep.png, drawn into DIR/sweep.partial.png (matplotlib takes the format from the name)
// and renamed over it: a link at sweep.png is replaced, never written through.
void plot(const std::string& dir) {
  const std::string png = (fs::path(dir) / "sweep.png").string();
  const std::string partial = (fs::path(dir) / "sweep.partial.png").string();
  for (const std::string& path : {png, partial}) {
    if (const std::string what = app::not_replaceable(path); !what.empty()) {
      std::cerr << "graspsim sweep: warning: no plot: " << path << " is " << what << ", not a file; the table is written\n";
      return;
    }
  }
  const std::string script = GRASPSIM_PLOT_SWEEP;
  // Debian's python3 (python3-matplotlib, tools/setup.sh), not one earlier on PATH without it.
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string command = python + " " + shell_quote(script) + " " +
                              shell_quote((fs::path(dir) / "sweep.csv").string()) + " --out " + shell_quote(partial);
  std::error_code ec;
  if (!fs::exists(script) || std::system(command.c_str()) != 0) {
    fs::remove(partial, ec);
    std::cerr << "graspsim sweep: warning: no plot (" << command
              << " failed: it needs python3-matplotlib); the table is written\n";
    return;
  }
  fs::rename(partial, png, ec);
  if (ec) std::cerr << "graspsim sweep: warning: cannot rename " << partial << " to " << png << ": " << ec.message() << "\n";
}

}  // namespace

namespace {

constexpr const char* kSweepUsage =
    "usage: graspsim sweep SCENARIO.lua --grid NAME=V1,V2,... [--grid ...] [--set NAME=VALUE]...\n"
    "                [--seeds N [--jitter A]] [--jobs N] --out DIR [--keep-traces] [--slurm] [--resume]\n";

struct SweepArgs {
  Plan plan;
  std::string out;
  long long jobs = std::max(1u, std::thread::hardware_concurrency());
  long long seeds = 0;
  bool slurm = false, resume = false, jitter_given = false;
};

Option grid_option(Plan& plan) {
  return {"--grid", "NAME=V1,V2,...", [&plan](const std::string& v, std::string& why) {
            try {
              Axis axis = parse_axis(v);
              for (const auto& g : plan.grid)
                if (g.name == axis.name) throw SweepError("--grid " + axis.name + " is given twice");
              plan.grid.push_back(std::move(axis));
              return true;
            } catch (const SweepError& e) {
              why = e.what();
              return false;
            }
          }};
}

CommandLine sweep_line(SweepArgs& a) {
  CommandLine line{"sweep", kSweepUsage, kSweepHelp, {}, {}};
  line.options = {grid_option(a.plan),
                  set_option(a.plan.sets),
                  count("--seeds", "a whole number from 1 to 1000000", 1, 1000000, a.seeds),
                  {"--jitter", "an amplitude in m, a number > 0", [&a](const std::string& v, std::string&) {
                     return a.jitter_given = parse_number(v, a.plan.jitter) && a.plan.jitter > 0.0;
                   },
                   true},
                  count("--jobs", "a whole number from 1 to 4096", 1, 4096, a.jobs),
                  text("--out", "a folder", a.out),
                  flag("--keep-traces", a.plan.keep_traces),
                  flag("--slurm", a.slurm),
                  flag("--resume", a.resume)};
  line.operand = [&a](const std::string& v) -> std::string {
    if (!a.plan.scenario.empty()) return "one scenario at a time (got '" + a.plan.scenario + "' and '" + v + "')";
    a.plan.scenario = v;
    return "";
  };
  return line;
}

// The folder DIR: refused if it is not one, holds someone else's files or another sweep, or any
// of the sweep's own files is there as something other than a file; made if missing, with its
// plan file (which says which sweep it holds) written whole. "" when ready.
std::string prepare_folder(const SweepArgs& a, const std::string& dir) {
  const std::string& out = a.out;
  const std::string plan_file = (fs::path(dir) / "sweep.plan").string();
  std::error_code ec;
  if (fs::exists(fs::status(dir, ec)) && !fs::is_directory(dir, ec))
    return "--out " + out + " is " + app::not_replaceable(dir) + ", not a folder: a sweep writes its table "
           "and its runs into a folder; choose a new or empty one";
  // The sweep's own files are replaced only when they are files (a device, a FIFO or a socket
  // left there is refused before anything runs).
  for (const char* name : {"sweep.plan", "sweep.plan.partial", "sweep.csv", "sweep.h5", "sweep.png"}) {
    try {
      check_replaceable((fs::path(dir) / name).string());
    } catch (const SweepError& e) {
      return "--out " + out + ": " + e.what();
    }
  }
  // A folder that holds files but no plan is someone else's: its sweep.csv, .h5 and .png would
  // be written over.
  if (fs::is_directory(dir, ec) && !fs::exists(plan_file, ec)) {
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      const bool empty_runs = entry.path().filename() == "runs" && fs::is_directory(entry.path(), ec) &&
                              fs::is_empty(entry.path(), ec);   // a sweep that stopped before its plan
      if (!empty_runs)
        return "--out " + out + " is a folder with files and no sweep.plan, not a sweep's: its files "
               "would be written over; choose a new or empty folder";
    }
  }
  fs::create_directories(fs::path(dir) / "runs", ec);
  if (ec) return "--out " + out + ": cannot make the folder: " + ec.message();
  if (fs::exists(plan_file)) {
    if (read_file(plan_file) != a.plan.text())
      return "--out " + out + " holds another sweep (" + plan_file + " differs): choose another folder";
    if (!a.resume) return "--out " + out + " holds this sweep already: --resume to go on with it";
  } else {
    // Written whole or not at all (a .partial renamed): a cut plan would hold another sweep.
    const std::string partial = plan_file + ".partial";
    std::ofstream file(partial, std::ios::trunc);
    file << a.plan.text();
    file.close();
    if (!file || std::rename(partial.c_str(), plan_file.c_str()) != 0) {
      std::remove(partial.c_str());
      return "--out " + out + ": cannot write " + plan_file;
    }
  }
  if (access((fs::path(dir) / "runs").c_str(), W_OK) != 0) return "--out " + out + ": cannot write in " + dir + "/runs";
  return "";
}

// Runs the runs without a row, locally or on Slurm: -1 when every one ended, else the exit status.
int run_pending(const SweepArgs& a, const std::string& dir) {
  const Plan& plan = a.plan;
  handle_signals();
  const std::vector<std::size_t> pending = pending_runs(plan, dir);
  Progress progress;
  progress.total = plan.size();
  progress.kept = plan.size() - pending.size();
  if (progress.kept > 0) std::fprintf(stderr, "graspsim sweep: %zu of %zu runs are done already\n", progress.kept, plan.size());
  if (pending.empty()) return -1;
  if (a.slurm) {
    if (const std::string why = run_slurm(self_program(), plan, dir, pending, progress, g_stop); !why.empty()) {
      std::cerr << "graspsim sweep: " << why << "\n";
      return g_stop.load() ? 128 + g_stop_signal.load() : kExitFailed;
    }
    return -1;
  }
  try {
    if (!run_local(self_program(), plan, dir, pending, static_cast<int>(a.jobs), g_stop, progress)) {
      std::cerr << "graspsim sweep: stopped; the finished runs are kept (--resume goes on)\n";
      return 128 + g_stop_signal.load();
    }
  } catch (const SweepError& e) {
    std::cerr << "graspsim sweep: " << e.what() << "\n";
    return kExitFailed;
  }
  return -1;
}

// The table of every run's row, its plot, and the count; the exit status.
int write_results(const SweepArgs& a, const std::string& dir) {
  const Plan& plan = a.plan;
  std::vector<Row> rows;
  std::vector<std::size_t> missing;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    if (auto row = read_row(plan, dir, i)) rows.push_back(std::move(*row));
    else missing.push_back(i);
  }
  try {
    write_table(plan, dir, rows);
  } catch (const std::exception& e) {
    std::cerr << "graspsim sweep: " << e.what() << "\n";
    return kExitFailed;
  }
  plot(dir);
  std::size_t passed = 0, errors = 0;
  for (const auto& r : rows) {
    passed += r.exit_status == 0;
    errors += r.exit_status >= 2;
  }
  std::printf("graspsim sweep: %zu runs: %zu pass, %zu fail, %zu error%s\n  table  %s/sweep.csv, %s/sweep.h5\n",
              plan.size(), passed, rows.size() - passed - errors, errors,
              missing.empty() ? "" : (", " + std::to_string(missing.size()) + " without a row").c_str(), dir.c_str(),
              dir.c_str());
  if (!missing.empty())
    std::cerr << "graspsim sweep: runs " << array_list(missing) << " left no row (their output: " << dir
              << "/runs/*.log" << (a.slurm ? ", " + dir + "/slurm/task-*.out" : std::string()) << ")\n";
  return (errors > 0 || !missing.empty()) ? kExitFailed : kExitOk;
}

}  // namespace

int sweep_command(const std::vector<std::string>& args) {
  SweepArgs a;
  const CommandLine line = sweep_line(a);
  switch (parse_command_line(line, args)) {
    case Parsed::kHelp: return kExitOk;
    case Parsed::kError: return kExitBadInput;
    case Parsed::kGo: break;
  }
  Plan& plan = a.plan;
  plan.seeds = static_cast<std::uint64_t>(a.seeds);
  if (plan.scenario.empty()) return usage_error(line, "sweep needs a scenario file");
  if (a.out.empty()) return usage_error(line, "sweep needs --out DIR");
  if (plan.grid.empty() && plan.seeds == 0) return usage_error(line, "nothing to sweep: give --grid NAME=V1,V2,... or --seeds N");
  if (a.jitter_given && plan.seeds == 0) return usage_error(line, "--jitter is the amplitude of --seeds: it needs --seeds N");
  if (!fs::is_regular_file(plan.scenario)) return bad_input("no scenario file " + plan.scenario);
  plan.scenario = fs::absolute(plan.scenario).lexically_normal().string();
  if (const std::string why = check_overrides(plan); !why.empty()) return bad_input(why);
  const std::string dir = fs::absolute(a.out).lexically_normal().string();
  if (const std::string why = prepare_folder(a, dir); !why.empty()) return bad_input(why);
  if (const int status = run_pending(a, dir); status >= 0) return status;
  return write_results(a, dir);
}

int sweep_task_command(const std::vector<std::string>& args) {
  std::vector<std::string> operands;
  constexpr const char* kTaskUsage = "usage: graspsim sweep-task DIR INDEX\n";
  const CommandLine line{"sweep-task", kTaskUsage,
                         std::string(kTaskUsage) + "\nRuns run INDEX of the sweep in DIR and writes its row: a Slurm "
                                                  "array task of `graspsim sweep --slurm`, which submits it.\n",
                         {},
                         [&operands](const std::string& v) {
                           operands.push_back(v);
                           return std::string();
                         }};
  switch (parse_command_line(line, args)) {
    case Parsed::kHelp: return kExitOk;
    case Parsed::kError: return kExitBadInput;
    case Parsed::kGo: break;
  }
  if (operands.size() != 2 || operands[1].empty() || operands[1].size() > 18 ||
      operands[1].find_first_not_of("0123456789") != std::string::npos)
    return usage_error(line, "sweep-task needs a sweep's folder and a run's number");
  const std::string& number = operands[1];
  const std::uint64_t index = std::strtoull(number.c_str(), nullptr, 10);
  const std::string dir = operands[0], plan_file = (fs::path(dir) / "sweep.plan").string();
  try {
    const Plan plan = Plan::parse(read_file(plan_file), plan_file);
    if (index >= plan.size()) return bad_input(plan_file + " has " + std::to_string(plan.size()) + " runs, not run " + number);
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = start_run(self_program(), plan, dir, index);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
      if (errno != EINTR) return bad_input("cannot wait for run " + number);
    const Row row = finish_run(plan, dir, index, status,
                               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    return row.exit_status < 128 ? kExitOk : row.exit_status;
  } catch (const SweepError& e) {
    return bad_input(e.what());
  }
}

}  // namespace graspsim::cli
