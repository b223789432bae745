// `graspsim sweep` (README.md "Sweeps") and `graspsim sweep-task`, which runs one run of a
// sweep's plan, as a Slurm array task does.
#pragma once

#include <atomic>
#include <string>
#include <vector>

namespace graspsim::cli {

int sweep_command(const std::vector<std::string>& args);
int sweep_task_command(const std::vector<std::string>& args);

}  // namespace graspsim::cli
