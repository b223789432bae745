// Crash safety end to end: `graspsim run --out X.h5` on a long scenario is killed with SIGKILL
// halfway; the file it leaves, X.h5.partial (a run writes its trace under that name and renames
// it only when it ends), opens read-only for h5py (SWMR) and for our reader, holds every tick up
// to the last flush with the run's real values, says `running`, and after `graspsim repair`
// opens for h5dump and any plain reader, saying `cut: repaired`.
#include <catch2/catch.hpp>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "app/run.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_recorder.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "tests/support/shell.hpp"

using namespace graspsim;

namespace {

const std::string kCli = GRASPSIM_CLI;
const std::string kScenario = std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/two_finger_lift.lua";
const std::string kTmp = GRASPSIM_TEST_TMP;
constexpr const char* kPython = "/usr/bin/python3";   // Debian's, with python3-h5py

using graspsim::test::Outcome;
using graspsim::test::shell;

// Servo rows on disk now (our reader, as a SWMR reader while the run writes), -1 while the file
// cannot be read yet (not created, or its layout not yet written).
std::int64_t servo_rows(const std::string& file) {
  try {
    return static_cast<std::int64_t>(recordings::read_dataset(file, "/servo/tick").shape.at(0));
  } catch (const std::exception&) {
    return -1;
  }
}

// Checks the cut file with h5py in SWMR mode: status; every loop is one table dataset whose
// columns are members of one row, so they cannot differ in length (with schema 2's dataset per
// column, a kill between two columns' appends leaves them apart: seen as /physics 1488 vs
// 1500 rows); /servo tick = 0..n-1 and time = tick / 3000 over its n rows. Prints n.
constexpr const char* kH5pyCheck = R"PY(
import sys, h5py, numpy
f = h5py.File(sys.argv[1], "r", swmr=True)
status = f.attrs["status"]
status = status.decode() if isinstance(status, bytes) else status
assert status == "running", status
for table in ("servo", "haptic", "physics"):
    assert isinstance(f[table], h5py.Dataset) and f[table].dtype.names, table
servo = f["servo"]
n = servo.shape[0]
tick = servo["tick"]
assert (tick == numpy.arange(n)).all()
assert (servo["time"] == tick / 3000.0).all()
fingers = servo.attrs["fingers"].split("\n")
assert fingers == ["thumb", "index"], fingers
assert servo["fingers"].shape == (n, 2) and servo["fingers"]["hip"].shape == (n, 2, 3)
print(n)
)PY";

}  // namespace

