// The fault catalogue, outputs (README.md "What can go wrong"): nothing that was there before a
// command ran is lost, and the command never ends by a signal. Each case runs the real graspsim
// binary, states its exit status and the message it must print, and checks that every earlier
// file (an earlier trace, the scenario, a mesh, a recording, a file beside the output) is
// byte-identical afterwards, or replaced only by a complete or marked trace of the run. A case
// the machine cannot run (no tmpfs mount) is reported as skipped by ctest, not passed.
#include <catch2/catch.hpp>

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "app/run.hpp"
#include "graspsim/hw/scripted_finger.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/scripting/scenario.hpp"
#include "tests/support/process.hpp"
#include "tests/support/shell.hpp"
#include "tests/support/skip.hpp"

using namespace graspsim;
using graspsim::test::Child;
using graspsim::test::Ended;
using graspsim::test::exists;
using graspsim::test::file_bytes;
using graspsim::test::Outcome;

namespace fs = std::filesystem;

namespace {

const std::string kCli = GRASPSIM_CLI;
const std::string kSource = GRASPSIM_SOURCE_DIR;
const std::string kLift = kSource + "/scenarios/two_finger_lift.lua";
const std::string kTmp = GRASPSIM_TEST_TMP;
constexpr const char* kPython = "/usr/bin/python3";   // Debian's, with python3-h5py
constexpr int kExitTraceFault = 3;                      // tools/cli/report.hpp

// A fresh, empty directory for one case.
std::string fresh_dir(const std::string& name) {
  const std::string dir = kTmp + "/catalogue_" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Outcome cli_in(const std::string& dir, const std::string& args) {
  return graspsim::test::shell("cd '" + dir + "' && " + kCli + " " + args);
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// A one-box scenario of 0.1 s named `name` (a Lua string literal's contents).
std::string one_box(const std::string& name) {
  return "return { name = \"" + name + "\", duration = 0.1,\n"
         "  objects = { { name = \"box\", size = { 0.1, 0.1, 0.1 }, mass = 1, position = { 0, 0, 0.05 } } } }\n";
}

std::int64_t rows(const std::string& trace, const std::string& table) {
  return static_cast<std::int64_t>(recordings::read_dataset(trace, "/" + table + "/tick").shape.at(0));
}

std::string status_of(const std::string& trace) { return recordings::read_string_attribute(trace, "/", "status"); }

// Every table of a lift trace (3000 / 500 / 50 Hz) is whole up to its last row: /servo ticks are
// 0, 1, ..., n - 1, /haptic every 6th and /physics every 60th tick, none past n - 1. Returns n.
std::int64_t check_whole_tables(const std::string& trace) {
  const recordings::Dataset servo = recordings::read_dataset(trace, "/servo/tick");
  const auto n = static_cast<std::int64_t>(servo.shape.at(0));
  for (std::int64_t i = 0; i < n; ++i)
    if (servo.values[static_cast<std::size_t>(i)] != static_cast<double>(i)) FAIL("/servo row " << i << " is not tick " << i);
  for (const auto& [table, divisor] : {std::pair{"haptic", 6}, std::pair{"physics", 60}}) {
    const recordings::Dataset t = recordings::read_dataset(trace, std::string("/") + table + "/tick");
    for (std::size_t i = 0; i < t.values.size(); ++i)
      if (t.values[i] != static_cast<double>(divisor * static_cast<std::int64_t>(i))) FAIL("/" << table << " row " << i);
    CHECK(static_cast<std::int64_t>(t.values.size()) <= (n + divisor - 1) / divisor);
  }
  return n;
}

// h5py opens the trace as a plain reader (not SWMR) and reads its status; "" if h5py is missing.
std::string h5py_status(const std::string& trace) {
  if (graspsim::test::shell(std::string(kPython) + " -c 'import h5py'").status != 0) return "";
  const Outcome o = graspsim::test::shell(std::string(kPython) + " -c \"import h5py, sys; f = h5py.File(sys.argv[1], 'r'); "
                                          "s = f.attrs['status']; print(s.decode() if isinstance(s, bytes) else s, f['servo'].shape[0])\" '" +
                                          trace + "'");
  return o.status == 0 ? o.output : "h5py failed: " + o.output;
}

// A long lift started in the background, stopped once its partial trace has rows (SIGSTOP, so
// that it holds its output while the case runs; SIGCONT lets it go on).
struct LongRun {
  Child child;
  std::string out;
  LongRun(const std::string& dir, const std::string& out_name)
      : child({kCli, "run", kLift, "--duration", "3000", "--quiet", "--out", out_name}, dir + "/long_run.log", dir),
        out(dir + "/" + out_name) {}
  // Waits (no timing: only for progress) until the partial trace holds rows; false if the run
  // ended first.
  bool wait_for_rows() {
    while (child.running()) {
      try {
        if (rows(out + ".partial", "servo") > 0) return true;
      } catch (const std::exception&) {
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return false;
  }
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// A full disk. The lift on a tmpfs too small for its trace: exit 3 (never a signal: HDF5's exit
// handler can crash with SIGSEGV, recordings/README.md "Crash safety"), "the trace could not be
// written to its end ... No space left on device ... kept up to the last flush"; the trace is at
// the output path (marked, so it may replace what was there), status "error: ...", every table
// whole up to its last flush, and it opens in our reader, h5py (without SWMR) and `graspsim
// repair` (nothing to repair). A file
// beside it is untouched. Swept over the disk's size: 200 kB holds no flush interval of the lift
// (one is 0.12 s, about 88 kB of /servo, and 128 kB are held back to close the file), 1 MB some.
TEST_CASE("catalogue: a full disk ends the run with exit 3 and a marked trace up to its last flush", "[fault_catalogue][disk]") {
  {
    // Skipped before any size is tried, so that a skip can never hide a failure.
    const graspsim::test::Tmpfs probe(kTmp + "/catalogue_tmpfs_probe", 64 * 1024);
    if (!probe.mounted()) GRASPSIM_SKIP(probe.why_not() << " (run as root, or where mount(2) is allowed)");
  }
  for (const std::size_t size : {200u * 1024u, 1024u * 1024u, 4u * 1024u * 1024u}) {
    graspsim::test::Tmpfs disk(kTmp + "/catalogue_tmpfs_" + std::to_string(size), size);
    REQUIRE(disk.mounted());
    const std::string beside = disk.directory() + "/beside.txt";
    write_file(beside, "an earlier file on the same disk\n");
    const std::string trace = disk.directory() + "/x.h5";
    // Compressed, so that the run starts: its size is not known ahead, and the run budget only
    // warns (uncompressed, a trace that cannot fit the disk is refused before it starts, exit 2:
    // tests/e2e/test_input_catalogue.cpp). 1000 s compressed is tens of MB: every size fills.
    const Outcome o = cli_in(disk.directory(), "run " + kLift + " --duration 1000 --compress 1 --quiet --out x.h5");
    INFO("tmpfs of " << size << " bytes\n" << o.output);
    CHECK(o.status == kExitTraceFault);
    CHECK_THAT(o.output, Catch::Contains("the trace could not be written to its end") &&
                             Catch::Contains("No space left on device") && Catch::Contains("kept up to the last flush"));
    REQUIRE(exists(trace));
    CHECK_FALSE(exists(trace + ".partial"));
    CHECK_THAT(status_of(trace), Catch::StartsWith("error: ") && Catch::Contains("No space left on device") &&
                                     Catch::Contains("kept up to the last flush"));
    const std::int64_t n = check_whole_tables(trace);
    if (size >= 1024u * 1024u) CHECK(n >= 360);   // at least one flush interval on 1 MB
    const std::string h5py = h5py_status(trace);
    if (h5py.empty()) FAIL("python3-h5py is not installed (" << kPython << "): tools/setup.sh installs it");
    CHECK_THAT(h5py, Catch::StartsWith("error: ") && Catch::EndsWith(std::to_string(n) + "\n"));
    const Outcome repair = graspsim::test::shell(kCli + " repair " + trace);
    CHECK(repair.status == 0);
    CHECK_THAT(repair.output, Catch::Contains("nothing to repair"));
    CHECK(file_bytes(beside) == std::string("an earlier file on the same disk\n"));
  }
}

// A full disk where no tmpfs can be mounted: a file-size limit (RLIMIT_FSIZE, as `ulimit -f` sets
// it) makes writes fail as a full disk does, and would kill the run with SIGXFSZ. graspsim ignores
// that signal and stops writing short of the limit by the room it keeps for closing: exit 3, "the
// file would pass N bytes, this process's file size limit", the trace marked and whole up to its
// last flush. Swept over the limit.
TEST_CASE("catalogue: a file-size limit ends the run with exit 3 and a marked trace, never SIGXFSZ", "[fault_catalogue][disk]") {
  for (const rlim_t limit : {rlim_t{200 * 1024}, rlim_t{1024 * 1024}}) {
    const std::string dir = fresh_dir("fsize_" + std::to_string(limit));
    const std::string trace = dir + "/x.h5";
    Child run({kCli, "run", kLift, "--duration", "100", "--quiet", "--out", "x.h5"}, dir + "/run.log", dir, limit);
    const Ended e = run.wait();
    INFO("limit " << limit << " bytes\n" << e.output);
    CHECK(e.signal == 0);
    CHECK(e.status == kExitTraceFault);
    CHECK_THAT(e.output, Catch::Contains("the file would pass " + std::to_string(limit) + " bytes") &&
                             Catch::Contains("file size limit"));
    REQUIRE(exists(trace));
    CHECK(fs::file_size(trace) <= limit);
    CHECK_THAT(status_of(trace), Catch::StartsWith("error: ") && Catch::Contains("kept up to the last flush"));
    const std::int64_t n = check_whole_tables(trace);
    if (limit >= 1024 * 1024) CHECK(n >= 360);
  }
}

// ---------------------------------------------------------------------------------------------
// Items 2 and 15: two runs, one output. While run A writes out.h5 (held stopped mid-run), run B
// on the same output exits 2 with "another graspsim run is writing it" and touches nothing: the
// earlier out.h5 is byte-identical; `graspsim repair out.h5.partial` exits 2 and leaves A's
// partial trace byte-identical; and A, let go and ended by SIGTERM, finishes a trace whose
// ticks run 0, 1, 2, ... to where it stopped (B truncated none of it), status "error: interrupted
// by SIGTERM", exit 143.
TEST_CASE("catalogue: a second run on an output being written refuses and touches nothing", "[fault_catalogue][lock]") {
  const std::string dir = fresh_dir("lock");
  REQUIRE(cli_in(dir, "run " + kLift + " --quiet --out out.h5").status == 0);
  const auto earlier = file_bytes(dir + "/out.h5");
  REQUIRE(earlier);
  LongRun a(dir, "out.h5");
  REQUIRE(a.wait_for_rows());
  REQUIRE(kill(a.child.pid(), SIGSTOP) == 0);
  const Outcome b = cli_in(dir, "run " + kLift + " --quiet --out out.h5");
  INFO(b.output);
  CHECK(b.status == 2);
  CHECK_THAT(b.output, Catch::Contains("--out 'out.h5': another graspsim run is writing it") &&
                           Catch::Contains("'out.h5.partial' is locked"));
  CHECK(file_bytes(dir + "/out.h5") == earlier);
  // Nor may the partial trace be "repaired" while the run holds it.
  const auto partial = file_bytes(dir + "/out.h5.partial");
  const Outcome repair = cli_in(dir, "repair out.h5.partial");
  INFO(repair.output);
  CHECK(repair.status == 2);
  CHECK_THAT(repair.output, Catch::Contains("is being written by a graspsim run (it is locked)"));
  CHECK(file_bytes(dir + "/out.h5.partial") == partial);
  REQUIRE(kill(a.child.pid(), SIGCONT) == 0);
  REQUIRE(kill(a.child.pid(), SIGTERM) == 0);
  const Ended e = a.child.wait();
  INFO(e.output);
  CHECK(e.signal == 0);
  CHECK(e.status == 128 + SIGTERM);
  CHECK_FALSE(exists(dir + "/out.h5.partial"));
  CHECK_THAT(status_of(dir + "/out.h5"), Catch::StartsWith("error: interrupted by SIGTERM at t = "));
  CHECK(check_whole_tables(dir + "/out.h5") > 0);
  fs::remove_all(dir);
}

// SIGTERM, SIGHUP and SIGINT end a run alike: exit 128 + signal, the trace renamed to the
// output path with status "error: interrupted by SIG<name> at t = ...", whole up to there, and
// nothing left under the partial name. The earlier trace there is replaced only by that marked
// one; the file beside it is untouched.
TEST_CASE("catalogue: SIGTERM, SIGHUP and SIGINT end a run with 128 + signal and a marked trace", "[fault_catalogue][signal]") {
  for (const auto& [signal, name] : {std::pair{SIGTERM, "SIGTERM"}, std::pair{SIGHUP, "SIGHUP"}, std::pair{SIGINT, "SIGINT"}}) {
    const std::string dir = fresh_dir(std::string("signal_") + name);
    write_file(dir + "/out.h5", "an earlier file at the output path\n");
    write_file(dir + "/beside.txt", "beside\n");
    LongRun run(dir, "out.h5");
    REQUIRE(run.wait_for_rows());
    REQUIRE(kill(run.child.pid(), signal) == 0);
    const Ended e = run.child.wait();
    INFO(name << "\n" << e.output);
    CHECK(e.signal == 0);
    CHECK(e.status == 128 + signal);
    CHECK_THAT(e.output, Catch::Contains(std::string("the run stopped early: interrupted by ") + name));
    CHECK_FALSE(exists(dir + "/out.h5.partial"));
    CHECK_THAT(status_of(dir + "/out.h5"), Catch::StartsWith(std::string("error: interrupted by ") + name + " at t = "));
    CHECK(check_whole_tables(dir + "/out.h5") > 0);
    CHECK(file_bytes(dir + "/beside.txt") == std::string("beside\n"));
    fs::remove_all(dir);
  }
}

// ---------------------------------------------------------------------------------------------
// Items 3 and 4: an output that is an input. The scenario itself, a symbolic link to it, a hard
// link to it, a mesh file it reads, a replay recording a device reads (and a link to that), and
// an output whose partial name is the recording: each exits 2 naming the input, writes nothing
// (no partial), and leaves every input byte-identical.
TEST_CASE("catalogue: an output that is an input, or a link to one, is refused and nothing is written", "[fault_catalogue][inputs]") {
  const std::string dir = fresh_dir("inputs");
  fs::create_directories(dir + "/meshes");
  fs::copy_file(kSource + "/scenarios/mesh_grasp.lua", dir + "/mesh_grasp.lua");
  fs::copy_file(kSource + "/scenarios/meshes/wedge_mm.stl", dir + "/meshes/wedge_mm.stl");
  fs::copy_file(kLift, dir + "/lift.lua");
  REQUIRE(cli_in(dir, "run lift.lua --quiet --out rec.h5").status == 0);
  fs::create_symlink("lift.lua", dir + "/link.lua");
  fs::create_hard_link(dir + "/lift.lua", dir + "/hard.lua");
  fs::create_symlink("rec.h5", dir + "/rec_link.h5");
  const std::vector<std::string> inputs = {"lift.lua", "mesh_grasp.lua", "meshes/wedge_mm.stl", "rec.h5"};
  std::vector<std::optional<std::string>> before;
  for (const std::string& f : inputs) before.push_back(file_bytes(dir + "/" + f));
  struct Case {
    std::string args;
    std::string says;
  };
  const std::vector<Case> cases = {
      {"run lift.lua --out lift.lua", "--out 'lift.lua' is the scenario"},
      {"run lift.lua --out link.lua", "--out 'link.lua' is the scenario ('lift.lua')"},
      {"run lift.lua --out hard.lua", "--out 'hard.lua' is the scenario ('lift.lua')"},
      {"run mesh_grasp.lua --out meshes/wedge_mm.stl", "is a mesh file of the scenario"},
      {"run lift.lua --device thumb=replay:rec.h5 --out rec.h5", "is the replay file of finger 'thumb' ('rec.h5')"},
      {"run lift.lua --device thumb=replay:rec.h5 --out rec_link.h5", "is the replay file of finger 'thumb'"},
      {"run lift.lua --device thumb=replay:rec.h5.partial --out rec.h5", "is written as 'rec.h5.partial'"},
      {"replay rec.h5 --out rec_link.h5", "is the trace being replayed"},
  };
  for (const Case& c : cases) {
    if (c.args.find("rec.h5.partial") != std::string::npos) fs::copy_file(dir + "/rec.h5", dir + "/rec.h5.partial");
    const Outcome o = cli_in(dir, c.args + " --quiet");
    INFO("graspsim " << c.args << "\n" << o.output);
    CHECK(o.status == 2);
    CHECK_THAT(o.output, Catch::Contains(c.says));
    for (std::size_t i = 0; i < inputs.size(); ++i) CHECK(file_bytes(dir + "/" + inputs[i]) == before[i]);
    for (const char* partial : {"lift.lua.partial", "link.lua.partial", "hard.lua.partial", "meshes/wedge_mm.stl.partial",
                                       "rec_link.h5.partial"})
      CHECK_FALSE(exists(dir + "/" + std::string(partial)));
    fs::remove(dir + "/rec.h5.partial");
  }
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// An output path that is not a regular file. Every command writes beside its output and renames
// over it, which as root would put a regular file in place of a device (`--out /dev/null`: for
// every program on the machine), a FIFO or a socket. Each is refused before anything runs, exit 2,
// naming the path, what it is and how to write nothing; the thing at the path is still what it
// was, no partial is left, and nothing hangs (a FIFO opened to write would wait for a reader:
// each command runs under `timeout`). Tested where it can harm nothing: a FIFO, a socket, a
// directory and a link to the FIFO in a temporary folder (devices in the next test).
namespace {

// A Unix socket bound at `path` (closed again: the socket file stays).
bool make_socket(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  if (fd < 0) return false;
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof address.sun_path, "%s", path.c_str());
  const bool bound = ::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0;
  ::close(fd);
  return bound;
}

fs::file_type type_of(const std::string& path) {
  std::error_code ec;
  return fs::symlink_status(path, ec).type();
}

}  // namespace

TEST_CASE("catalogue: an output that is a FIFO, a socket or a directory is refused, naming how to write none",
          "[fault_catalogue][not_a_file]") {
  const std::string dir = fresh_dir("not_a_file");
  fs::copy_file(kLift, dir + "/lift.lua");
  REQUIRE(cli_in(dir, "run lift.lua --quiet --out rec.h5").status == 0);
  REQUIRE(::mkfifo((dir + "/fifo").c_str(), 0644) == 0);
  REQUIRE(make_socket(dir + "/sock"));
  fs::create_directory(dir + "/folder");
  fs::create_symlink("fifo", dir + "/fifo_link");
  REQUIRE(::mkfifo((dir + "/x.h5.partial").c_str(), 0644) == 0);
  // A finished one-run sweep whose table's name a FIFO has taken since: its --resume writes the
  // table at once, and must not replace the FIFO.
  REQUIRE(cli_in(dir, "sweep lift.lua --grid mu=1.2 --jobs 1 --out sweep").status == 0);
  fs::remove(dir + "/sweep/sweep.csv");
  REQUIRE(::mkfifo((dir + "/sweep/sweep.csv").c_str(), 0644) == 0);
  struct Case {
    std::string args;
    std::vector<std::string> says;
  };
  const std::vector<Case> cases = {
      {"run lift.lua --quiet --out fifo", {"--out 'fifo' is a FIFO, not a regular file", "--no-trace writes no trace"}},
      {"run lift.lua --quiet --out sock", {"--out 'sock' is a socket, not a regular file", "--no-trace"}},
      {"run lift.lua --quiet --out folder", {"--out 'folder' is a directory, not a regular file", "name a file in it", "--no-trace"}},
      {"run lift.lua --quiet --out fifo_link", {"--out 'fifo_link' is a symbolic link to a FIFO", "--no-trace"}},
      {"run lift.lua --quiet --out x.h5", {"written as 'x.h5.partial'", "taken by a FIFO"}},
      {"run lift.lua --no-trace --summary fifo", {"--summary 'fifo' is a FIFO", "leave out --summary to write none"}},
      {"replay rec.h5 --quiet --out fifo", {"--out 'fifo' is a FIFO", "a replay writes its trace", "name a file with --out"}},
      {"replay rec.h5 --quiet --out sock", {"--out 'sock' is a socket"}},
      {"sweep lift.lua --grid mu=0.5 --out fifo", {"--out fifo is a FIFO, not a folder"}},
      {"sweep lift.lua --grid mu=1.2 --jobs 1 --out sweep --resume", {"sweep/sweep.csv is a FIFO, not a regular file"}},
  };
  for (const Case& c : cases) {
    const Outcome o = graspsim::test::shell("cd '" + dir + "' && timeout 60 " + kCli + " " + c.args);
    INFO("graspsim " << c.args << "\n" << o.output);
    CHECK(o.status == 2);
    for (const std::string& s : c.says) CHECK_THAT(o.output, Catch::Contains(s));
    CHECK(type_of(dir + "/fifo") == fs::file_type::fifo);
    CHECK(type_of(dir + "/sock") == fs::file_type::socket);
    CHECK(type_of(dir + "/folder") == fs::file_type::directory);
    CHECK(type_of(dir + "/fifo_link") == fs::file_type::symlink);
    CHECK(type_of(dir + "/x.h5.partial") == fs::file_type::fifo);
    CHECK(type_of(dir + "/sweep/sweep.csv") == fs::file_type::fifo);
    for (const char* partial : {"fifo.partial", "sock.partial", "folder.partial", "fifo_link.partial"})
      CHECK_FALSE(exists(dir + "/" + std::string(partial)));
    CHECK(fs::is_empty(dir + "/folder"));
  }
  fs::remove_all(dir);
}

// The devices themselves, /dev/null and /dev/full, only where they can harm nothing: in a mount
// namespace of the test's own (`unshare -m`, propagation private) with a tmpfs of its own on
// /dev holding fresh device nodes (mknod 1,3 and 1,7). The script checks that it runs in another
// mount namespace than the test's before it mounts anything; the machine's /dev is never
// touched. Skipped, saying why, where the namespace, the tmpfs or the nodes cannot be made
// (unshare missing, not root, no CAP_SYS_ADMIN or CAP_MKNOD).
TEST_CASE("catalogue: --out /dev/null and /dev/full are refused, in a private /dev", "[fault_catalogue][not_a_file]") {
  char outer[64] = {};
  REQUIRE(::readlink("/proc/self/ns/mnt", outer, sizeof outer - 1) > 0);
  const std::string script =
      "set -u\n"
      "[ \"$(readlink /proc/self/ns/mnt)\" != \"$GRASPSIM_OUTER_NS\" ] || { echo 'not in a new mount namespace'; exit 77; }\n"
      "mount --make-rprivate / || { echo 'cannot make the namespace private'; exit 77; }\n"
      "mount -t tmpfs -o size=1m,mode=755 graspsim-test-dev /dev || { echo 'cannot mount a tmpfs on /dev'; exit 77; }\n"
      "mknod -m 666 /dev/null c 1 3 && mknod -m 666 /dev/full c 1 7 || { echo 'cannot make device nodes'; exit 77; }\n"
      "for dev in /dev/null /dev/full; do\n"
      "  \"$GRASPSIM_CLI\" run \"$GRASPSIM_LIFT\" --quiet --out $dev; echo \"exit $dev $?\"\n"
      "  [ -c $dev ] && echo \"still a device: $dev\"\n"
      "done\n"
      "echo \"left in /dev: $(ls -A /dev | tr '\\n' ' ')\"\n";
  const std::string dir = fresh_dir("dev_null");
  write_file(dir + "/private_dev.sh", script);
  const Outcome o = graspsim::test::shell("cd '" + dir + "' && GRASPSIM_OUTER_NS='" + std::string(outer) +
                                          "' GRASPSIM_CLI='" + kCli + "' GRASPSIM_LIFT='" + kLift +
                                          "' timeout 120 unshare -m --propagation private sh private_dev.sh");
  INFO(o.output);
  if (o.status == 77 || o.output.find("unshare: ") != std::string::npos)
    GRASPSIM_SKIP("no private /dev to test in: " << o.output);
  REQUIRE(o.status == 0);
  for (const std::string dev : {"/dev/null", "/dev/full"}) {
    CHECK_THAT(o.output, Catch::Contains("--out '" + dev + "' is a character device, not a regular file"));
    CHECK_THAT(o.output, Catch::Contains("exit " + dev + " 2"));
    CHECK_THAT(o.output, Catch::Contains("still a device: " + dev));
  }
  CHECK_THAT(o.output, Catch::Contains("left in /dev: full null \n"));
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// A device that cannot be opened at the start. With an earlier trace at the default
// output path (two_finger_lift.h5 in the working directory), each bad device exits 2 with "the
// run could not start" and "nothing was written", and that trace is byte-identical; no partial
// is left.
TEST_CASE("catalogue: a device error at the start leaves an earlier trace at the output path untouched", "[fault_catalogue][devices]") {
  const std::string dir = fresh_dir("device_start");
  REQUIRE(cli_in(dir, "run " + kLift + " --quiet").status == 0);
  const auto earlier = file_bytes(dir + "/two_finger_lift.h5");
  REQUIRE(earlier);
  struct Case {
    std::string spec;
    std::string says;
  };
  const std::vector<Case> cases = {
      {"udp:no.such.host.invalid:7000", "cannot resolve host 'no.such.host.invalid'"},
      {"replay:typo.h5", "typo.h5"},
      {"sim-phantom:nosuch", "unknown device model \"nosuch\""},
      {"phantom:X", "OpenHaptics device \"X\""},
  };
  for (const Case& c : cases) {
    const Outcome o = cli_in(dir, "run " + kLift + " --quiet --device thumb=" + c.spec);
    INFO(c.spec << "\n" << o.output);
    CHECK(o.status == 2);
    CHECK_THAT(o.output, Catch::Contains("the run could not start") && Catch::Contains(c.says) &&
                             Catch::Contains("nothing was written"));
    CHECK(file_bytes(dir + "/two_finger_lift.h5") == earlier);
    CHECK_FALSE(exists(dir + "/two_finger_lift.h5.partial"));
  }
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// The default output name comes from the scenario's `name`, sanitised
// (app::default_trace_name): bytes outside [A-Za-z0-9_.-] become '_', and so does a '.' first,
// last or after a '.'. Each name writes exactly one file, the expected one, in the working
// directory, and nothing outside it (its parent, or the absolute path the name spelled).
TEST_CASE("catalogue: default output names stay inside the working directory", "[fault_catalogue][names]") {
  const std::string root = fresh_dir("names");
  const std::string absolute = "/tmp/graspsim_catalogue_x";   // a name that spells a path outside
  fs::remove(absolute + ".h5");
  struct Case {
    std::string name;   // Lua string literal contents
    std::string file;   // the trace it must write
  };
  const std::vector<Case> cases = {
      {"../x", "___x.h5"},
      {absolute, "_tmp_graspsim_catalogue_x.h5"},
      {".hidden", "_hidden.h5"},
      {"a/../../b", "a_.__.__b.h5"},
      {"..", "__.h5"},
      {"c\\1d", "c_d.h5"},   // a control character (Lua's "\1")
      {"", "trace.h5"},
      {"ok-name_1.2", "ok-name_1.2.h5"},
  };
  for (const Case& c : cases) {
    fs::remove_all(root + "/cwd");
    fs::create_directories(root + "/cwd");
    write_file(root + "/s.lua", one_box(c.name));
    const Outcome o = cli_in(root + "/cwd", "run ../s.lua --quiet");
    INFO("name \"" << c.name << "\"\n" << o.output);
    CHECK(o.status == 0);
    std::vector<std::string> written;
    for (const auto& entry : fs::directory_iterator(root + "/cwd")) written.push_back(entry.path().filename().string());
    CHECK(written == std::vector<std::string>{c.file});
    std::vector<std::string> parent;
    for (const auto& entry : fs::directory_iterator(root)) parent.push_back(entry.path().filename().string());
    std::sort(parent.begin(), parent.end());
    CHECK(parent == std::vector<std::string>{"cwd", "s.lua"});
    CHECK_FALSE(exists(absolute + ".h5"));
    CHECK_FALSE(exists(root + "/../x.h5"));
  }
  fs::remove_all(root);
}

// ---------------------------------------------------------------------------------------------
// kill -9 loses less than 0.25 s of simulated time, however far the writer lags. The
// run's rule (app/run_trace.cpp): a flush every 360 servo ticks (0.12 s at 3000 Hz), and each
// flush waits until the one before it is on disk. So at any tick n the file holds every tick up
// to the flush before last: n - (rows on disk) < 2 x 360 = 720 ticks < 0.25 s x 3000 Hz = 750.
// The run is forked from this test and killed with SIGKILL by its own thumb device when that is
// read for tick `kill_at` (rows 0 .. kill_at - 1 recorded). A slow disk is made by this
// executable's own pwrite (HDF5's writes go through it: a program's definition comes before
// libc's), which sleeps `delay` ms per call in the forked run: the writer thread lags, the loop
// does not. Swept over the kill tick and the delay. Without the wait the writer falls behind by
// up to its pool of 4 blocks per table: with the wait removed this test loses 782 and 1140 ticks
// (two tries) at no delay and 1502 (0.50 s) at 1 and 5 ms, and fails.
namespace {

std::atomic<int> g_pwrite_delay_ms{0};   // ms per pwrite of this process (0: none)

// A scripted finger that kills its own process (SIGKILL, as kill -9) when read for one tick.
class KillingFinger : public hw::Device {
 public:
  KillingFinger(std::unique_ptr<hw::Device> inner, std::int64_t kill_at) : inner_(std::move(inner)), kill_at_(kill_at) {}
  hw::DeviceSample read(std::int64_t tick, double time) override {
    if (tick == kill_at_) std::raise(SIGKILL);
    return inner_->read(tick, time);
  }
  hw::DeviceLimits limits() const override { return inner_->limits(); }
  std::string describe() const override { return inner_->describe(); }

 protected:
  void output(const hw::Vec3& force) override { inner_->render(force); }

 private:
  std::unique_ptr<hw::Device> inner_;
  std::int64_t kill_at_;
};

}  // namespace

// The slow disk: every pwrite of this process (libhdf5's sec2 driver writes with pwrite) waits
// g_pwrite_delay_ms first, then writes through the system call.
extern "C" ssize_t pwrite(int fd, const void* buffer, std::size_t bytes, off_t offset) {
  if (const int delay = g_pwrite_delay_ms.load(); delay > 0) std::this_thread::sleep_for(std::chrono::milliseconds(delay));
  return static_cast<ssize_t>(syscall(SYS_pwrite64, fd, buffer, bytes, offset));
}

TEST_CASE("catalogue: kill -9 loses under 0.25 s of simulated time however far the writer lags", "[fault_catalogue][crash]") {
  constexpr std::int64_t kBound = 750;   // ticks: 0.25 s at 3000 Hz
  const auto scenario = scripting::Scenario::load(kLift);
  for (const int delay : {0, 1, 5}) {
    std::int64_t worst = 0;
    for (const std::int64_t kill_at : {std::int64_t{1500}, std::int64_t{2222}, std::int64_t{4321}}) {
      const std::string out = kTmp + "/catalogue_kill9.h5";
      fs::remove(out);
      fs::remove(out + ".partial");
      const pid_t child = fork();
      REQUIRE(child >= 0);
      if (child == 0) {
        g_pwrite_delay_ms.store(delay);
        app::RunOptions options;
        options.out = out;
        options.devices.make = [&](std::size_t f) -> std::unique_ptr<hw::Device> {
          auto finger = std::make_unique<hw::ScriptedFinger>(scenario.make_trajectory(f), scenario.fingers()[f].limits);
          if (f != 0) return finger;
          return std::make_unique<KillingFinger>(std::move(finger), kill_at);
        };
        app::run_scenario(scenario, options);
        _exit(99);   // not reached: the thumb kills the run first
      }
      int raw = 0;
      REQUIRE(waitpid(child, &raw, 0) == child);
      REQUIRE(WIFSIGNALED(raw));
      REQUIRE(WTERMSIG(raw) == SIGKILL);
      CHECK_FALSE(exists(out));   // never renamed: the kept trace is the partial
      const std::string cut = out + ".partial";
      CHECK(status_of(cut) == "running");
      const std::int64_t kept = check_whole_tables(cut);
      const std::int64_t lost = kill_at - kept;
      INFO("pwrite delay " << delay << " ms, killed at tick " << kill_at << ": " << kept << " ticks kept, " << lost << " lost");
      CHECK(lost >= 0);
      CHECK(lost < kBound);
      worst = std::max(worst, lost);
      fs::remove(cut);
    }
    std::printf("kill -9 with a pwrite delay of %d ms: at most %lld ticks (%.3f s) lost\n", delay,
                static_cast<long long>(worst), static_cast<double>(worst) / 3000.0);
  }
}
