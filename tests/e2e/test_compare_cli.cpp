// `graspsim compare` as a user meets it, on real traces of the two-finger lift: identical runs
// compare equal bit for bit, a 1e-9 m change written into one trace in place (trace_edit.hpp) is
// found at its tick, time, object and component (exit 1), tolerances decide, --json is valid
// JSON, and every kind of unusable input exits 2 with a message naming the file or dataset.
#include <catch2/catch.hpp>

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <chrono>
#include <csignal>
#include <string>
#include <sys/wait.h>
#include <thread>

#include "app/json.hpp"
#include "tests/support/process.hpp"
#include "tests/support/shell.hpp"
#include "tests/support/skip.hpp"
#include "tests/support/trace_edit.hpp"

namespace {

const std::string kCli = GRASPSIM_CLI;
const std::string kSource = GRASPSIM_SOURCE_DIR;
const std::string kTmp = GRASPSIM_TEST_TMP;

using graspsim::test::Outcome;

Outcome cli(const std::string& args, bool with_stderr = true) {
  return graspsim::test::shell(kCli + " " + args, with_stderr);
}

// Runs the two-finger lift (4 s) into `out`, with extra arguments.
void run_lift(const std::string& out, const std::string& extra = "") {
  const Outcome o = cli("run " + kSource + "/scenarios/two_finger_lift.lua --quiet --out " +
                        out + " " + extra);
  INFO(o.output);
  REQUIRE(o.status == 0);
  REQUIRE(std::filesystem::exists(out));
}

// Adds `delta` to element (row, column) of column `path`, returning the new value.
double nudge(const std::string& file, const std::string& path, std::uint64_t row, std::uint64_t column,
             double delta) {
  return graspsim::test::add_to_element(file, path, row, column, delta);
}

// A minimal JSON syntax checker (RFC 8259 grammar; numbers loosely): true if `text` is one
// JSON value with only whitespace around it.
class JsonChecker {
 public:
  explicit JsonChecker(const std::string& text) : s_(text) {}
  bool valid() {
    skip();
    if (!value()) return false;
    skip();
    return i_ == s_.size();
  }

 private:
  void skip() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  bool literal(const char* word) {
    const std::string w = word;
    if (s_.compare(i_, w.size(), w) != 0) return false;
    i_ += w.size();
    return true;
  }
  bool string() {
    if (i_ >= s_.size() || s_[i_] != '"') return false;
    for (++i_; i_ < s_.size(); ++i_) {
      const unsigned char c = static_cast<unsigned char>(s_[i_]);
      if (c == '"') return ++i_, true;
      if (c < 0x20) return false;
      if (c == '\\') ++i_;
    }
    return false;
  }
  bool number() {
    const std::size_t start = i_;
    if (i_ < s_.size() && s_[i_] == '-') ++i_;
    while (i_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[i_])) || s_[i_] == '.' ||
                              s_[i_] == 'e' || s_[i_] == 'E' || s_[i_] == '+' || s_[i_] == '-'))
      ++i_;
    return i_ > start && std::isdigit(static_cast<unsigned char>(s_[i_ - 1]));
  }
  bool value() {
    skip();
    if (i_ >= s_.size()) return false;
    const char c = s_[i_];
    if (c == '{') return compound('}', true);
    if (c == '[') return compound(']', false);
    if (c == '"') return string();
    if (c == 't') return literal("true");
    if (c == 'f') return literal("false");
    if (c == 'n') return literal("null");
    return number();
  }
  bool compound(char close, bool object) {
    ++i_;
    skip();
    if (i_ < s_.size() && s_[i_] == close) return ++i_, true;
    while (true) {
      skip();
      if (object) {
        if (!string()) return false;
        skip();
        if (i_ >= s_.size() || s_[i_++] != ':') return false;
      }
      if (!value()) return false;
      skip();
      if (i_ >= s_.size()) return false;
      if (s_[i_] == ',') { ++i_; continue; }
      if (s_[i_] == close) return ++i_, true;
      return false;
    }
  }
  const std::string& s_;
  std::size_t i_ = 0;
};

}  // namespace

