// CI smoke run of the work-precision benchmark (README.md, "Speed against error"): graspsim_bench
// --quick runs, exits 0, and writes bench.csv and stability.csv with the expected columns, one
// row per case x rate x gyroscopic option (the hard cases) or x scheme (the contact accuracy
// cases), finite numbers where they must be, and prints the contact accuracy table. Its times are
// not checked (a shared CI machine times nothing reliably); only that they are positive and finite.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

std::vector<std::vector<std::string>> read_csv(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) rows.push_back(split(line));
  return rows;
}

bool finite_number(const std::string& s) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  return !s.empty() && *end == '\0' && std::isfinite(v);
}

}  // namespace

TEST_CASE("graspsim_bench --quick writes the work-precision CSV and the stability table", "[bench]") {
  const std::string dir = GRASPSIM_TEST_TMP "/bench-smoke";
  std::filesystem::remove_all(dir);
  const std::string cmd = std::string(GRASPSIM_BENCH) + " --quick --out " + dir + " > " + dir + ".log 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);

  const auto bench = read_csv(dir + "/bench.csv");
  REQUIRE(bench.size() > 1);
  const std::vector<std::string> header{"case", "rate_hz", "integrator", "status", "wall_per_sim_s", "wall_min",
                                        "wall_max", "cpu_per_sim_s", "repeats", "error", "error_measure", "energy_drift",
                                        "momentum_drift", "period_s", "period_ref_s", "precession_rad_s",
                                        "precession_ref_rad_s", "note", "scheme"};
  REQUIRE(bench[0] == header);
  // 4 hard cases x 3 rates (quick: 50, 500, 3000 Hz) x 3 gyroscopic options, and 4 contact
  // accuracy cases x 3 rates x 2 schemes, each once.
  CHECK(bench.size() == 1 + 4 * 3 * 3 + 4 * 3 * 2);
  const std::set<std::string> contact{"cube_rest", "slope_stick", "slope_slide", "cube_settle"};
  std::set<std::string> seen;
  for (std::size_t i = 1; i < bench.size(); ++i) {
    const auto& r = bench[i];
    INFO("row " << i << ": " << r[0] << " " << r[1] << " Hz " << r[2] << " " << r[3]);
    REQUIRE(r.size() == header.size());
    CHECK(seen.insert(r[0] + "/" + r[1] + "/" + r[2] + "/" + r[18]).second);
    CHECK(finite_number(r[1]));
    CHECK((r[2] == "neglect" || r[2] == "explicit" || r[2] == "implicit"));
    CHECK((r[3] == "ok" || r[3].rfind("unstable: ", 0) == 0));
    for (int c : {4, 5, 6, 7}) {
      CHECK(finite_number(r[c]));
      CHECK(std::strtod(r[c].c_str(), nullptr) > 0.0);
    }
    CHECK(r[8] == "1");
    if (r[3] == "ok") CHECK(finite_number(r[9]));   // an unstable run may have an infinite error
    CHECK(!r[10].empty());
    CHECK((r[18] == "paper" || r[18] == "implicit"));
    // The schemes of the contact scenes both run (the status is "ok" or "unstable: ...", never
    // "refused: ..."): the implicit one accepts unset stiffness, the paper one has its soft floor.
    if (contact.count(r[0])) CHECK(finite_number(r[9]));
  }
  std::ifstream log(dir + ".log");
  const std::string printed((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  CHECK(printed.find("contact accuracy: 10 cm, 1 kg cube") != std::string::npos);
  const auto stab = read_csv(dir + "/stability.csv");
  REQUIRE(stab.size() == 1 + 3 * 3);
  CHECK(stab[0] == std::vector<std::string>{"rate_hz", "integrator", "k_max_n_per_m", "estimate_n_per_m"});
  for (std::size_t i = 1; i < stab.size(); ++i) {
    REQUIRE(stab[i].size() == 4);
    CHECK(finite_number(stab[i][2]));
    CHECK(std::strtod(stab[i][2].c_str(), nullptr) > 0.0);
  }
}

// The robustness case on one scenario, two seeds: robustness.csv has, per integrator, one row per
// expectation (the lift has 5) and per run check (4), each passed in at most `runs` runs, and the
// worst body excursion, a finite positive length (the lift moves its box 5 cm at least).
TEST_CASE("graspsim_bench --cases robustness writes pass rates per check and integrator", "[bench]") {
  const std::string dir = GRASPSIM_TEST_TMP "/bench-smoke-robustness";
  std::filesystem::remove_all(dir);
  const std::string cmd = std::string(GRASPSIM_BENCH) + " --cases robustness --seeds 2 --scenarios two_finger_lift --out " +
                          dir + " > " + dir + ".log 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  // A check's sentence is quoted (it may hold commas): split outside quotes.
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(dir + "/robustness.csv");
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells(1);
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      else if (c == ',' && !quoted) cells.emplace_back();
      else cells.back() += c;
    }
    rows.push_back(cells);
  }
  REQUIRE(rows.size() == 1 + 2 * (5 + 4 + 1));
  CHECK(rows[0] == std::vector<std::string>{"scenario", "integrator", "check", "passed", "runs", "value"});
  std::set<std::string> integrators;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const auto& r = rows[i];
    INFO("row " << i << ": " << r[2]);
    REQUIRE(r.size() == 6);
    CHECK(r[0] == "two_finger_lift");
    integrators.insert(r[1]);
    if (r[2] == "worst body excursion m") {
      CHECK(finite_number(r[5]));
      CHECK(std::strtod(r[5].c_str(), nullptr) > 0.05);
    } else {
      const long passed = std::strtol(r[3].c_str(), nullptr, 10);
      CHECK(r[4] == "2");
      CHECK(passed >= 0);
      CHECK(passed <= 2);
    }
  }
  CHECK(integrators == std::set<std::string>{"paper", "implicit"});
}
