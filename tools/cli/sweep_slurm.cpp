// `graspsim sweep --slurm`: the job script, sbatch --array, and waiting on squeue (sweep_slurm.hpp).
#include "cli/sweep_slurm.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "app/sweep_exec.hpp"
#include "app/sweep_row.hpp"

namespace graspsim::cli {

namespace fs = std::filesystem;
using namespace app::sweep;

std::string run_slurm(const std::string& program, const Plan& plan, const std::string& dir,
                      const std::vector<std::size_t>& pending,
                      const std::function<void(std::size_t, std::size_t)>& progress, const std::atomic<bool>& stop) {
  const fs::path slurm = fs::path(dir) / "slurm";
  std::error_code ec;
  fs::create_directories(slurm, ec);
  if (ec) return "cannot make " + slurm.string() + ": " + ec.message();
  const std::string script = (slurm / "job.sh").string();
  try {
    check_replaceable(script);
  } catch (const SweepError& e) {
    return e.what();
  }
  {
    std::ofstream out(script, std::ios::trunc);
    out << slurm_job_script(program, dir);
    if (!out) return "cannot write " + script;
  }
  const std::string submit = sbatch_command(script, slurm.string(), array_list(pending));
  FILE* p = popen((submit + " 2>&1").c_str(), "r");
  if (!p) return "cannot run sbatch";
  std::string reply;
  char buf[256];
  while (std::fgets(buf, sizeof buf, p)) reply += buf;
  const int status = pclose(p);
  const std::string job = reply.substr(0, reply.find_first_of(";\n"));
  if (status != 0 || job.empty() || job.find_first_not_of("0123456789") != std::string::npos)
    return "sbatch refused the job array (" + submit + "): " + reply;
  std::fprintf(stderr, "graspsim sweep: submitted %zu runs as Slurm job array %s (%s)\n", pending.size(), job.c_str(),
               script.c_str());
  std::size_t reported = 0;
  // s: how long squeue may fail in a row (each failure can itself take seconds: it retries the
  // controller) before the sweep gives up waiting.
  constexpr double kSqueueFailing = 60.0;
  int failures = 0;                                  // squeue failures in a row
  std::chrono::steady_clock::time_point failing_since;
  for (;;) {
    if (stop.load()) {
      std::system(("scancel " + job).c_str());
      return "stopped: cancelled job " + job;
    }
    // Empty output means the array has left the queue only when squeue answered (exit 0); a job
    // id the controller has already forgotten is ended too. Any other failure (the controller
    // down or restarting) is retried for up to kSqueueFailing seconds in a row.
    FILE* q = popen(("squeue -h -j " + job + " -o %i 2>&1").c_str(), "r");
    std::string queued;
    while (q && std::fgets(buf, sizeof buf, q)) queued += buf;
    const int squeue_status = q ? pclose(q) : -1;
    std::size_t done = 0;
    for (const std::size_t i : pending) done += read_row(plan, dir, i).has_value();
    if (done != reported) progress(reported = done, pending.size());
    if (squeue_status == 0) {
      failures = 0;
      if (queued.find_first_not_of(" \n") == std::string::npos) return {};
    } else if (queued.find("Invalid job id") != std::string::npos) {
      return {};
    } else if (++failures == 1) {
      failing_since = std::chrono::steady_clock::now();
    } else if (std::chrono::duration<double>(std::chrono::steady_clock::now() - failing_since).count() > kSqueueFailing) {
      return "squeue failed " + std::to_string(failures) + " times in a row (" +
             std::to_string(static_cast<int>(kSqueueFailing)) + " s) while job " + job +
             " may still run (its runs' rows are kept; rerun with --resume once Slurm answers): " +
             (queued.empty() ? "no output" : queued.substr(0, queued.find_last_not_of(" \n") + 1));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
}

}  // namespace graspsim::cli
