// graspsim repair FILE: the one documented repair step for a trace cut by a crash
// (recordings/README.md, "Crash safety").
#include "cli/repair.hpp"

#include <iostream>

#include "app/output_file.hpp"
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

}  // namespace

int repair_command(const std::vector<std::string>& args) {
  if (args.size() == 1 && (args[0] == "-h" || args[0] == "--help")) {
    std::cout << kRepairHelp;
    return 0;
  }
  if (args.size() != 1 || args[0].empty() || args[0].front() == '-') {
    std::cerr << "graspsim: repair needs exactly one trace file\n" << kRepairHelp;
    return 2;
  }
  if (app::locked_by_a_run(args[0])) {
    std::cerr << "graspsim: '" << args[0] << "' is being written by a graspsim run (it is locked): "
              << "it is not cut; repair it only if that run is killed\n";
    return 2;
  }
  try {
    const recordings::RepairResult r = recordings::repair_trace(args[0]);
    if (r.repaired) {
      std::cout << "graspsim: repaired '" << args[0] << "': status \"" << r.status_after << "\", "
                << r.servo_rows << " servo ticks kept\n";
    } else {
      std::cout << "graspsim: '" << args[0] << "' was not cut (status \"" << r.status_before
                << "\"); nothing to repair\n";
    }
    return 0;
  } catch (const recordings::TraceError& e) {
    std::cerr << "graspsim: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace graspsim::cli
