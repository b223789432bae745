// The sweep's plan: its runs, their arguments, and the plan file (sweep_plan.hpp).
#include "app/sweep_plan.hpp"

#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

namespace graspsim::app::sweep {

std::string escape(const std::string& field) {
  std::string out;
  for (const char c : field) {
    if (c == '\t') out += "\\t";
    else if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\\') out += "\\\\";
    else out += c;
  }
  return out;
}

std::string unescape(const std::string& field) {
  std::string out;
  for (std::size_t i = 0; i < field.size(); ++i) {
    if (field[i] != '\\' || i + 1 == field.size()) {
      out += field[i];
      continue;
    }
    const char c = field[++i];
    out += c == 't' ? '\t' : c == 'n' ? '\n' : c == 'r' ? '\r' : c;
  }
  return out;
}

std::vector<std::string> split_tabs(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  for (;;) {
    const std::size_t tab = line.find('\t', start);
    fields.push_back(unescape(line.substr(start, tab - start)));
    if (tab == std::string::npos) return fields;
    start = tab + 1;
  }
}

Axis parse_axis(const std::string& grid) {
  const std::size_t eq = grid.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == grid.size())
    throw SweepError("--grid needs NAME=V1,V2,... (got '" + grid + "')");
  Axis axis{grid.substr(0, eq), {}};
  const std::string list = grid.substr(eq + 1);
  const char separator = list.find(';') != std::string::npos ? ';' : ',';
  std::set<std::string> seen;
  for (std::size_t start = 0; start <= list.size();) {
    const std::size_t end = std::min(list.find(separator, start), list.size());
    const std::string value = list.substr(start, end - start);
    if (value.empty()) throw SweepError("--grid " + grid + ": an empty value");
    if (!seen.insert(value).second) throw SweepError("--grid " + grid + ": the value '" + value + "' is given twice");
    axis.values.push_back(value);
    start = end + 1;
  }
  return axis;
}

std::size_t Plan::size() const {
  std::size_t n = seeds > 0 ? seeds : 1;
  for (const auto& a : grid) n *= a.values.size();
  return n;
}

Plan::Run Plan::run(std::size_t index) const {
  Run r;
  r.index = index;
  std::size_t rest = index;
  if (seeds > 0) {
    r.seed = rest % seeds;
    rest /= seeds;
  }
  r.values.resize(grid.size());
  for (std::size_t a = grid.size(); a-- > 0;) {
    r.values[a] = grid[a].values[rest % grid[a].values.size()];
    rest /= grid[a].values.size();
  }
  return r;
}

std::string Plan::run_file(const std::string& dir, std::size_t index, const std::string& extension) const {
  const int width = std::max<int>(4, static_cast<int>(std::to_string(size() - 1).size()));
  char name[64];
  std::snprintf(name, sizeof name, "%0*zu.%s", width, index, extension.c_str());
  return (std::filesystem::path(dir) / "runs" / name).string();
}

std::vector<std::string> Plan::run_arguments(std::size_t index, const std::string& dir) const {
  const Run r = run(index);
  std::vector<std::string> args{"run", scenario};
  for (const auto& s : sets) args.insert(args.end(), {"--set", s});
  for (std::size_t a = 0; a < grid.size(); ++a) args.insert(args.end(), {"--set", grid[a].name + "=" + r.values[a]});
  if (r.seed) {
    std::ostringstream amplitude;
    amplitude.precision(17);
    amplitude << jitter;
    args.insert(args.end(), {"--jitter", amplitude.str(), "--jitter-seed", std::to_string(*r.seed)});
  }
  if (keep_traces) args.insert(args.end(), {"--out", run_file(dir, index, "h5")});
  else args.push_back("--no-trace");
  args.insert(args.end(), {"--quiet", "--summary", run_file(dir, index, "summary")});
  return args;
}

std::string Plan::text() const {
  std::ostringstream out;
  out.precision(17);
  out << "graspsim sweep plan 1\n";
  out << "scenario\t" << escape(scenario) << "\n";
  for (const auto& a : grid) {
    out << "grid\t" << escape(a.name);
    for (const auto& v : a.values) out << "\t" << escape(v);
    out << "\n";
  }
  for (const auto& s : sets) out << "set\t" << escape(s) << "\n";
  out << "seeds\t" << seeds << "\n";
  out << "jitter\t" << jitter << "\n";
  out << "keep_traces\t" << (keep_traces ? 1 : 0) << "\n";
  return out.str();
}

Plan Plan::parse(const std::string& text, const std::string& file) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || line != "graspsim sweep plan 1")
    throw SweepError(file + ": not a graspsim sweep plan");
  Plan plan;
  try {
    while (std::getline(in, line)) {
      const auto f = split_tabs(line);
      if (f[0] == "scenario" && f.size() == 2) plan.scenario = f[1];
      else if (f[0] == "grid" && f.size() >= 3) plan.grid.push_back({f[1], {f.begin() + 2, f.end()}});
      else if (f[0] == "set" && f.size() == 2) plan.sets.push_back(f[1]);
      else if (f[0] == "seeds" && f.size() == 2) plan.seeds = std::stoull(f[1]);
      else if (f[0] == "jitter" && f.size() == 2) plan.jitter = std::stod(f[1]);
      else if (f[0] == "keep_traces" && f.size() == 2) plan.keep_traces = f[1] == "1";
      else throw SweepError(file + ": cannot read the line '" + line + "'");
    }
  } catch (const std::logic_error&) {   // stoull, stod
    throw SweepError(file + ": cannot read the line '" + line + "'");
  }
  if (plan.scenario.empty()) throw SweepError(file + ": no scenario");
  return plan;
}

}  // namespace graspsim::app::sweep