TEST_CASE("the JSON checker of this test accepts JSON and refuses broken text", "[compare_cli]") {
  CHECK(JsonChecker(R"({"a": [1, -2.5e-9, "x\"y", null, true, {}], "b": {"c": []}})").valid());
  CHECK_FALSE(JsonChecker(R"({"a": 1,})").valid());
  CHECK_FALSE(JsonChecker(R"({"a": nan})").valid());
  CHECK_FALSE(JsonChecker(R"({"a": "x
"})").valid());
  CHECK_FALSE(JsonChecker(R"({"a": 1} x)").valid());
}

TEST_CASE("graspsim compare finds a 1e-9 m change at its tick, time, object and component", "[compare_cli]") {
  const std::string a = kTmp + "/compare_cli_a.h5", b = kTmp + "/compare_cli_b.h5";
  run_lift(a);
  run_lift(b);

  // Two runs of the same scenario: bitwise identical (root attributes that differ, such as a
  // wall-clock one, would only be notes).
  Outcome o = cli("compare " + a + " " + b + " --bitwise");
  INFO(o.output);
  CHECK(o.status == 0);
  CHECK_THAT(o.output, Catch::Contains("SAME: bitwise identical"));

  // Physics row 20 is servo tick 20 * (servo rate / physics rate).
  nudge(b, "/physics/objects/box/position", 20, 2, 1e-9);
  o = cli("compare " + a + " " + b);
  INFO(o.output);
  CHECK(o.status == 1);
  const std::string first_line = "DIFFERENT: 1 of ";
  CHECK_THAT(o.output, Catch::Contains(first_line));
  // The rates, from the JSON of a comparison of A with itself (not assumed here).
  const Outcome rates = cli("compare " + a + " " + a + " --json", false);
  const auto servo_at = rates.output.find("\"servo\": ");
  const auto physics_at = rates.output.find("\"physics\": ");
  REQUIRE(servo_at != std::string::npos);
  REQUIRE(physics_at != std::string::npos);
  const long servo = std::stol(rates.output.substr(servo_at + 9));
  const long physics = std::stol(rates.output.substr(physics_at + 11));
  const long tick = 20 * (servo / physics);
  char time[64];
  std::snprintf(time, sizeof time, "t = %.6g s", static_cast<double>(tick) / servo);
  CHECK_THAT(o.output, Catch::Contains("first at physics tick " + std::to_string(tick) + " (" + time +
                                       "): object box position z"));

  // A tolerance above the change passes, one below fails; a per-dataset one overrides.
  CHECK(cli("compare " + a + " " + b + " --atol 2e-9").status == 0);
  CHECK(cli("compare " + a + " " + b + " --atol 5e-10").status == 1);
  CHECK(cli("compare " + a + " " + b + " --tol physics/objects/box/position=2e-9").status == 0);
  CHECK(cli("compare " + a + " " + b + " --atol 1 --tol 'physics/objects/box/*=1e-10'").status == 1);
  CHECK(cli("compare " + a + " " + b + " --tol 'physics/*=1e-10,1e-6'").status == 0);   // rtol

  // --json: valid JSON naming the tick, dataset, object and component.
  o = cli("compare " + a + " " + b + " --json", false);
  INFO(o.output);
  CHECK(o.status == 1);
  CHECK(JsonChecker(o.output).valid());
  CHECK_THAT(o.output, Catch::Contains("\"same\": false"));
  CHECK_THAT(o.output, Catch::Contains("\"exit_code\": 1"));
  CHECK_THAT(o.output, Catch::Contains("\"differing_datasets\": 1,"));
  CHECK_THAT(o.output, Catch::Contains("{\"path\": \"physics/objects/box/position\", \"loop\": \"physics\", "
                                       "\"kind\": \"object\", \"name\": \"box\", \"quantity\": \"position\""));
  CHECK_THAT(o.output, Catch::Contains("\"first\": {\"tick\": " + std::to_string(tick) + ", "));
  CHECK_THAT(o.output, Catch::Contains("\"component\": \"z\""));
  // The identical comparison is valid JSON too.
  CHECK(JsonChecker(rates.output).valid());
  CHECK_THAT(rates.output, Catch::Contains("\"same\": true"));
}

