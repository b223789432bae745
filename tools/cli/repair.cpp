// graspsim repair FILE: the one documented repair step for a trace cut by a crash
// (recordings/README.md, "Crash safety").
#include "cli/repair.hpp"

#include <iostream>

#include "app/output_file.hpp"
#include "cli/options.hpp"
#include "graspsim/recordings/trace_repair.hpp"
#include "graspsim/recordings/trace_writer.hpp"

namespace graspsim::cli {
namespace {

constexpr const char* kRepairHelp =
    "usage: graspsim repair TRACE.h5\n"
    "\n"
    "Repairs a trace whose run was killed (root attribute status still \"running\"): clears\n"
    "the HDF5 file's SWMR/open status flags and extends its end of allocation past the end of\n"
    "the file (like `h5clear -s --increment`, which never truncates), and sets status to\n"
    "\"cut: repaired\". The file keeps every tick up to the run's last flush. A trace that was not\n"
    "cut is left untouched. A trace a run is still writing (locked: FILE.h5.partial while the\n"
    "run goes on) is refused.\n"
    "\n"
    "exit status: 0 repaired or nothing to repair, 2 bad input (not a graspsim trace, or it\n"
    "cannot be repaired).\n";

// Repairs the trace at `path` unless a run holds it; the exit status.
int repair(const std::string& path) {
  if (app::locked_by_a_run(path)) {
    std::cerr << "graspsim: '" << path << "' is being written by a graspsim run (it is locked): "
              << "it is not cut; repair it only if that run is killed\n";
    return 2;
  }
  try {
    const recordings::RepairResult r = recordings::repair_trace(path);
    if (r.repaired) {
      std::cout << "graspsim: repaired '" << path << "': status \"" << r.status_after << "\", "
                << r.servo_rows << " servo ticks kept\n";
    } else {
      std::cout << "graspsim: '" << path << "' was not cut (status \"" << r.status_before
                << "\"); nothing to repair\n";
    }
    return 0;
  } catch (const recordings::TraceError& e) {
    std::cerr << "graspsim: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace

int repair_command(const std::vector<std::string>& args) {
  std::string trace;
  CommandLine line{"repair", "usage: graspsim repair TRACE.h5\n", kRepairHelp, {}, {}};
  line.operand = [&trace](const std::string& v) -> std::string {
    if (!trace.empty()) return "one trace at a time (got '" + trace + "' and '" + v + "')";
    trace = v;
    return "";
  };
  switch (parse_command_line(line, args)) {
    case Parsed::kHelp: return 0;
    case Parsed::kError: return 2;
    case Parsed::kGo: break;
  }
  if (trace.empty()) return usage_error(line, "repair needs exactly one trace file");
  return repair(trace);
}

}  // namespace graspsim::cli
