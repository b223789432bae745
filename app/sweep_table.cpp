// The sweep's summary table (sweep_table.hpp).
#include "app/sweep_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace graspsim::app::sweep {
namespace {

using recordings::SweepColumn;

bool is_number(const std::string& text, double& out) {
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return !text.empty() && end && *end == '\0' && std::isfinite(out);
}

SweepColumn text_column(std::string name) { return {std::move(name), "", SweepColumn::Kind::text, {}, {}, {}}; }
SweepColumn integer_column(std::string name) { return {std::move(name), "", SweepColumn::Kind::integer, {}, {}, {}}; }

// A CSV field, quoted when it holds a comma, a quote or a line break (RFC 4180).
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (const char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string cell(const SweepColumn& c, std::size_t r) {
  if (c.kind == SweepColumn::Kind::text) return c.text[r];
  if (c.kind == SweepColumn::Kind::integer) return std::to_string(c.integers[r]);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", c.reals[r]);
  // Grid values are written as the shortest text that reads back the same double.
  for (int digits = 1; digits <= 17; ++digits) {
    char shorter[32];
    std::snprintf(shorter, sizeof shorter, "%.*g", digits, c.reals[r]);
    if (std::strtod(shorter, nullptr) == c.reals[r]) return shorter;
  }
  return buf;
}

}  // namespace

std::string status_of(const Row& row) {
  return row.exit_status == 0 ? "pass" : row.exit_status == 1 ? "fail" : "error";
}

std::vector<SweepColumn> table_columns(const Plan& plan, const std::vector<Row>& rows) {
  std::vector<SweepColumn> columns;
  SweepColumn run = integer_column("run");
  for (const auto& row : rows) run.integers.push_back(static_cast<std::int64_t>(row.index));
  columns.push_back(std::move(run));
  for (std::size_t a = 0; a < plan.grid.size(); ++a) {
    bool numeric = true;
    double x = 0.0;
    for (const auto& v : plan.grid[a].values) numeric = numeric && is_number(v, x);
    SweepColumn c = numeric ? SweepColumn{plan.grid[a].name, "", SweepColumn::Kind::real, {}, {}, {}}
                            : text_column(plan.grid[a].name);
    for (const auto& row : rows) {
      if (numeric) c.reals.push_back(std::strtod(row.values[a].c_str(), nullptr));
      else c.text.push_back(row.values[a]);
    }
    columns.push_back(std::move(c));
  }
  if (plan.seeds > 0) {
    SweepColumn seed = integer_column("seed");
    for (const auto& row : rows) seed.integers.push_back(static_cast<std::int64_t>(row.seed.value_or(0)));
    columns.push_back(std::move(seed));
  }
  SweepColumn status = text_column("status"), exit = integer_column("exit");
  SweepColumn wall{"wall_s", "s", SweepColumn::Kind::real, {}, {}, {}};
  SweepColumn trace = text_column("trace"), error = text_column("error");
  for (const auto& row : rows) {
    status.text.push_back(status_of(row));
    exit.integers.push_back(row.exit_status);
    wall.reals.push_back(row.wall);
    trace.text.push_back(row.trace);
    error.text.push_back(row.error);
  }
  columns.push_back(std::move(status));
  columns.push_back(std::move(exit));
  columns.push_back(std::move(wall));
  if (plan.keep_traces) columns.push_back(std::move(trace));
  columns.push_back(std::move(error));
  // Every expectation any run reported, in the order they first appear (by run).
  std::vector<std::string> whats;
  for (const auto& row : rows)
    for (const auto& e : row.expectations)
      if (std::find(whats.begin(), whats.end(), e.what) == whats.end()) whats.push_back(e.what);
  for (const auto& what : whats) {
    SweepColumn pass = integer_column("pass: " + what), measured = text_column("measured: " + what);
    for (const auto& row : rows) {
      const auto e = std::find_if(row.expectations.begin(), row.expectations.end(),
                                  [&](const Expectation& x) { return x.what == what; });
      pass.integers.push_back(e == row.expectations.end() ? -1 : e->passed ? 1 : 0);
      measured.text.push_back(e == row.expectations.end() ? "" : e->measured);
    }
    columns.push_back(std::move(pass));
    columns.push_back(std::move(measured));
  }
  return columns;
}

std::string csv_text(const std::vector<SweepColumn>& columns) {
  std::string out;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (i) out += ',';
    out += csv_field(columns[i].name);
  }
  out += "\n";
  const std::size_t n = columns.empty() ? 0 : columns.front().rows();
  for (std::size_t r = 0; r < n; ++r) {
    for (std::size_t i = 0; i < columns.size(); ++i) {
      if (i) out += ',';
      out += csv_field(cell(columns[i], r));
    }
    out += "\n";
  }
  return out;
}

void write_table(const Plan& plan, const std::string& dir, const std::vector<Row>& rows) {
  const auto columns = table_columns(plan, rows);
  const std::string csv = (std::filesystem::path(dir) / "sweep.csv").string(), partial = csv + ".partial";
  const std::string h5 = (std::filesystem::path(dir) / "sweep.h5").string();
  for (const std::string& path : {csv, partial, h5, h5 + ".partial"}) check_replaceable(path);
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out << csv_text(columns);
    out.close();
    if (!out) throw SweepError("cannot write " + partial);
  }
  if (std::rename(partial.c_str(), csv.c_str()) != 0) throw SweepError("cannot rename " + partial + " to " + csv);
  std::string grid;
  for (const auto& a : plan.grid) {
    if (!grid.empty()) grid += ' ';
    grid += a.name;
  }
  recordings::write_sweep_table(h5, columns,
                                {{"scenario", plan.scenario}, {"grid", grid},
                                 {"seeds", std::to_string(plan.seeds)}, {"plan", plan.text()}});
}

}  // namespace graspsim::app::sweep
