// `graspsim sweep --slurm`: a sweep's pending runs as one Slurm job array (README.md "Sweeps").
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "app/sweep_plan.hpp"
#include "app/sweep_slurm.hpp"

namespace graspsim::cli {

using app::sweep::shell_quote;

// Writes DIR/slurm/job.sh (one array task: `program sweep-task DIR $SLURM_ARRAY_TASK_ID`),
// submits `pending` with `sbatch --array`, and waits until none of its tasks is pending or
// running, calling `progress(rows written, pending.size())` as rows appear. When `stop` is set
// the job is cancelled. Returns "" or what went wrong (sbatch's own message included).
std::string run_slurm(const std::string& program, const app::sweep::Plan& plan, const std::string& dir,
                      const std::vector<std::size_t>& pending,
                      const std::function<void(std::size_t, std::size_t)>& progress, const std::atomic<bool>& stop);

}  // namespace graspsim::cli
