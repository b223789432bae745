// `graspsim run --summary FILE` (README.md "Exit status"): a summary that cannot be written is
// an output fault (exit 3, the reason with strerror), not a pass a sweep would record with no
// expectation read; and a file already at FILE.partial, the name the summary is written under,
// is refused before the run (exit 2) and kept byte for byte.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/shell.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kCli = GRASPSIM_CLI;
const std::string kLift = std::string(GRASPSIM_SOURCE_DIR) + "/scenarios/two_finger_lift.lua";

std::string fresh_dir(const std::string& name) {
  const std::string dir = std::string(GRASPSIM_TEST_TMP) + "/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string contents(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST_CASE("run --summary: an unwritable summary exits 3 naming the file and why", "[summary]") {
  // The lift passes (exit 0 with a writable summary, the control); a summary in a folder that is
  // not there cannot be created: ENOENT's text must be in the message.
  const std::string dir = fresh_dir("summary_unwritable");
  const auto ok = graspsim::test::shell(kCli + " run " + kLift + " --no-trace --quiet --summary " + dir + "/s.txt");
  CHECK(ok.status == 0);
  CHECK(contents(dir + "/s.txt").rfind("PASS\t", 0) == 0);
  const auto bad = graspsim::test::shell(kCli + " run " + kLift + " --no-trace --quiet --summary " + dir + "/no/s.txt");
  INFO(bad.output);
  CHECK(bad.status == 3);
  CHECK_THAT(bad.output, Catch::Contains(dir + "/no/s.txt.partial") && Catch::Contains("No such file or directory"));
}

TEST_CASE("run --summary: a file already at FILE.partial is refused with exit 2 and kept", "[summary][bad_input]") {
  const std::string dir = fresh_dir("summary_partial_kept");
  std::ofstream(dir + "/s.txt.partial") << "a user's notes";
  const auto o = graspsim::test::shell(kCli + " run " + kLift + " --no-trace --quiet --summary " + dir + "/s.txt");
  INFO(o.output);
  CHECK(o.status == 2);
  CHECK_THAT(o.output, Catch::Contains("--summary " + dir + "/s.txt is written as " + dir + "/s.txt.partial"));
  CHECK(contents(dir + "/s.txt.partial") == "a user's notes");
  CHECK_FALSE(fs::exists(dir + "/s.txt"));
}
