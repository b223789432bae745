// What `graspsim sweep --slurm` hands to Slurm (app/sweep_slurm.hpp), for a folder whose name
// holds a space, a %, a quote and a line break: run by /bin/sh, without Slurm. Before, the folder
// went raw into the script: a line break made script lines of the rest, a space cut #SBATCH
// --output, and Slurm replaced the % of the name as a pattern.
#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "app/sweep_slurm.hpp"

namespace {

namespace fs = std::filesystem;
using namespace graspsim::app::sweep;

const std::string kDir = "/sweeps/lift 50%'s\nrm -rf x";   // a space, a %, a quote, a line break

// What `command` prints through /bin/sh.
std::string shell_output(const std::string& command) {
  std::string out;
  FILE* p = popen(command.c_str(), "r");
  REQUIRE(p);
  char buf[256];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  CHECK(pclose(p) == 0);
  return out;
}

}  // namespace

TEST_CASE("the Slurm job script runs `PROGRAM sweep-task DIR TASK` with the folder as one argument", "[sweep][slurm]") {
  const std::string script = slurm_job_script("/bin/echo", kDir);
  // Seven line breaks: after the shebang, the comment (the folder's own break escaped), three
  // #SBATCH and exec, and the one inside exec's quoted folder (one word to the shell).
  std::size_t lines = 0;
  for (const char c : script) lines += c == '\n';
  CHECK(lines == 7);
  CHECK(script.find("#SBATCH --output") == std::string::npos);   // on the command line instead
  CHECK(script.find("# One run of the graspsim sweep in /sweeps/lift 50%'s\\nrm -rf x per array task") != std::string::npos);
  const fs::path file = fs::path(GRASPSIM_TEST_TMP) / "slurm_job_script.sh";
  std::ofstream(file) << script;
  // echo prints its arguments joined by spaces: the folder, line break included, as it is.
  CHECK(shell_output("SLURM_ARRAY_TASK_ID=7 sh '" + file.string() + "'") == "sweep-task " + kDir + " 7\n");
}

TEST_CASE("sbatch's --output is one quoted argument with the folder's % doubled, only %a left a pattern",
          "[sweep][slurm]") {
  const std::string command = sbatch_command("/sweeps/job's.sh", kDir + "/slurm", "0-3,5");
  REQUIRE(command.rfind("sbatch ", 0) == 0);
  // printf '%s|' in place of sbatch: each argument as the shell passes it, ended by |.
  const std::string args = shell_output("printf '%s|' " + command.substr(7));
  CHECK(args == "--parsable|--array=0-3,5|--output=/sweeps/lift 50%%'s\nrm -rf x/slurm/task-%a.out|/sweeps/job's.sh|");
}
