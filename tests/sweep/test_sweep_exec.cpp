// The sweep's handling of its runs' files (app/sweep_exec.hpp), without running graspsim.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <atomic>
#include <cerrno>
#include <filesystem>
#include <fstream>

#include "app/output_file.hpp"
#include "app/sweep_exec.hpp"

namespace fs = std::filesystem;
using namespace graspsim::app;

TEST_CASE("a run's partial trace left by a killed run is removed before the rerun, and one a live run holds is kept",
          "[sweep]") {
  // A SIGKILLed run leaves runs/<index>.h5.partial holding bytes; the rerun's OutputClaim refuses a
  // non-empty unlocked partial, so without the removal `--resume --keep-traces` made the row a
  // permanent error. A partial whose lock is held belongs to a running run and must stay.
  const fs::path dir = fs::path(GRASPSIM_TEST_TMP) / "sweep_stale_partial";
  fs::remove_all(dir);
  fs::create_directories(dir / "runs");
  sweep::Plan plan;
  plan.scenario = "/s/lift.lua";
  plan.grid = {{"mu", {"0.2", "0.6"}}};
  plan.keep_traces = true;
  const std::string partial = partial_name(plan.run_file(dir.string(), 1, "h5"));
  std::ofstream(partial) << "the start of a trace";
  REQUIRE(fs::file_size(partial) > 0);
  CHECK(sweep::clear_stale_partial(plan, dir.string(), 1));
  CHECK_FALSE(fs::exists(partial));

  OutputClaim live(plan.run_file(dir.string(), 0, "h5"));   // a run writing run 0 now
  std::ofstream(live.partial(), std::ios::app) << "bytes";
  CHECK_FALSE(sweep::clear_stale_partial(plan, dir.string(), 0));
  CHECK(fs::exists(live.partial()));
  live.abandon();
}

TEST_CASE("when the sweep's own bookkeeping throws, every run it started is stopped and reaped", "[sweep]") {
  // A stand-in for graspsim: the run with mu=0.2 ends at once, the others sleep 30 s. The first
  // run's end makes `done` throw; the sleeping runs must not outlive run_local (no child left to
  // reap: waitpid says ECHILD), and the exception must reach the caller.
  const fs::path dir = fs::path(GRASPSIM_TEST_TMP) / "sweep_throw_reaps";
  fs::remove_all(dir);
  fs::create_directories(dir / "runs");
  const std::string program = (dir / "fake_graspsim.sh").string();
  std::ofstream(program) << "#!/bin/sh\ncase \"$*\" in *mu=0.2*) exit 0;; *) exec sleep 30;; esac\n";
  fs::permissions(program, fs::perms::owner_all);
  sweep::Plan plan;
  plan.scenario = "/s/lift.lua";
  plan.grid = {{"mu", {"0.2", "0.6", "0.9"}}};
  std::atomic<bool> stop{false};
  const auto fail = [](std::size_t, std::size_t) { throw sweep::SweepError("the table could not be written"); };
  CHECK_THROWS_AS(sweep::run_local(program, plan, dir.string(), {0, 1, 2}, 3, stop, fail), sweep::SweepError);
  errno = 0;
  CHECK(waitpid(-1, nullptr, WNOHANG) == -1);
  CHECK(errno == ECHILD);
}