TEST_CASE("graspsim compare refuses unusable input with exit status 2", "[compare_cli][bad_input]") {
  const std::string a = kTmp + "/compare_cli_bad_a.h5";
  run_lift(a);
  const std::string physics100 = kTmp + "/compare_cli_bad_rate.h5";
  run_lift(physics100, "--set rates.physics=100");
  const std::string text = kTmp + "/compare_cli_text.h5";
  std::ofstream(text) << "hello\n";
  const std::string cut = kTmp + "/compare_cli_cut.h5";
  std::filesystem::remove(cut);
  std::filesystem::copy_file(a, cut);
  std::filesystem::resize_file(cut, std::filesystem::file_size(a) / 3);
  // A copy without one dataset.
  const std::string fewer = kTmp + "/compare_cli_fewer.h5";
  std::filesystem::remove(fewer);
  std::filesystem::copy_file(a, fewer);
  graspsim::test::drop_column(fewer, "/physics", "objects/box/torque");

  struct Case { std::string args; std::vector<std::string> says; };
  const std::vector<Case> cases = {
      {"compare " + a, {"two trace files"}},
      {"compare " + a + " " + kTmp + "/compare_nowhere.h5", {"compare_nowhere.h5", "no such file"}},
      {"compare " + a + " " + text, {"compare_cli_text.h5", "not an HDF5 file"}},
      {"compare " + cut + " " + a, {"compare_cli_cut.h5"}},
      {"compare " + a + " " + physics100, {"different rates", "/ 100 Hz", "compare_cli_bad_rate.h5"}},
      {"compare " + a + " " + fewer, {"'/physics/objects/box/torque'", "missing in '" + fewer + "'"}},
      {"compare " + a + " " + a + " --tol nothing/here=1", {"'nothing/here' matches no dataset"}},
      {"compare " + a + " " + a + " --tol box=", {"--tol needs PATTERN=ATOL"}},
      {"compare " + a + " " + a + " --atol -1", {"--atol needs a number >= 0"}},
      {"compare " + a + " " + a + " --bitwise --atol 1", {"--bitwise"}},
  };
  for (const Case& c : cases) {
    const Outcome o = cli(c.args);
    INFO("graspsim " << c.args << "\n" << o.output);
    CHECK(o.status == 2);
    for (const std::string& s : c.says) CHECK_THAT(o.output, Catch::Contains(s));
  }
  // With --json the error is a JSON object on stdout as well.
  const Outcome o = cli("compare " + a + " " + text + " --json", false);
  CHECK(o.status == 2);
  CHECK(JsonChecker(o.output).valid());
  CHECK_THAT(o.output, Catch::Contains("\"exit_code\": 2"));
  // The inputs are left as they were.
  CHECK(std::filesystem::file_size(text) == 6);
}

TEST_CASE("graspsim compare --help explains tolerances, exit codes and h5diff", "[compare_cli]") {
  const Outcome o = cli("compare --help");
  CHECK(o.status == 0);
  for (const char* s : {"--atol", "--rtol", "--tol PATTERN=ATOL", "--bitwise", "--json", "--attributes",
                        "exit status", "h5diff", "servo/*"})
    CHECK_THAT(o.output, Catch::Contains(s));
}

