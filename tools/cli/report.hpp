// What the run and replay commands share: exit codes and the expectations report.
#pragma once

#include <atomic>
#include <cstdio>

#include "app/run.hpp"

namespace graspsim::cli {

constexpr int kExitOk = 0;            // every expectation held
constexpr int kExitFailed = 1;        // an expectation failed
constexpr int kExitBadInput = 2;      // bad input: arguments, scenario, output path, script error
constexpr int kExitTraceFault = 3;    // an output the run owes could not be written: the --summary,
                                      // or the trace to its end (a full disk): the trace
                                      // keeps every tick up to its last flush, marked
constexpr int kExitInterrupted = 130; // Ctrl-C (128 + SIGINT); SIGTERM 143, SIGHUP 129

// 128 + the signal that stopped the run (SIGINT if none is known).
inline int exit_interrupted(const std::atomic<int>* signal) {
  const int s = signal ? signal->load() : 0;
  return s > 0 ? 128 + s : kExitInterrupted;
}

// Prints the expectations of a run (only the failed ones when quiet); returns how many failed.
inline int print_expectations(const app::RunResult& result, bool quiet) {
  int failed = 0;
  if (!result.expectations.empty() && !quiet) std::printf("  expectations\n");
  for (const auto& e : result.expectations) {
    failed += !e.passed;
    if (quiet && e.passed) continue;
    std::printf("    %s  %s%s%s\n", e.passed ? "PASS" : "FAIL", e.what.c_str(), e.detail.empty() ? "" : ": ",
                e.detail.c_str());
  }
  return failed;
}

}  // namespace graspsim::cli
