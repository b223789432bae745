// The sweep's bookkeeping (app/sweep_*.hpp), without running anything: which run is which grid
// point and seed, what each run is given, how a grid is read, and that rows, summaries and the
// CSV read back what was written, whatever text an expectation holds.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "app/sweep_exec.hpp"
#include "app/sweep_plan.hpp"
#include "app/sweep_row.hpp"
#include "app/sweep_table.hpp"

namespace {

using namespace graspsim::app::sweep;

Plan two_by_three_by_two() {
  Plan plan;
  plan.scenario = "/s/lift.lua";
  plan.grid = {{"mu", {"0.2", "0.6"}}, {"mass", {"0.2", "0.4", "0.8"}}};
  plan.seeds = 2;
  return plan;
}

}  // namespace

TEST_CASE("a sweep's runs are its grid's cross product times its seeds, the seed changing fastest",
          "[sweep]") {
  // 2 x 3 points x 2 seeds = 12 runs; run 7 = point 3 (mu 0.6, mass 0.2), seed 1.
  const Plan plan = two_by_three_by_two();
  REQUIRE(plan.size() == 12);
  const Plan::Run r = plan.run(7);
  CHECK(r.values == std::vector<std::string>{"0.6", "0.2"});
  CHECK(r.seed == 1u);
  CHECK(plan.run(11).values == std::vector<std::string>{"0.6", "0.8"});
  // Each run gets its point as --set, its seed as --jitter-seed with the sweep's amplitude, and
  // no trace unless --keep-traces.
  const std::vector<std::string> args = plan.run_arguments(7, "/d");
  const std::vector<std::string> expected{"run", "/s/lift.lua", "--set", "mu=0.6", "--set", "mass=0.2",
                                          "--jitter", "0.00050000000000000001", "--jitter-seed", "1",
                                          "--no-trace", "--quiet", "--summary", "/d/runs/0007.summary"};
  CHECK(args == expected);
}

TEST_CASE("a grid is NAME=V1,V2 (semicolons when a value holds commas), and a bad one is refused naming the --grid", "[sweep]") {
  CHECK(parse_axis("mu=0.2,0.6").values == std::vector<std::string>{"0.2", "0.6"});
  // A value holding commas (a vector field) needs ';' between values.
  CHECK(parse_axis("gravity=0,0,-9.81;0,0,-1.62").values == std::vector<std::string>{"0,0,-9.81", "0,0,-1.62"});
  for (const char* bad : {"mu", "=0.2", "mu=", "mu=0.2,,0.6", "mu=0.2,0.2"}) {
    INFO(bad);
    CHECK_THROWS_WITH(parse_axis(bad), Catch::Contains("--grid"));
  }
}

TEST_CASE("the plan file and a row read back what was written, tabs and line breaks included", "[sweep]") {
  Plan plan = two_by_three_by_two();
  plan.sets = {"duration=2\tx"};
  CHECK(Plan::parse(plan.text(), "p").text() == plan.text());
  Row row;
  row.index = 3;
  row.values = {"0.2", "0.8"};
  row.seed = 1;
  row.exit_status = 1;
  row.wall = 0.25;
  row.expectations = {{"lifted\tat least\n5 cm", false, "rose -0.0 mm \\ end"}};
  const Row back = parse_row(row_text(row), "r");
  CHECK(back.expectations.size() == 1);
  CHECK(back.expectations[0].what == row.expectations[0].what);
  CHECK(back.expectations[0].measured == row.expectations[0].measured);
  CHECK(back.seed == row.seed);
  // A row file cut short (no closing line) is not a finished run's.
  const std::string text = row_text(row);
  CHECK_THROWS_AS(parse_row(text.substr(0, text.size() - 4), "r"), SweepError);
}

TEST_CASE("the CSV quotes fields with commas or quotes and lists every expectation in two columns",
          "[sweep]") {
  Plan plan;
  plan.grid = {{"mu", {"0.2"}}};
  Row row;
  row.values = {"0.2"};
  row.expectations = {{"grip", true, "thumb on 'box', index on \"box\""}};
  const std::string csv = csv_text(table_columns(plan, {row}));
  CHECK(csv ==
        "run,mu,status,exit,wall_s,error,pass: grip,measured: grip\n"
        "0,0.2,pass,0,0,,1,\"thumb on 'box', index on \"\"box\"\"\"\n");
}

TEST_CASE("Slurm's --array list joins consecutive runs into ranges", "[sweep]") {
  CHECK(array_list({0, 1, 2, 3, 5, 7, 8, 9}) == "0-3,5,7-9");
  CHECK(array_list({4}) == "4");
}
