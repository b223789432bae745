// Golden traces: run, decimate, compare (see golden.hpp and README.md, "Golden traces").
#include "golden/golden.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "graspsim/recordings/trace_decimate.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/scripting/scenario.hpp"

namespace graspsim::golden {
namespace {

std::string format(const char* fmt, auto... args) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, fmt, args...);
  return buffer;
}

}  // namespace

std::string golden_path(const std::string& golden_dir, const std::string& scenario_file) {
  return golden_dir + "/" + std::filesystem::path(scenario_file).stem().string() + ".h5";
}

std::string bless_command(const std::string& scenario_file) {
  return "tools/bless scenarios/" + std::filesystem::path(scenario_file).filename().string();
}

app::RunResult run_for_golden(const std::string& scenario_file, const std::string& trace) {
  // Goldens hold the paper's scheme: they prove it stays bit for bit (README, "Golden traces").
  scripting::LoadOptions load;
  load.sets = {"integrator=paper"};
  const auto scenario = scripting::Scenario::load(scenario_file, load);
  app::RunOptions options;
  options.out = trace;
  options.overrides = load.sets;   // recorded, so that a replay of the trace runs the same step
  return app::run_scenario(scenario, options);
}

void decimate_trace(const std::string& in, const std::string& out, const DecimateOptions& options) {
  const std::int64_t rate_servo = recordings::read_int_attribute(in, "/", "rate_servo");
  const std::int64_t rate_physics = recordings::read_int_attribute(in, "/", "rate_physics");
  recordings::DecimateOptions copy;
  copy.stride = options.stride > 0
                    ? options.stride
                    : std::max<std::int64_t>(1, rate_servo / std::min(rate_physics, kGoldenRowsPerSecond));
  copy.compression = options.compression;
  copy.root_strings = {
      {"golden", format("golden format 1 (HDF5 1.10 file format), decimated: the /servo, /haptic and /physics rows at ticks that are "
                        "multiples of %" PRId64 " (servo ticks; every physics tick up to 500 per simulated s); shuffle + deflate %d",
                        copy.stride, options.compression)},
      {"golden_cpu", cpu_model()}};
  if (!options.blessed_changes.empty()) copy.root_strings.emplace_back("blessed_changes", options.blessed_changes);
  recordings::decimate_trace(in, out, copy);
}

std::string divergence_summary(const recordings::CompareResult& result, std::size_t max_datasets,
                               bool only_b) {
  std::ostringstream out;
  std::size_t listed = 0;
  for (const auto& d : result.datasets) {
    if (!d.differs()) continue;
    const std::string component = d.first && d.first->component < d.components.size() && !d.components[d.first->component].empty()
                                      ? " " + d.components[d.first->component] : "";
    if (listed == 0 && d.first) {
      out << format("  first divergence at tick %" PRId64 " (t = %.6f s): %s%s: golden %.17g, run %.17g\n",
                    d.first->tick, d.first->time, d.path.c_str(), component.c_str(), d.first->b, d.first->a);
    }
    if (listed == max_datasets) {
      out << "  ... and more datasets differ (" << result.differing_datasets() << " in all)\n";
      break;
    }
    out << format("  %-48s first at tick %" PRId64 ", max abs error %.3g %s, max rel error %.3g, %" PRId64
                  " of %" PRId64 " elements differ\n",
                  d.path.c_str(), d.first ? d.first->tick : std::int64_t{-1}, d.max_abs_error, d.units.c_str(),
                  d.max_rel_error, d.exceeded, d.elements);
    ++listed;
  }
  for (const auto& loop : result.loops) {
    if (loop.only_b == 0 && (only_b || loop.only_a == 0)) continue;
    out << format("  /%s: %" PRId64 " rows matched by tick, %" PRId64 " only in the run, %" PRId64
                  " only in the golden",
                  loop.loop.c_str(), loop.matched, loop.only_a, loop.only_b);
    if (loop.first_only_b) out << format(" (first %" PRId64 ")", *loop.first_only_b);
    out << "\n";
  }
  return out.str();
}

GoldenCheck check_against_golden(const std::string& fresh, const std::string& golden,
                                 const std::string& scenario_file) {
  recordings::CompareOptions options;
  options.bitwise = true;
  GoldenCheck check;
  check.result = recordings::compare_traces(fresh, golden, options);
  bool every_golden_row = true;
  for (const auto& loop : check.result.loops)
    if (loop.only_b > 0 || loop.matched != loop.rows_b) every_golden_row = false;
  check.same = check.result.same() && every_golden_row;
  if (check.same) return check;
  std::ostringstream msg;
  msg << "golden trace " << golden << " differs from a fresh run of " << scenario_file << " (bitwise):\n"
      << divergence_summary(check.result, 12, true);
  for (const auto& a : check.result.attributes) {
    if ((a.name == "compiler" || a.name == "build_flags") && a.a != a.b) {
      msg << "  note: the golden's " << a.name << " was '" << a.b.value_or("(none)") << "', this run's is '"
          << a.a.value_or("(none)") << "'\n";
    }
    if (a.name == "golden_cpu" && a.b && *a.b != cpu_model())
      msg << "  note: the golden was blessed on CPU '" << *a.b << "', this is '" << cpu_model() << "'\n";
  }
  msg << "  (bit-identity is promised for the same compiler, flags, libraries and CPU: README.md, "
         "Determinism)\n"
      << "If the change is intended, re-bless the golden (it prints what changed): "
      << bless_command(scenario_file);
  check.message = msg.str();
  return check;
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) {
        std::string model = line.substr(colon + 1);
        model.erase(0, model.find_first_not_of(' '));
        return model;
      }
    }
  }
  return "unknown";
}

}  // namespace graspsim::golden
