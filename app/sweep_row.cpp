// A sweep's rows and the run summaries they are made from (sweep_row.hpp).
#include "app/sweep_row.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "app/output_file.hpp"
#include <sstream>

namespace graspsim::app::sweep {

std::string read_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return {};   // a FIFO's read would wait for a writer
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return in ? text.str() : std::string();
}

std::string summary_text(const std::vector<scripting::ExpectationResult>& expectations) {
  std::string out;
  for (const auto& e : expectations)
    out += std::string(e.passed ? "PASS" : "FAIL") + "\t" + escape(e.what) + "\t" + escape(e.detail) + "\n";
  return out;
}

std::vector<Expectation> parse_summary(const std::string& text) {
  std::vector<Expectation> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto f = split_tabs(line);
    if (f.size() == 3 && (f[0] == "PASS" || f[0] == "FAIL")) out.push_back({f[1], f[0] == "PASS", f[2]});
  }
  return out;
}

std::string row_text(const Row& row) {
  std::ostringstream out;
  out.precision(6);
  out << "index\t" << row.index << "\n";
  for (const auto& v : row.values) out << "value\t" << escape(v) << "\n";
  if (row.seed) out << "seed\t" << *row.seed << "\n";
  out << "exit\t" << row.exit_status << "\n";
  out << "wall\t" << row.wall << "\n";
  out << "trace\t" << escape(row.trace) << "\n";
  out << "error\t" << escape(row.error) << "\n";
  for (const auto& e : row.expectations)
    out << "expect\t" << (e.passed ? "PASS" : "FAIL") << "\t" << escape(e.what) << "\t" << escape(e.measured) << "\n";
  out << "end\n";   // a row file without it was cut short
  return out.str();
}

Row parse_row(const std::string& text, const std::string& file) {
  Row row;
  std::istringstream in(text);
  std::string line;
  bool ended = false;
  try {
    while (std::getline(in, line)) {
      const auto f = split_tabs(line);
      if (f[0] == "index" && f.size() == 2) row.index = std::stoull(f[1]);
      else if (f[0] == "value" && f.size() == 2) row.values.push_back(f[1]);
      else if (f[0] == "seed" && f.size() == 2) row.seed = std::stoull(f[1]);
      else if (f[0] == "exit" && f.size() == 2) row.exit_status = std::stoi(f[1]);
      else if (f[0] == "wall" && f.size() == 2) row.wall = std::stod(f[1]);
      else if (f[0] == "trace" && f.size() == 2) row.trace = f[1];
      else if (f[0] == "error" && f.size() == 2) row.error = f[1];
      else if (f[0] == "expect" && f.size() == 4) row.expectations.push_back({f[2], f[1] == "PASS", f[3]});
      else if (f[0] == "end" && f.size() == 1) ended = true;
      else throw SweepError(file + ": cannot read the line '" + line + "'");
    }
  } catch (const std::logic_error&) {
    throw SweepError(file + ": cannot read the line '" + line + "'");
  }
  if (!ended) throw SweepError(file + ": cut short (no 'end' line)");
  return row;
}

void write_row(const Plan& plan, const std::string& dir, const Row& row) {
  const std::string path = plan.run_file(dir, row.index, "row"), partial = path + ".partial";
  check_replaceable(path);
  check_replaceable(partial);
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out << row_text(row);
    out.close();
    if (!out) throw SweepError("cannot write " + partial);
  }
  if (std::rename(partial.c_str(), path.c_str()) != 0) throw SweepError("cannot rename " + partial + " to " + path);
}

std::optional<Row> read_row(const Plan& plan, const std::string& dir, std::size_t index) {
  const std::string path = plan.run_file(dir, index, "row");
  const std::string text = read_file(path);
  if (text.empty()) return std::nullopt;
  Row row;
  try {
    row = parse_row(text, path);
  } catch (const SweepError&) {
    return std::nullopt;   // cut short: the run is run again
  }
  const Plan::Run r = plan.run(index);
  if (row.index != index || row.values != r.values || row.seed != r.seed) return std::nullopt;
  return row;
}

void check_replaceable(const std::string& path) {
  if (const std::string what = not_replaceable(path); !what.empty())
    throw SweepError(path + " is " + what + ", not a regular file: a sweep replaces only files; move it away");
}

std::string write_summary(const std::string& path, const std::string& text) {
  const std::string partial = path + ".partial";
  if (const std::string what = not_replaceable(path); !what.empty())
    return "cannot write " + path + ": it is " + what + ", not a regular file (only a file is replaced)";
  const int fd = open(partial.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    const int e = errno;
    return "cannot create " + partial + ": " + std::strerror(e) +
           (e == EEXIST ? " (a file of that name is there and is kept: move it away)" : "");
  }
  std::size_t at = 0;
  int error = 0;
  while (at < text.size()) {
    const ssize_t n = write(fd, text.data() + at, text.size() - at);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      error = errno;
      break;
    }
    at += static_cast<std::size_t>(n);
  }
  if (close(fd) != 0 && !error) error = errno;
  if (const std::string what = not_replaceable(path); !error && !what.empty()) {   // taken while it was written
    unlink(partial.c_str());
    return "cannot write " + path + ": it became " + what + ", not a regular file (only a file is replaced)";
  }
  if (!error && std::rename(partial.c_str(), path.c_str()) != 0) error = errno;
  if (!error) return "";
  unlink(partial.c_str());
  return "cannot write " + path + ": " + std::strerror(error);
}

}  // namespace graspsim::app::sweep