// Two files whose /physics is missing, or a scalar dataset where the table should be, are not
// "the same": compare_traces compares the tables both hold (here /servo and /haptic, equal) and
// passes over the rest, so without a check they compared equal, exit 0. Each trace's root
// attribute `record` names physics, so a table with a tick column must be there: exit 2, naming
// the file and what is wrong. A trace that did not --record physics still compares (exit 0).
TEST_CASE("graspsim compare refuses traces whose /physics is missing or a scalar", "[compare_cli][bad_input]") {
  if (graspsim::test::shell("/usr/bin/python3 -c 'import h5py'").status != 0)
    GRASPSIM_SKIP("no python3-h5py to edit the traces with");
  const std::string a = kTmp + "/compare_cli_physics_a.h5";
  run_lift(a);
  const auto edited = [&](const std::string& name, const std::string& edit) {
    const std::string path = kTmp + "/compare_cli_physics_" + name + ".h5";
    std::filesystem::remove(path);
    std::filesystem::copy_file(a, path);
    const Outcome o = graspsim::test::shell("/usr/bin/python3 -c \"import h5py, sys; f = h5py.File(sys.argv[1], 'a'); " +
                                            edit + "\" " + path);
    INFO(o.output);
    REQUIRE(o.status == 0);
    return path;
  };
  const std::string missing = edited("missing", "del f['physics']");
  const std::string scalar = edited("scalar", "del f['physics']; f['physics'] = 0.0");
  struct Case {
    std::string a, b, says;
  };
  for (const Case& c : {Case{missing, missing, "/physics is missing"}, Case{scalar, scalar, "/physics is a plain dataset"},
                        Case{a, missing, "/physics is missing"}, Case{scalar, a, "/physics is a plain dataset"}}) {
    for (const std::string json : {"", " --json"}) {
      const Outcome o = cli("compare " + c.a + " " + c.b + json);
      INFO("compare " << c.a << " " << c.b << json << "\n" << o.output);
      CHECK(o.status == 2);
      CHECK_THAT(o.output, Catch::Contains("is not a whole graspsim trace: " + c.says) &&
                               Catch::Contains("its root attribute record is 'servo:1,haptic:1,physics:1,devices:1'"));
    }
  }
  const std::string servo_only = kTmp + "/compare_cli_servo_only.h5";
  run_lift(servo_only, "--record servo,haptic");
  CHECK(cli("compare " + servo_only + " " + servo_only).status == 0);
}

// compare --view serves the page where --port says, as `graspsim view` does (0: any free port,
// printed); stopped by SIGINT it exits 0.
TEST_CASE("graspsim compare --view takes --port", "[compare_cli][view]") {
  const std::string a = kTmp + "/compare_cli_view.h5";
  run_lift(a);
  const std::string log = kTmp + "/compare_cli_view.log";
  graspsim::test::Child child({kCli, "compare", a, a, "--view", "--port", "0"}, log);
  std::string printed;
  for (int i = 0; i < 6000 && child.running(); ++i) {   // until it prints its URL (at most 60 s)
    printed = graspsim::test::file_bytes(log).value_or("");
    if (printed.find("url  http://127.0.0.1:") != std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  INFO(printed);
  REQUIRE_THAT(printed, Catch::Contains("SAME") && Catch::Contains("url  http://127.0.0.1:"));
  CHECK_THAT(printed, !Catch::Contains("http://127.0.0.1:8717/"));   // not the default: any free port
  REQUIRE(kill(child.pid(), SIGINT) == 0);
  const graspsim::test::Ended e = child.wait();
  CHECK(e.status == 0);
}

// The one JSON escaper (app/json.hpp), which compare's --json and the view's scene both use:
// quotes and backslashes escaped, control bytes as \n \r \t or \u00XX, the rest as it is.
TEST_CASE("the JSON escaper escapes what RFC 8259 requires and keeps the rest", "[compare_cli][json]") {
  CHECK(graspsim::app::json_string("") == "\"\"");
  CHECK(graspsim::app::json_string("box \"a\" \\ b") == "\"box \\\"a\\\" \\\\ b\"");
  CHECK(graspsim::app::json_string("l1\nl2\r\t") == "\"l1\\nl2\\r\\t\"");
  CHECK(graspsim::app::json_string(std::string("\x01\x1f\x7f", 3)) == "\"\\u0001\\u001f\x7f\"");
  CHECK(graspsim::app::json_string("caf\xc3\xa9") == "\"caf\xc3\xa9\"");
  CHECK(JsonChecker(graspsim::app::json_string(std::string("\0\b\f/x", 5))).valid());
}
