// Running a sweep's runs: each one a child `graspsim run` process (one process per run keeps
// every run deterministic and isolated), its stdout and stderr in runs/<index>.log, its
// expectations in runs/<index>.summary, its row written when it ends (sweep_row.hpp).
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <sys/types.h>
#include <vector>

#include "app/sweep_plan.hpp"
#include "app/sweep_row.hpp"

namespace graspsim::app::sweep {

// Removes run `index`'s partial trace (runs/<index>.h5.partial) unless a live run holds its lock:
// one left by a run that was killed would make the rerun refuse its --out. The sweep owns runs/.
// Returns true when one was removed.
bool clear_stale_partial(const Plan& plan, const std::string& dir, std::size_t index);

// Starts run `index` of `plan` (its stale partial trace removed first) as a child process of `graspsim` (the executable `program`);
// throws SweepError when it cannot be started.
pid_t start_run(const std::string& program, const Plan& plan, const std::string& dir, std::size_t index);

// The row of run `index` whose process ended with waitpid status `status` after `wall` s;
// written to its file unless the run was stopped by a signal (then it is run again on resume).
Row finish_run(const Plan& plan, const std::string& dir, std::size_t index, int status, double wall);

// The runs of `plan` without a row in `dir`, in order.
std::vector<std::size_t> pending_runs(const Plan& plan, const std::string& dir);

// Runs `indices` with at most `jobs` at once, calling `done(finished, total)` after each one.
// Returns false when `stop` was set (its runs are stopped with SIGTERM and their rows not written);
// `stop` is seen within 10 ms, whether or not a run ends. When a run cannot be started or its row
// written, or `done` throws, every run still going is stopped (SIGTERM) and reaped before the
// exception leaves.
bool run_local(const std::string& program, const Plan& plan, const std::string& dir,
               const std::vector<std::size_t>& indices, int jobs, const std::atomic<bool>& stop,
               const std::function<void(std::size_t, std::size_t)>& done);

// "0-3,5,7-9": the indices (sorted) as Slurm's --array list.
std::string array_list(const std::vector<std::size_t>& indices);

}  // namespace graspsim::app::sweep
