// graspsim_bless (run through tools/bless): re-blesses golden traces. For each scenario: run it
// at its own rates, decimate the trace into a golden, compare with the old golden (bitwise) and
// say what changed, then write it. An unchanged golden is left as it is (git sees no change).
// A run that stops early or fails an expectation is not blessed.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "app/golden.hpp"
#include "app/output_file.hpp"
#include "graspsim/recordings/trace_reader.hpp"

#ifndef GRASPSIM_SOURCE_DIR
#error "GRASPSIM_SOURCE_DIR must be defined"
#endif

namespace fs = std::filesystem;
using namespace graspsim;

namespace {

constexpr const char* kUsage =
    "usage: tools/bless [--dry-run] [--allow-failing] (--all | SCENARIO.lua...)\n"
    "Re-blesses golden traces (tests/golden/<scenario>.h5): runs each scenario at its own rates,\n"
    "decimates the trace (every /physics row, /servo and /haptic rows at physics ticks, deflate 9),\n"
    "compares it bitwise with the old golden, prints what changed, and writes it.\n"
    "  --all            every scenarios/*.lua\n"
    "  --dry-run        compare and report, write nothing (exit 1 if a golden would change)\n"
    "  --allow-failing  bless a run that fails one of its expectations\n"
    "Exit status: 0 done (or, with --dry-run, nothing would change), 1 a run refused or a golden\n"
    "would change, 2 bad input.\n";

std::string kilobytes(std::uintmax_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f kB", static_cast<double>(bytes) / 1000.0);
  return text;
}

// 0 blessed or unchanged, 1 refused or (dry run) would change, 2 bad input.
int bless(const std::string& scenario_file, const fs::path& work, bool dry_run, bool allow_failing) {
  const std::string golden = golden::golden_path(std::string(GRASPSIM_SOURCE_DIR) + "/tests/golden", scenario_file);
  const std::string stem = fs::path(scenario_file).stem().string();
  const std::string full = (work / (stem + ".full.h5")).string();
  const std::string fresh = (work / (stem + ".h5")).string();
  std::cout << stem << ": " << scenario_file << "\n";
  // A golden replaces only a file: not a device, FIFO, socket or directory left at its path.
  for (const std::string& path : {golden, golden + ".partial"}) {
    if (const std::string what = app::not_replaceable(path); !what.empty()) {
      std::cerr << "  error: " << path << " is " << what << ", not a regular file: bless replaces only files; "
                << "move it away\n";
      return 2;
    }
  }
  app::RunResult run;
  try {
    run = golden::run_for_golden(scenario_file, full);
  } catch (const std::exception& e) {
    std::cerr << "  error: " << e.what() << "\n";
    return 2;
  }
  if (!run.error.empty()) {
    std::cout << "  refused: the run stopped early: " << run.error << "\n";
    return 1;
  }
  bool failing = false;
  for (const auto& e : run.expectations) {
    if (!e.passed) {
      std::cout << "  FAIL " << e.what << (e.detail.empty() ? "" : ": " + e.detail) << "\n";
      failing = true;
    }
  }
  if (failing && !allow_failing) {
    std::cout << "  refused: the run fails an expectation (--allow-failing blesses it anyway)\n";
    return 1;
  }
  // Goldens come from the build CI tests with (build/, Release: ./tools/check).
  const std::string flags = recordings::read_string_attribute(full, "/", "build_flags");
  if (flags.rfind("Release:", 0) != 0) {
    std::cout << "  refused: this build is not the Release build CI uses (" << flags
              << "); bless from build/ (./tools/bless)\n";
    return 1;
  }
  golden::decimate_trace(full, fresh);
  const auto size = fs::file_size(fresh);
  bool changed = true;
  std::string what;   // what this bless changes, kept in the golden (root attribute blessed_changes)
  if (fs::exists(golden)) {
    try {
      recordings::CompareOptions options;
      options.bitwise = true;
      const auto result = recordings::compare_traces(fresh, golden, options);
      changed = !result.same() || result.unmatched_ticks() > 0;
      bool rule_changed = false;   // same values, but kept or stored another way
      for (const auto& a : result.attributes) rule_changed = rule_changed || a.name == "golden";
      if (!changed && rule_changed) {
        what = "same values where ticks meet, but the golden's rule changed";
        std::cout << "  " << what << "\n";
      }
      if (!changed && !rule_changed) {
        std::cout << "  unchanged: bit-identical to " << golden << " on every row; left as it is\n";
        return 0;
      }
      if (changed) {
        what = "changed against the golden before:\n" + golden::divergence_summary(result);
        std::cout << "  changed:\n" << golden::divergence_summary(result);
      }
    } catch (const recordings::CompareInputError& e) {
      what = std::string("the golden before could not be compared (") + e.what() + ")";
      std::cout << "  " << what << "\n";
    }
  } else {
    what = "new: no golden before";
    std::cout << "  new: no golden yet\n";
  }
  if (failing) what += "\nblessed with --allow-failing: the run fails an expectation (the golden test fails it)";
  if (dry_run) {
    std::cout << "  dry run: " << golden << " not written\n";
    return 1;
  }
  golden::DecimateOptions kept;
  kept.blessed_changes = what;
  golden::decimate_trace(full, fresh, kept);
  fs::create_directories(fs::path(golden).parent_path());
  // Whole or not at all: copied beside the golden, then renamed over it.
  const std::string partial = golden + ".partial";
  fs::copy_file(fresh, partial, fs::copy_options::overwrite_existing);
  fs::rename(partial, golden);
  std::cout << "  wrote " << golden << " (" << kilobytes(size) << ", " << run.physics_ticks
            << " physics ticks)\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  bool all = false, dry_run = false, allow_failing = false;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--all") all = true;
    else if (arg == "--dry-run") dry_run = true;
    else if (arg == "--allow-failing") allow_failing = true;
    else if (arg == "-h" || arg == "--help") { std::cout << kUsage; return 0; }
    else if (!arg.empty() && arg[0] == '-') { std::cerr << "bless: unknown option '" << arg << "'\n" << kUsage; return 2; }
    else files.push_back(arg);
  }
  if (all) {
    for (const auto& entry : fs::directory_iterator(std::string(GRASPSIM_SOURCE_DIR) + "/scenarios"))
      if (entry.path().extension() == ".lua") files.push_back(entry.path().string());
    std::sort(files.begin(), files.end());
  }
  if (files.empty()) {
    std::cerr << kUsage;
    return 2;
  }
  for (const std::string& f : files) {
    if (!fs::is_regular_file(f)) {
      std::cerr << "bless: no such scenario file '" << f << "'\n";
      return 2;
    }
  }
  // Scenarios inside the repository run as scenarios/X.lua from its root, so the golden's
  // scenario_path does not carry the blesser's checkout.
  const fs::path root = fs::canonical(GRASPSIM_SOURCE_DIR);
  for (std::string& f : files) {
    const fs::path relative = fs::canonical(f).lexically_relative(root);
    if (!relative.empty() && *relative.begin() != "..") f = relative.string();
    else f = fs::canonical(f).string();
  }
  fs::current_path(root);
  const fs::path work = fs::temp_directory_path() / ("graspsim-bless-" + std::to_string(getpid()));
  fs::create_directories(work);
  int status = 0;
  for (const std::string& f : files) {
    int s = 2;
    try {
      s = bless(f, work, dry_run, allow_failing);
    } catch (const std::exception& e) {
      std::cerr << "  error: " << e.what() << "\n";
    }
    status = std::max(status, s);
  }
  std::error_code ec;
  fs::remove_all(work, ec);
  return status;
}
