// The two files of a comparison, as compare_traces reads them: opened read-only (SWMR if
// they were not closed cleanly), root attributes as text, the tables at the top and the
// columns of each. Unusable input is a CompareInputError naming the file and the object.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "graspsim/recordings/trace_compare.hpp"
#include "h5.hpp"

namespace graspsim::recordings::compare {

inline std::string quoted(const std::string& text) { return "'" + text + "'"; }

[[noreturn]] inline void fail(const std::string& message) { throw CompareInputError(message); }

struct OpenTrace {
  std::string name;     // as given
  h5::Handle file;
  bool swmr = false;    // opened in SWMR read mode (the file was not closed cleanly)
};

OpenTrace open_trace(const std::string& path);

// Any attribute of `object` as text: strings as they are, numbers exactly (%.17g), arrays
// joined by ", ", anything else by its type.
std::string attribute_text(hid_t object, const std::string& name, const std::string& context);
// Every root attribute, by name, as text.
std::map<std::string, std::string> root_attributes(const OpenTrace& t);
std::int64_t int_attribute(const OpenTrace& t, const std::string& name);

// Whether `path` below `loc` is a dataset, a group, ...
H5I_type_t object_type(hid_t loc, const std::string& path, const std::string& context);
// Tables at the top of the file, by name: compound datasets (schema 3 and 4: one dataset per loop,
// its columns in its rows), the tables of a group of tables (/devices/<finger>), or groups of
// datasets (schema 2 and before).
std::vector<std::string> top_groups(const OpenTrace& t);
// Every column of table `group`, sorted: the columns of a compound table (table_layout.hpp), or the datasets
// below a group (recursively), as paths relative to it.
std::vector<std::string> datasets_below(const OpenTrace& t, const std::string& group);

}  // namespace graspsim::recordings::compare
