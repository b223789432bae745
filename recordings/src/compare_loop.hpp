// One loop of a comparison: the rows of a table with a tick column in both traces, aligned
// by tick, and every other column compared element by element on the aligned rows.
#pragma once

#include <string>
#include <vector>

#include "compare_input.hpp"
#include "graspsim/recordings/trace_compare.hpp"

namespace graspsim::recordings::compare {

// Loop order: the three loops of the schema first, then any other table by name.
inline int loop_rank(const std::string& g) {
  if (g == "servo") return 0;
  if (g == "haptic") return 1;
  if (g == "physics") return 2;
  return 3;
}

// Compares loop `group` of A and B (recordings/README.md "Comparing traces"): appends its
// LoopAlignment and one DatasetResult per column but the tick to `result`, and marks in
// `rule_used` the tolerance rules that matched. Throws CompareInputError for columns that
// differ in name, shape or kind, a missing tick or time column, or ticks that do not increase.
void compare_loop(const OpenTrace& a, const OpenTrace& b, const std::string& group,
                  const CompareOptions& options, std::vector<bool>& rule_used,
                  CompareResult& result);

}  // namespace graspsim::recordings::compare
