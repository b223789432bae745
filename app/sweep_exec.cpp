// Running a sweep's runs as child processes (sweep_exec.hpp).
#include "app/sweep_exec.hpp"

#include "app/output_file.hpp"
#include "app/sweep_row.hpp"

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <map>
#include <sstream>
#include <spawn.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

extern char** environ;

namespace graspsim::app::sweep {

bool clear_stale_partial(const Plan& plan, const std::string& dir, std::size_t index) {
  const std::string partial = partial_name(plan.run_file(dir, index, "h5"));
  std::error_code ec;
  if (!std::filesystem::exists(partial, ec) || locked_by_a_run(partial)) return false;
  return std::filesystem::remove(partial, ec);
}

pid_t start_run(const std::string& program, const Plan& plan, const std::string& dir, std::size_t index) {
  const std::vector<std::string> args = plan.run_arguments(index, dir);
  std::vector<char*> argv{const_cast<char*>(program.c_str())};
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const std::string log = plan.run_file(dir, index, "log");
  for (const char* extension : {"log", "summary", "row"}) check_replaceable(plan.run_file(dir, index, extension));
  std::remove(plan.run_file(dir, index, "summary").c_str());   // a stopped run's, if any
  std::remove((plan.run_file(dir, index, "summary") + ".partial").c_str());   // a killed run's, if any
  if (plan.keep_traces) clear_stale_partial(plan, dir, index);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw SweepError("cannot start " + program + " for run " + std::to_string(index) + ": " + std::strerror(rc));
  return pid;
}

Row finish_run(const Plan& plan, const std::string& dir, std::size_t index, int status, double wall) {
  const Plan::Run r = plan.run(index);
  Row row;
  row.index = index;
  row.values = r.values;
  row.seed = r.seed;
  row.wall = wall;
  row.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  const std::string summary = plan.run_file(dir, index, "summary");
  row.expectations = parse_summary(read_file(summary));
  std::remove(summary.c_str());
  if (plan.keep_traces) {
    const std::string trace = plan.run_file(dir, index, "h5");
    if (std::filesystem::exists(trace)) row.trace = std::filesystem::relative(trace, dir).string();
  }
  if (row.exit_status >= 2) {   // why: graspsim's own last error line, else the last line written
    std::istringstream log(read_file(plan.run_file(dir, index, "log")));
    std::string line, last;
    while (std::getline(log, line)) {
      if (line.rfind("graspsim: ", 0) == 0 && line.rfind("graspsim: warning: ", 0) != 0) row.error = line.substr(10);
      if (!line.empty()) last = line;
    }
    if (row.error.empty()) row.error = last;
  }
  if (row.exit_status < 128) write_row(plan, dir, row);
  return row;
}

std::vector<std::size_t> pending_runs(const Plan& plan, const std::string& dir) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < plan.size(); ++i)
    if (!read_row(plan, dir, i)) out.push_back(i);
  return out;
}

namespace {

// Ends every run in `running` (SIGTERM) and waits for each: none is left running or unreaped.
template <class Running>
void end_all(Running& running) {
  for (const auto& [pid, run] : running) kill(pid, SIGTERM);
  for (const auto& [pid, run] : running) {
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  }
  running.clear();
}

}  // namespace

bool run_local(const std::string& program, const Plan& plan, const std::string& dir,
               const std::vector<std::size_t>& indices, int jobs, const std::atomic<bool>& stop,
               const std::function<void(std::size_t, std::size_t)>& done) {
  using Clock = std::chrono::steady_clock;
  // How long the loop sleeps when no run has ended; `stop` is seen within it, whatever the runs do.
  constexpr auto kPoll = std::chrono::milliseconds(10);
  std::map<pid_t, std::pair<std::size_t, Clock::time_point>> running;
  std::size_t next = 0, finished = 0;
  bool stopping = false;
  try {
    while (next < indices.size() || !running.empty()) {
      if (stop.load() && !stopping) {   // stop every run; their rows are not written
        stopping = true;
        for (const auto& [pid, run] : running) kill(pid, SIGTERM);
      }
      while (!stopping && next < indices.size() && static_cast<int>(running.size()) < jobs) {
        const std::size_t index = indices[next++];
        running[start_run(program, plan, dir, index)] = {index, Clock::now()};
      }
      if (running.empty()) break;
      int status = 0;
      const pid_t pid = waitpid(-1, &status, WNOHANG);
      if (pid == 0) {   // none ended yet
        std::this_thread::sleep_for(kPoll);
        continue;
      }
      if (pid < 0) {
        if (errno == EINTR) continue;   // a signal: the loop's top sees `stop`
        throw SweepError(std::string("waiting for a run: ") + std::strerror(errno));
      }
      const auto it = running.find(pid);
      if (it == running.end()) continue;
      const auto [index, start] = it->second;
      running.erase(it);
      const double wall = std::chrono::duration<double>(Clock::now() - start).count();
      if (stopping) continue;
      finish_run(plan, dir, index, status, wall);
      if (done) done(++finished, indices.size());
    }
  } catch (...) {   // no run outlives the sweep that started it
    end_all(running);
    throw;
  }
  return !stopping;
}

std::string array_list(const std::vector<std::size_t>& indices) {
  std::string out;
  for (std::size_t i = 0; i < indices.size();) {
    std::size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    if (!out.empty()) out += ',';
    out += std::to_string(indices[i]);
    if (j > i) {
      out += '-';
      out += std::to_string(indices[j]);
    }
    i = j + 1;
  }
  return out;
}

}  // namespace graspsim::app::sweep
