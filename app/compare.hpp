// `graspsim compare` output: the readable table and the JSON document (its fields are listed
// in recordings/README.md, "Comparing traces"). The comparison itself is
// recordings::compare_traces.
#pragma once

#include <string>

#include "graspsim/recordings/trace_compare.hpp"

namespace graspsim::app {

// The report for people: the alignment of each loop, a verdict line, the differing datasets
// sorted by first divergence (tick, time, loop, object or finger, quantity, component, the two
// values there, max abs and rel error, how many elements are out), then notes. `all` also
// lists the datasets within tolerance with their largest errors.
std::string compare_table(const recordings::CompareResult& result, bool all);

// The same as one JSON object (fields: recordings/README.md, "Comparing traces"); ends in '\n'.
std::string compare_json(const recordings::CompareResult& result);

// What of `trace`'s own loops is not a table there: each of servo, haptic and physics that its
// root attribute `record` names (every one when it has none) must be a table with a tick column,
// /<loop>/tick. "" when each is; otherwise the file, the loop and what is there instead (nothing,
// or a plain dataset). compare_traces compares the tables two files share and passes over
// anything else, so two files whose /physics is missing or a scalar would be "the same": such a
// file is a damaged trace or none, and compare refuses it (exit 2).
std::string missing_loop_tables(const std::string& trace);

// {"exit_code": 2, "error": message} for input that could not be compared; ends in '\n'.
std::string compare_error_json(const std::string& message);

}  // namespace graspsim::app
