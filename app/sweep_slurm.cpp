#include "app/sweep_slurm.hpp"

#include <cstdio>

namespace graspsim::app::sweep {

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string slurm_pattern_literal(const std::string& path) {
  std::string out;
  for (const char c : path) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out;
}

namespace {

// `s` with its control characters escaped: one line of text.
std::string one_line(const std::string& s) {
  std::string out;
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", u);
      out += buf;
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

std::string slurm_job_script(const std::string& program, const std::string& dir) {
  return "#!/bin/sh\n"
         "# One run of the graspsim sweep in " + one_line(dir) + " per array task (graspsim sweep --slurm).\n"
         "#SBATCH --job-name=graspsim-sweep\n"
         "#SBATCH --ntasks=1\n"
         "#SBATCH --cpus-per-task=1\n"
         "exec " + shell_quote(program) + " sweep-task " + shell_quote(dir) + " \"$SLURM_ARRAY_TASK_ID\"\n";
}

std::string sbatch_command(const std::string& script, const std::string& log_dir, const std::string& array) {
  return "sbatch --parsable --array=" + shell_quote(array) + " " +
         shell_quote("--output=" + slurm_pattern_literal(log_dir) + "/task-%a.out") + " " + shell_quote(script);
}

}  // namespace graspsim::app::sweep
