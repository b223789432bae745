// Trace comparison (see trace_compare.hpp and recordings/README.md, "Comparing traces").
//
// Each loop's rows are aligned by tick with a merge join of the two (increasing) tick columns,
// so a shorter, cut or decimated trace still compares where ticks match. Every other dataset of
// the loop is then read in hyperslabs of block_rows rows (never row by row) and compared pair
// by pair in tick order, so the first element outside the tolerance is the first divergence.
#include "graspsim/recordings/trace_compare.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <map>
#include <set>

#include "compare_input.hpp"
#include "graspsim/recordings/trace_recorder.hpp"
#include "compare_loop.hpp"

namespace graspsim::recordings {
namespace {

using namespace compare;

using Attributes = std::map<std::string, std::string>;

void check_options(const CompareOptions& options) {
  if (!(options.tolerance.atol >= 0) || !(options.tolerance.rtol >= 0))
    fail("tolerances must be >= 0");
  for (const ToleranceRule& r : options.rules)
    if (!(r.tolerance.atol >= 0) || !(r.tolerance.rtol >= 0) || r.pattern.empty())
      fail("tolerance rule " + quoted(r.pattern) + ": needs a pattern and tolerances >= 0");
}

// Both files are graspsim traces of one schema version, or of two that this graspsim reads
// (kOldestSchemaVersion to kSchemaVersion: the same columns in other layouts, which the readers
// see alike, so a schema 3 golden compares with a schema 4 run); they go to the result.
void check_schema(const OpenTrace& a, const OpenTrace& b, const Attributes& attrs_a,
                  const Attributes& attrs_b, CompareResult& result) {
  for (const auto* t : {&a, &b}) {
    const auto& attrs = t == &a ? attrs_a : attrs_b;
    if (!attrs.count("schema_version"))
      fail("trace " + quoted(t->name) +
           " is not a graspsim trace (it has no root attribute 'schema_version')");
  }
  result.schema_version = int_attribute(a, "schema_version");
  result.schema_version_b = int_attribute(b, "schema_version");
  if (result.schema_version == result.schema_version_b) return;
  const auto readable = [](std::int64_t v) { return v >= kOldestSchemaVersion && v <= kSchemaVersion; };
  if (!readable(result.schema_version) || !readable(result.schema_version_b))
    fail("the traces have different schema versions: " + quoted(a.name) + " has " +
         std::to_string(result.schema_version) + ", " + quoted(b.name) + " has " +
         std::to_string(result.schema_version_b));
  result.notes.push_back(quoted(a.name) + " is schema " + std::to_string(result.schema_version) + ", " +
                         quoted(b.name) + " schema " + std::to_string(result.schema_version_b) +
                         ": the same columns in another layout, compared column by column");
}

// Both files have the same servo, haptic and physics rates (a tick means the same time in
// both); they go to the result.
void check_rates(const OpenTrace& a, const OpenTrace& b, const Attributes& attrs_a,
                 const Attributes& attrs_b, CompareResult& result) {
  const char* rate_names[3] = {"rate_servo", "rate_haptic", "rate_physics"};
  std::int64_t rates[2][3] = {};
  for (int f = 0; f < 2; ++f) {
    const OpenTrace& t = f == 0 ? a : b;
    const auto& attrs = f == 0 ? attrs_a : attrs_b;
    for (int r = 0; r < 3; ++r) {
      if (!attrs.count(rate_names[r]))
        fail("trace " + quoted(t.name) + " has no root attribute " + quoted(rate_names[r]));
      rates[f][r] = int_attribute(t, rate_names[r]);
    }
  }
  const auto rate_text = [&](int f) {
    return std::to_string(rates[f][0]) + " / " + std::to_string(rates[f][1]) + " / " +
           std::to_string(rates[f][2]) + " Hz";
  };
  if (!std::equal(rates[0], rates[0] + 3, rates[1]))
    fail("the traces have different rates (servo / haptic / physics): " + quoted(a.name) + " " +
         rate_text(0) + ", " + quoted(b.name) + " " + rate_text(1));
  result.rate_servo = rates[0][0];
  result.rate_haptic = rates[0][1];
  result.rate_physics = rates[0][2];
}

// Root attributes other than the ones checked above that differ (counted only when asked), and
// a note for a trace whose status is not `complete`.
void compare_attributes(const OpenTrace& a, const OpenTrace& b, const Attributes& attrs_a,
                        const Attributes& attrs_b, const CompareOptions& options,
                        CompareResult& result) {
  std::set<std::string> names;
  for (const auto& [k, v] : attrs_a) names.insert(k);
  for (const auto& [k, v] : attrs_b) names.insert(k);
  for (const std::string& n : names) {
    if (n == "schema_version" || n == "rate_servo" || n == "rate_haptic" || n == "rate_physics")
      continue;
    const auto ia = attrs_a.find(n), ib = attrs_b.find(n);
    if (ia != attrs_a.end() && ib != attrs_b.end() && ia->second == ib->second) continue;
    AttributeDifference d;
    d.name = n;
    if (ia != attrs_a.end()) d.a = ia->second;
    if (ib != attrs_b.end()) d.b = ib->second;
    d.counted = options.attributes;
    result.attributes.push_back(std::move(d));
  }
  for (const OpenTrace* t : {&a, &b}) {
    const auto& attrs = t == &a ? attrs_a : attrs_b;
    const auto s = attrs.find("status");
    if (s != attrs.end() && s->second != "complete")
      result.notes.push_back(quoted(t->name) + " has status " + quoted(s->second) +
                             " (not a complete run)");
  }
}

// Whether table `g` is selected by CompareOptions::only (empty: every table).
bool selected(const std::string& g, const std::vector<std::string>& only) {
  if (only.empty()) return true;
  return std::any_of(only.begin(), only.end(), [&](const std::string& o) {
    return g == o || (g.size() > o.size() && g.compare(0, o.size(), o) == 0 && g[o.size()] == '/');
  });
}

// The selected tables both files hold, in loop order (servo, haptic, physics, then the rest by
// name); the selected tables one file holds go to result.one_sided. Every `only` entry must
// select a table of one file or the other, and the files must share at least one table.
std::vector<std::string> shared_tables(const OpenTrace& a, const OpenTrace& b, const CompareOptions& options,
                                       CompareResult& result) {
  const std::vector<std::string> groups_a = top_groups(a), groups_b = top_groups(b);
  const auto holds = [](const std::vector<std::string>& groups, const std::string& g) {
    return std::find(groups.begin(), groups.end(), g) != groups.end();
  };
  for (const std::string& o : options.only) {
    const auto hit = [&](const std::string& g) { return selected(g, {o}); };
    if (std::none_of(groups_a.begin(), groups_a.end(), hit) && std::none_of(groups_b.begin(), groups_b.end(), hit))
      fail("--only " + o + ": neither trace has a loop " + quoted(o) +
           " (loops look like servo, haptic, physics, devices or devices/<finger>)");
  }
  std::vector<std::string> both, only_a, only_b;
  for (const std::string& g : groups_a)
    if (selected(g, options.only)) (holds(groups_b, g) ? both : only_a).push_back(g);
  for (const std::string& g : groups_b)
    if (selected(g, options.only) && !holds(groups_a, g)) only_b.push_back(g);
  const auto by_loop = [](std::vector<std::string>& v) {
    std::stable_sort(v.begin(), v.end(),
                     [](const std::string& x, const std::string& y) { return loop_rank(x) < loop_rank(y); });
  };
  by_loop(both);
  by_loop(only_a);
  by_loop(only_b);
  for (const std::string& g : only_a) result.one_sided.push_back({g, true});
  for (const std::string& g : only_b) result.one_sided.push_back({g, false});
  const auto list = [](const std::vector<std::string>& groups) {
    std::string t;
    for (const std::string& g : groups) t += (t.empty() ? "" : ", ") + g;
    return t.empty() ? std::string("none") : t;
  };
  if (both.empty())
    fail("the traces " + quoted(a.name) + " and " + quoted(b.name) + " share no " +
         (options.only.empty() ? "loop" : "selected loop") + " to compare (" + quoted(a.name) + ": " +
         list(groups_a) + "; " + quoted(b.name) + ": " + list(groups_b) + ")");
  return both;
}

// The differing datasets first, by first tick (a cause before its consequences), then loop;
// the rest by path.
void sort_datasets(CompareResult& result) {
  std::stable_sort(result.datasets.begin(), result.datasets.end(),
                   [](const DatasetResult& x, const DatasetResult& y) {
                     if (x.differs() != y.differs()) return x.differs();
                     if (x.differs()) {
                       if (x.first->tick != y.first->tick) return x.first->tick < y.first->tick;
                       if (loop_rank(x.loop) != loop_rank(y.loop))
                         return loop_rank(x.loop) < loop_rank(y.loop);
                     }
                     return x.path < y.path;
                   });
}

CompareResult compare_impl(const std::string& file_a, const std::string& file_b,
                           const CompareOptions& options) {
  check_options(options);
  CompareResult result;
  result.file_a = file_a;
  result.file_b = file_b;
  result.options = options;
  const OpenTrace a = open_trace(file_a);
  const OpenTrace b = open_trace(file_b);
  for (const OpenTrace* t : {&a, &b})
    if (t->swmr)
      result.notes.push_back(quoted(t->name) + " was not closed cleanly (still marked open for "
                             "writing); it was opened in SWMR read mode");

  const Attributes attrs_a = root_attributes(a);
  const Attributes attrs_b = root_attributes(b);
  check_schema(a, b, attrs_a, attrs_b, result);
  check_rates(a, b, attrs_a, attrs_b, result);
  compare_attributes(a, b, attrs_a, attrs_b, options, result);

  std::vector<bool> rule_used(options.rules.size(), false);
  for (const std::string& g : shared_tables(a, b, options, result)) {
    const std::vector<std::string> names_a = datasets_below(a, g);
    if (!std::binary_search(names_a.begin(), names_a.end(), std::string("tick"))) {
      result.notes.push_back("group /" + g + " has no tick column and is not compared");
      continue;
    }
    compare_loop(a, b, g, options, rule_used, result);
  }
  for (std::size_t r = 0; r < options.rules.size(); ++r)
    if (!rule_used[r])
      fail("tolerance pattern " + quoted(options.rules[r].pattern) +
           " matches no dataset (paths look like physics/objects/<object>/position)");
  sort_datasets(result);
  return result;
}

}  // namespace

bool tolerance_pattern_matches(const std::string& pattern, const std::string& path) {
  const std::string p = pattern.substr(std::min(pattern.find_first_not_of('/'), pattern.size()));
  const std::string d = path.substr(std::min(path.find_first_not_of('/'), path.size()));
  return fnmatch(p.c_str(), d.c_str(), 0) == 0;
}

std::int64_t CompareResult::differing_datasets() const {
  std::int64_t n = 0;
  for (const DatasetResult& d : datasets) n += d.differs();
  return n;
}

std::int64_t CompareResult::counted_attributes() const {
  std::int64_t n = 0;
  for (const AttributeDifference& d : attributes) n += d.counted;
  return n;
}

std::int64_t CompareResult::unmatched_ticks() const {
  std::int64_t n = 0;
  for (const LoopAlignment& l : loops) n += l.only_a + l.only_b;
  return n;
}

bool CompareResult::same() const {
  return differing_datasets() == 0 && counted_attributes() == 0 &&
         !(options.all_ticks && unmatched_ticks() > 0);
}

CompareResult compare_traces(const std::string& a, const std::string& b,
                             const CompareOptions& options) {
  h5::Lock lock;
  h5::Quiet quiet;
  try {
    return compare_impl(a, b, options);
  } catch (const CompareInputError&) {
    throw;
  } catch (const TraceError& e) {
    throw CompareInputError(e.what());
  } catch (const std::bad_alloc&) {
    throw CompareInputError("comparing " + quoted(a) + " and " + quoted(b) + ": not enough memory");
  }
}

}  // namespace graspsim::recordings
