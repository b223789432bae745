// The text `graspsim sweep --slurm` hands to Slurm (README.md "Sweeps"): the array task's job
// script and the sbatch command line. Any folder name is safe in both: shell-quoted, kept out of
// #SBATCH lines, its line breaks escaped in the script's comment, and its % doubled where Slurm
// reads a filename pattern.
#pragma once

#include <string>

namespace graspsim::app::sweep {

// `s` in single quotes for /bin/sh.
std::string shell_quote(const std::string& s);

// `path` as a literal in a Slurm filename pattern (sbatch --output): every % doubled (%%),
// so only the pattern's own %a is replaced.
std::string slurm_pattern_literal(const std::string& path);

// The job script of one array task of the sweep in `dir`: `program sweep-task DIR
// $SLURM_ARRAY_TASK_ID`, both quoted; `dir` in its comment with control characters as \n, \r,
// \t or \xNN, so that it stays one comment line.
std::string slurm_job_script(const std::string& program, const std::string& dir);

// `sbatch --parsable --array=ARRAY --output=LOG_DIR/task-%a.out SCRIPT`, each argument quoted,
// LOG_DIR as a literal of the pattern.
std::string sbatch_command(const std::string& script, const std::string& log_dir, const std::string& array);

}  // namespace graspsim::app::sweep
