// `graspsim compare A.h5 B.h5`: its command table, the comparison (recordings::compare_traces)
// and its report (app/compare.hpp), and with --view the two runs in the browser.
#include "cli/compare.hpp"

#include <algorithm>
#include <iostream>

#include "app/compare.hpp"
#include "cli/options.hpp"
#include "cli/report.hpp"
#include "cli/view.hpp"
#include "graspsim/recordings/trace_compare.hpp"

namespace graspsim::cli {
namespace {

namespace rec = recordings;

constexpr const char* kCompareUsage =
    "usage: graspsim compare A.h5 B.h5 [--atol X] [--rtol X] [--tol PATTERN=ATOL[,RTOL]]...\n"
    "                [--bitwise] [--attributes] [--all-ticks] [--all] [--only LOOP]... [--json]\n"
    "                [--view [--port N] [--open]]\n";

constexpr const char* kCompareHelp =
    "usage: graspsim compare A.h5 B.h5 [options]\n"
    "\n"
    "Compares two graspsim traces. The rows of each loop (/servo, /haptic, /physics) are\n"
    "aligned by their tick column, not by row index, so a shorter, cut or decimated trace\n"
    "still compares where ticks match (ticks in one trace only are counted and reported).\n"
    "Every dataset is compared element by element; for each one that differs it reports the\n"
    "first tick and time where the tolerance is exceeded, the object or finger, the quantity\n"
    "and component (x/y/z, w/x/y/z), the two values there, and the largest absolute and\n"
    "relative errors. Differing datasets are listed by first divergence.\n"
    "\n"
    "An element pair (a, b) is within tolerance when |a - b| <= atol + rtol * max(|a|, |b|);\n"
    "NaN equals NaN, an infinity only the same infinity; integer columns (contact state, body\n"
    "index, counts) are compared as integers. The default tolerance is 0: equal values.\n"
    "\n"
    "options:\n"
    "  --atol X             absolute tolerance for every dataset (default 0)\n"
    "  --rtol X             relative tolerance for every dataset (default 0)\n"
    "  --tol PATTERN=ATOL[,RTOL]\n"
    "                       tolerance for the datasets whose path matches PATTERN, instead of\n"
    "                       --atol/--rtol (RTOL defaults to 0). Paths look like\n"
    "                       physics/objects/box/position or haptic/fingers/thumb/force; PATTERN\n"
    "                       is a glob where * also crosses '/': 'servo/*', '*/position',\n"
    "                       'physics/objects/box/*'. Repeatable; the last matching one wins; a\n"
    "                       pattern that matches no dataset is an error.\n"
    "  --bitwise            equal only if the stored bits are equal (NaN equals a NaN with the\n"
    "                       same bits; -0 differs from 0); no tolerances\n"
    "  --attributes         count differing root attributes (scenario source, parameters,\n"
    "                       seed, version, compiler, status ...) as differences; by default\n"
    "                       they are only notes, since wall-clock, status and version\n"
    "                       legitimately differ. Rates must always match; schema versions\n"
    "                       too, unless both are 2 to 4 (the same columns, other layouts).\n"
    "  --all-ticks          ticks present in one trace only count as differences\n"
    "  --all                also list the datasets within tolerance, with their largest error\n"
    "  --only LOOP[,LOOP...]\n"
    "                       compare only these loops (repeatable): servo, haptic, physics,\n"
    "                       devices (every /devices/FINGER) or devices/FINGER; a loop neither\n"
    "                       trace holds is an error\n"
    "  --json               one JSON object on stdout instead of the table (fields:\n"
    "                       recordings/README.md, \"Comparing traces\")\n"
    "  --view               then show both runs in the browser, as `graspsim view A.h5 B.h5`\n"
    "                       does (B ghosted, the first divergence marked), until Ctrl-C; exit\n"
    "                       status then that of the view. The mark is the first divergence at\n"
    "                       tolerance 0 over every loop: no --atol, --rtol, --tol, --bitwise\n"
    "                       or --only with it\n"
    "  --port N             the view's port on 127.0.0.1 (default 8717; 0: any free port)\n"
    "  --open               open the view with xdg-open as well\n"
    "\n"
    "Tables one trace holds and the other does not (/devices/FINGER of a device session\n"
    "against its scripted run, a loop one trace did not --record) are listed as \"only in A\"\n"
    "or \"only in B\" and not compared; the loops both hold are. Ticks one trace did not keep\n"
    "(--record LOOP:EVERY) are counted as ticks in one trace only.\n"
    "\n"
    "exit status: 0 same: every compared element within tolerance (tables in one trace only do\n"
    "not count; ticks in one trace only count only with --all-ticks, root attributes only with\n"
    "--attributes); 1 different: some element outside the tolerance (or a counted tick or\n"
    "attribute); 2 unusable input: a missing, truncated or non-HDF5 file, not a graspsim trace,\n"
    "rates that differ, schema versions that differ (unless both are 2 to 4), no loop both\n"
    "traces hold, a loop a trace records\n"
    "missing or not a table (a /physics that is absent or a scalar), a column of a shared loop\n"
    "in one trace only, different shapes, bad options (an --only loop neither trace holds).\n"
    "\n"
    "Why not h5diff: with the box's height changed by 1e-9 m at one physics tick of the\n"
    "two-finger lift, `h5diff -r A.h5 B.h5` prints, between blocks for every other dataset,\n"
    "  dataset: </physics/objects/box/position> and </physics/objects/box/position>\n"
    "  [ 60 2 ]          0.03019         0.03019         1e-09\n"
    "an element index (row 60, column 2) and values cut to 4 digits; it pairs rows by index,\n"
    "so a decimated trace differs everywhere. graspsim compare prints\n"
    "  DIFFERENT: 1 of 36 datasets exceed the tolerance; first at physics tick 3600\n"
    "  (t = 1.2 s): object box position z\n"
    "with both values in full (0.030189999999999998, 0.030190000999999998), and lists every\n"
    "differing dataset by the tick where it first parts, so a cause comes before its\n"
    "consequences.\n"
    "\n"
    "example: graspsim compare golden.h5 new.h5 --rtol 1e-12 --tol 'servo/*=1e-9'\n";


struct CompareArgs {
  std::vector<std::string> files;
  rec::CompareOptions options;
  bool json = false, all = false, tolerances = false, view = false, open = false, port_given = false;
  int port = kDefaultViewPort;
};

// Parses "A,B" or "A" into two non-negative numbers (B = 0 when missing).
bool parse_tolerance(const std::string& text, rec::Tolerance& out) {
  const auto comma = text.find(',');
  out = {};
  if (!parse_number(text.substr(0, comma), out.atol) || out.atol < 0) return false;
  if (comma != std::string::npos && (!parse_number(text.substr(comma + 1), out.rtol) || out.rtol < 0))
    return false;
  return true;
}

Option tol_option(CompareArgs& a) {
  return {"--tol", "PATTERN=ATOL or PATTERN=ATOL,RTOL with numbers >= 0", [&a](const std::string& v, std::string&) {
            const auto eq = v.rfind('=');
            rec::ToleranceRule rule;
            if (eq == std::string::npos || eq == 0 || !parse_tolerance(v.substr(eq + 1), rule.tolerance)) return false;
            rule.pattern = v.substr(0, eq);
            a.options.rules.push_back(rule);
            return a.tolerances = true;
          }};
}

// --only LOOP or LOOP,LOOP,...; repeatable. (Not a list of words up to the files: a loop and a
// file name cannot be told apart.)
Option only_option(CompareArgs& a) {
  return {"--only", "a loop (servo, haptic, physics, devices or devices/<finger>)",
          [&a](const std::string& v, std::string& why) {
            for (std::size_t start = 0; start <= v.size();) {
              const std::size_t comma = std::min(v.find(',', start), v.size());
              const std::string loop = v.substr(start, comma - start);
              if (loop.empty()) {
                why = "--only " + v + ": an empty loop name";
                return false;
              }
              a.options.only.push_back(loop);
              start = comma + 1;
            }
            return true;
          }};
}

CommandLine compare_line(CompareArgs& a) {
  CommandLine line{"compare", kCompareUsage, kCompareHelp, {}, {}};
  const auto tolerance = [&a](const std::string& name, double& target) {
    return Option{name, "a number >= 0", [&a, &target](const std::string& v, std::string&) {
                    return (a.tolerances = parse_number(v, target) && target >= 0);
                  },
                  true};
  };
  line.options = {tolerance("--atol", a.options.tolerance.atol), tolerance("--rtol", a.options.tolerance.rtol),
                  tol_option(a), flag("--bitwise", a.options.bitwise), flag("--attributes", a.options.attributes),
                  flag("--all-ticks", a.options.all_ticks), flag("--all", a.all), only_option(a), flag("--json", a.json),
                  flag("--view", a.view), port(a.port, a.port_given), flag("--open", a.open)};
  line.operand = [&a](const std::string& v) -> std::string {
    a.files.push_back(v);
    return "";
  };
  return line;
}

// The combinations refused: "" when fine.
std::string check_arguments(const CompareArgs& a) {
  if (a.options.bitwise && a.tolerances) return "--bitwise compares exact bits: it takes no --atol, --rtol or --tol";
  if (a.view && (a.tolerances || a.options.bitwise || !a.options.only.empty()))
    return "--view marks the first divergence at tolerance 0 over every loop: it takes no --atol, --rtol, "
           "--tol, --bitwise or --only";
  if (!a.view && (a.port_given || a.open)) return std::string(a.open ? "--open" : "--port") + " is for the view: add --view";
  return "";
}

// Compares the two traces and prints the table or the JSON: the exit status, or -1 to go on to
// the view.
int compare_and_report(const CompareArgs& a) {
  const auto input_error = [&a](const std::string& message) {
    if (a.json) std::cout << app::compare_error_json(message);
    std::cerr << "graspsim compare: " << message << "\n";
    return kExitBadInput;
  };
  rec::CompareResult result;
  try {
    result = rec::compare_traces(a.files[0], a.files[1], a.options);
    // Loops a trace records that are no table of it are never "the same": refused.
    for (const std::string& f : a.files)
      if (const std::string missing = app::missing_loop_tables(f); !missing.empty()) return input_error(missing);
  } catch (const rec::TraceError& e) {
    return input_error(e.what());
  }
  std::cout << (a.json ? app::compare_json(result) : app::compare_table(result, a.all));
  if (a.view) return -1;
  return result.same() ? kExitOk : kExitFailed;
}

}  // namespace

int compare_command(const std::vector<std::string>& args) {
  CompareArgs a;
  const CommandLine line = compare_line(a);
  switch (parse_command_line(line, args)) {
    case Parsed::kHelp: return kExitOk;
    case Parsed::kError: return kExitBadInput;
    case Parsed::kGo: break;
  }
  if (a.files.size() != 2) {
    if (a.json) std::cout << app::compare_error_json("compare needs two trace files");
    return usage_error(line, "compare needs two trace files (got " + std::to_string(a.files.size()) + ")");
  }
  if (const std::string e = check_arguments(a); !e.empty()) {
    if (a.json) std::cout << app::compare_error_json(e);
    return usage_error(line, e);
  }
  const int status = compare_and_report(a);
  if (status >= 0) return status;
  std::cout.flush();
  std::vector<std::string> view_args = {a.files[0], a.files[1], "--port", std::to_string(a.port)};
  if (a.open) view_args.push_back("--open");
  return view_command(view_args);
}

}  // namespace graspsim::cli
