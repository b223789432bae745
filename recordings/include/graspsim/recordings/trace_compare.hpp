// Comparing two traces: rows aligned by loop and tick, every dataset compared element by
// element against a tolerance, the first divergence located by tick, time, quantity, object or
// finger and component. Used by `graspsim compare`, and callable directly by tests (golden
// traces) and replay. See recordings/README.md, "Comparing traces".
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "graspsim/recordings/trace_writer.hpp"

namespace graspsim::recordings {

// The traces cannot be compared: a file missing or not HDF5 or truncated, not a graspsim
// trace, schema versions that differ (unless both are ones this graspsim reads), rates that differ, no table both hold (after `only`), a column of a
// shared table in one trace only, different widths or element kinds, a --tol pattern or an
// `only` loop that matches nothing. what() names the file and the dataset.
class CompareInputError : public TraceError {
 public:
  using TraceError::TraceError;
};

struct Tolerance {
  double atol = 0.0;   // absolute, in the dataset's units
  double rtol = 0.0;   // relative, 1
};

// Per-dataset tolerance: `pattern` is matched against the dataset path without a leading '/'
// ("physics/objects/box/position") with fnmatch(3) rules where '*' also crosses '/'
// ("servo/*", "*/position", "physics/objects/box/*"). The last rule that matches wins.
struct ToleranceRule {
  std::string pattern;
  Tolerance tolerance;
};

struct CompareOptions {
  Tolerance tolerance;                    // for every dataset no rule matches
  std::vector<ToleranceRule> rules;       // per dataset, in command-line order
  bool bitwise = false;                   // equal only if the stored bits are (tolerances unused)
  bool attributes = false;                // root attribute differences count as differences
  bool all_ticks = false;                 // ticks present in one trace only count as differences
  // Compare only these loops (--only): a table is selected when its path is one of them or
  // lies below one ("physics"; "devices" for every /devices/<finger>, or "devices/index").
  // Empty: every table.
  std::vector<std::string> only;
  std::size_t block_rows = 65536;         // rows read per hyperslab
};

// One loop's table (/servo, /haptic, /physics) and how its rows align.
struct LoopAlignment {
  std::string loop;                          // "servo"
  std::int64_t rows_a = 0, rows_b = 0;       // rows compared in each file
  std::int64_t matched = 0;                  // ticks present in both
  std::int64_t only_a = 0, only_b = 0;       // ticks present in one file only
  std::optional<std::int64_t> first_only_a;  // the first such tick
  std::optional<std::int64_t> first_only_b;
};

// Where one element pair was compared.
struct ElementPoint {
  std::int64_t tick = 0;
  double time = 0.0;           // s, from A's time column
  std::size_t component = 0;   // index into DatasetResult::components (0 for width 1)
  double a = 0.0, b = 0.0;     // the values (integers converted to double)
  double abs_error = 0.0;      // |a - b|
  double rel_error = 0.0;      // |a - b| / max(|a|, |b|), 0 when both are 0
};

struct DatasetResult {
  std::string path;       // "physics/objects/box/position" (no leading '/')
  std::string loop;       // "physics"
  std::string kind;       // "object", "finger" or "" (for tick, time and loop-wide columns)
  std::string name;       // the object or finger, "" if none
  std::string quantity;   // "position"
  std::vector<std::string> components;   // "x","y","z" / "w","x","y","z" / "" for width 1
  std::string units;      // the dataset's "units" attribute
  bool integer = false;   // stored as integers (compared exactly as integers, errors in double)
  Tolerance tolerance;    // the tolerance applied
  std::string rule;       // the --tol pattern that set it, "" for the global one
  std::int64_t elements = 0;   // element pairs compared
  std::int64_t exceeded = 0;   // element pairs outside the tolerance (or not bitwise equal)
  double max_abs_error = 0.0;  // over every pair compared (inf when one side is NaN)
  double max_rel_error = 0.0;
  std::optional<ElementPoint> first;     // first pair outside the tolerance, by tick
  std::optional<ElementPoint> worst;     // the pair with the largest absolute error (if > 0)
  bool differs() const { return exceeded > 0; }
};

// A root attribute present in only one file or with different values.
struct AttributeDifference {
  std::string name;
  std::optional<std::string> a, b;   // the values as text; nullopt where missing
  bool counted = false;              // counts as a difference (CompareOptions::attributes)
};

// A table (loop) that one trace holds and the other does not: a device table of a device
// session against its scripted run, a loop one trace did not record (--record). Listed; it does
// not make the input unusable, and it is not a difference.
struct OneSidedTable {
  std::string table;   // "devices/index" (no leading '/')
  bool in_a = true;    // held by A (else by B)
};

struct CompareResult {
  std::string file_a, file_b;
  CompareOptions options;                       // what was asked
  std::int64_t schema_version = 0;              // A's
  std::int64_t schema_version_b = 0;            // B's: another only where both are readable (2 to 4)
  std::int64_t rate_servo = 0, rate_haptic = 0, rate_physics = 0;   // Hz
  std::vector<LoopAlignment> loops;             // servo, haptic, physics, then any other table
  std::vector<OneSidedTable> one_sided;         // selected tables in one trace only, in loop order
  std::vector<DatasetResult> datasets;          // the differing ones first, by first divergence
                                                // (tick, then time, then path), then by path
  std::vector<AttributeDifference> attributes;  // by name
  std::vector<std::string> notes;               // anything else worth saying (status, SWMR open)
  std::int64_t differing_datasets() const;
  std::int64_t counted_attributes() const;
  std::int64_t unmatched_ticks() const;         // only_a + only_b over every loop
  // No dataset outside the tolerance, no counted attribute difference, and (with all_ticks)
  // no tick in one file only.
  bool same() const;
};

// Compares trace `a` with trace `b`. Throws CompareInputError for input that cannot be compared
// (see above); never prints.
CompareResult compare_traces(const std::string& a, const std::string& b,
                             const CompareOptions& options = {});

// True if `pattern` matches dataset `path` (the rule syntax of ToleranceRule).
bool tolerance_pattern_matches(const std::string& pattern, const std::string& path);

}  // namespace graspsim::recordings