TEST_CASE("a run killed with SIGKILL halfway leaves a readable, repairable trace", "[e2e][crash]") {
  // 60 s simulated at 3000 Hz: 180000 servo ticks; killed once 30 s are on disk.
  const std::string out = kTmp + "/e2e_crash.h5";
  const std::string file = out + ".partial";   // where the killed run's trace stays
  std::remove(out.c_str());
  std::remove(file.c_str());
  const std::int64_t total = 180000, half = total / 2;
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    execl(kCli.c_str(), kCli.c_str(), "run", kScenario.c_str(), "--duration", "60", "--out",
          out.c_str(), "--quiet", static_cast<char*>(nullptr));
    _exit(127);
  }
  // Let the run go in slices of about 1 ms (SIGCONT, sleep, SIGSTOP: no timing, only progress)
  // until half of it is on disk, then kill it while it is stopped. A run of 60 s simulated
  // takes about 0.1 s here, so looking at it while it ran free could miss it, and the finished
  // run renames its trace away; a slice is about 1 s simulated, far short of the 30 s left.
  std::int64_t seen = -1;
  int status = 0;
  bool exited = false;
  for (;;) {
    REQUIRE(kill(child, SIGSTOP) == 0);
    REQUIRE(waitpid(child, &status, WUNTRACED) == child);   // stopped, or ended before it
    if (!WIFSTOPPED(status)) {
      exited = true;
      break;
    }
    seen = servo_rows(file);
    if (seen >= half) break;
    REQUIRE(kill(child, SIGCONT) == 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (!exited) {
    REQUIRE(kill(child, SIGKILL) == 0);
    REQUIRE(waitpid(child, &status, 0) == child);
  }
  INFO("the run must still be going when killed; exit status " << status);
  REQUIRE(WIFSIGNALED(status));
  REQUIRE(WTERMSIG(status) == SIGKILL);

  // Our reader: the cut file says running and holds every tick up to the last flush (at least
  // what was seen before the kill), with tick = row and time = tick / 3000 exactly.
  CHECK(recordings::read_string_attribute(file, "/", "status") == "running");
  CHECK(recordings::read_int_attribute(file, "/", "schema_version") == recordings::kSchemaVersion);
  const recordings::Dataset tick = recordings::read_dataset(file, "/servo/tick");
  const recordings::Dataset time = recordings::read_dataset(file, "/servo/time");
  const std::int64_t n = static_cast<std::int64_t>(tick.shape.at(0));
  CHECK(n >= seen);
  CHECK(n < total);
  REQUIRE(time.values.size() == tick.values.size());
  std::int64_t bad = 0;
  for (std::int64_t i = 0; i < n; ++i) {
    bad += tick.values[i] != static_cast<double>(i) || time.values[i] != static_cast<double>(i) / 3000.0;
  }
  CHECK(bad == 0);
  // /physics (every 60th tick) reaches the last flush too: the run hands every table to the
  // writer together every flush interval (360 ticks); a table whose block fills in between (after
  // a wall-clock flush) goes ahead alone, so /physics lags /servo by at most one interval plus
  // one physics period.
  const recordings::Dataset physics_tick = recordings::read_dataset(file, "/physics/tick");
  const recordings::Dataset hashes = recordings::read_dataset(file, "/physics/state_hash");
  const std::int64_t m = static_cast<std::int64_t>(physics_tick.shape.at(0));
  REQUIRE(m > 100);
  CHECK(hashes.bits.size() == static_cast<std::size_t>(m));
  CHECK((m - 1) * 60 + 60 + 360 >= n);
  // Nothing took the output's name: a killed run never renamed its trace.
  CHECK(shell("test -e " + out).status != 0);
  // The rows are the run's real values: the first 2 s of /physics/state_hash equal those of the
  // same scenario run here (bit-identical determinism, and no zero-filled chunk on disk).
  {
    scripting::LoadOptions load;
    load.sets.push_back("duration=2");
    const auto scenario = scripting::Scenario::load(kScenario, load);
    app::RunOptions options;
    options.out = kTmp + "/e2e_crash_reference.h5";
    const app::RunResult result = app::run_scenario(scenario, options);
    REQUIRE(result.error.empty());
    const recordings::Dataset reference = recordings::read_dataset(options.out, "/physics/state_hash");
    REQUIRE(reference.bits.size() == 100);
    CHECK(std::vector<std::uint64_t>(hashes.bits.begin(), hashes.bits.begin() + 100) == reference.bits);
  }

  // h5py, read-only in SWMR mode (Debian's python3-h5py; skipped with a message if missing).
  if (shell(std::string(kPython) + " -c 'import h5py'").status == 0) {
    const std::string script = kTmp + "/e2e_crash_check.py";
    if (FILE* out = std::fopen(script.c_str(), "w")) {
      std::fputs(kH5pyCheck, out);
      std::fclose(out);
    }
    const Outcome o = shell(std::string(kPython) + " " + script + " " + file);
    INFO(o.output);
    CHECK(o.status == 0);
    CHECK(std::atoll(o.output.c_str()) == n);   // what our reader sees
  } else {
    // tools/setup.sh installs it: a test that passed without its h5py part would say nothing.
    FAIL("python3-h5py is not installed (" << kPython << "): tools/setup.sh installs it");
  }

  // compare and replay take the cut file as it is (still marked open for SWMR writing):
  // compared with a complete run of the same 60 s, every tick it holds is bit-identical (the
  // ticks it lacks are counted, not differences); a replay from its device samples reproduces
  // every one of its ticks, state hash included.
  {
    const std::string full = kTmp + "/e2e_crash_full.h5";
    const Outcome run = shell(kCli + " run " + kScenario + " --duration 60 --quiet --out " + full);
    REQUIRE(run.status == 0);
    const Outcome compared = shell(kCli + " compare " + file + " " + full + " --bitwise");
    INFO(compared.output.substr(0, 3000));
    CHECK(compared.status == 0);
    CHECK_THAT(compared.output, Catch::Contains("SWMR"));
    const std::string replayed = kTmp + "/e2e_crash_replay.h5";
    const Outcome replay = shell(kCli + " replay " + file + " --out " + replayed);
    INFO(replay.output.substr(0, 3000));
    // Exit 1, not 0: the expectations due after the cut are reported as not checked.
    CHECK(replay.status == 1);
    CHECK_THAT(replay.output, Catch::Contains("reproduced  bit for bit"));
    CHECK_THAT(replay.output, Catch::Contains("not checked"));
    CHECK(static_cast<std::int64_t>(recordings::read_dataset(replayed, "/servo/tick").shape.at(0)) == n);
    std::remove(full.c_str());
    std::remove(replayed.c_str());
  }

  // The repair step, then h5dump (without SWMR) and our reader open it, nothing lost.
  const Outcome repaired = shell(kCli + " repair " + file);
  INFO(repaired.output);
  CHECK(repaired.status == 0);
  CHECK_THAT(repaired.output, Catch::Contains("repaired"));
  CHECK(recordings::read_string_attribute(file, "/", "status") == "cut: repaired");
  CHECK(static_cast<std::int64_t>(recordings::read_dataset(file, "/servo/tick").shape.at(0)) == n);
  CHECK(recordings::read_dataset(file, "/physics/state_hash").bits == hashes.bits);
  if (shell("command -v h5dump").status == 0) {
    const Outcome header = shell("h5dump -H " + file);
    INFO(header.output.substr(0, 2000));
    CHECK(header.status == 0);
    CHECK(shell("h5dump -d /physics " + file + " > /dev/null").status == 0);
  } else {
    FAIL("h5dump (hdf5-tools) is not installed: tools/setup.sh installs it");
  }
  // Nothing left to repair; a file that is not a trace is bad input.
  CHECK(shell(kCli + " repair " + file).status == 0);
  CHECK(shell(kCli + " repair " + kScenario).status == 2);
}

// A reader following a run (h5py in SWMR mode, as recordings/README.md suggests) holds the
// file's lock while the run ends: the writer still finishes the file (status "complete" and the
// kept attributes), since close() reopens it without file locking. The follower is a python
// process that opens the trace, says so, and holds it until its stdin closes.
TEST_CASE("a run ends cleanly while an h5py SWMR reader holds its trace", "[e2e][crash]") {
  if (shell(std::string(kPython) + " -c 'import h5py'").status != 0) {
    FAIL("python3-h5py is not installed (" << kPython << "): tools/setup.sh installs it");
  }
  const std::string file = kTmp + "/e2e_followed.h5";
  std::remove(file.c_str());
  recordings::TraceOptions options;
  options.background = true;
  recordings::TraceWriter writer(file, options);
  recordings::TraceTable& t = writer.table("servo");
  t.add_column("tick", 1, recordings::DType::kInt64, "tick");
  for (int r = 0; r < 100; ++r) *t.append_row() = r;
  writer.flush();
  writer.wait();
  int to_child[2], from_child[2];
  REQUIRE(pipe(to_child) == 0);
  REQUIRE(pipe(from_child) == 0);
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    dup2(to_child[0], 0);
    dup2(from_child[1], 1);
    close(to_child[1]);
    close(from_child[0]);
    execl(kPython, kPython, "-c",
          "import sys, h5py\n"
          "f = h5py.File(sys.argv[1], 'r', swmr=True)\n"
          "print(f['servo'].shape[0], flush=True)\n"
          "sys.stdin.read()\n",
          file.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(to_child[0]);
  close(from_child[1]);
  char line[64] = {};
  const ssize_t got = read(from_child[0], line, sizeof line - 1);   // the reader has it open
  CHECK(got > 0);
  CHECK(std::atoi(line) == 100);
  writer.set_attribute("expectations", "PASS kept for close()");
  CHECK_NOTHROW(writer.close("complete"));
  close(to_child[1]);   // the reader may go
  int status = 0;
  waitpid(child, &status, 0);
  close(from_child[0]);
  CHECK(recordings::read_string_attribute(file, "/", "status") == "complete");
  CHECK(recordings::read_string_attribute(file, "/", "expectations") == "PASS kept for close()");
}
