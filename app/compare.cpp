// `graspsim compare` output: table and JSON.
#include "app/compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "app/json.hpp"
#include "graspsim/recordings/record_selection.hpp"
#include "graspsim/recordings/trace_reader.hpp"

namespace graspsim::app {
namespace {

using recordings::CompareResult;
using recordings::DatasetResult;
using recordings::ElementPoint;

std::string printf_string(const char* format, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

std::string exact(double x) { return printf_string("%.17g", x); }
std::string brief(double x) { return printf_string("%.3g", x); }

std::string pad(const std::string& s, std::size_t width, bool right = false) {
  if (s.size() >= width) return s;
  return right ? std::string(width - s.size(), ' ') + s : s + std::string(width - s.size(), ' ');
}

// One line of a multi-line string attribute where the two values part, or the whole value.
std::string shorten(const std::string& v) {
  std::string one = v;
  for (char& c : one)
    if (c == '\n') c = ' ';
  if (one.size() > 70) one = one.substr(0, 67) + "...";
  return "'" + one + "'";
}

std::string attribute_note(const recordings::AttributeDifference& d) {
  std::string s = "root attribute '" + d.name + "' ";
  if (!d.a) return s + "only in B: " + shorten(*d.b);
  if (!d.b) return s + "only in A: " + shorten(*d.a);
  if (d.a->find('\n') != std::string::npos || d.b->find('\n') != std::string::npos) {
    // Multi-line text (scenario source, parameters): the first line that differs.
    std::istringstream la(*d.a), lb(*d.b);
    std::string x, y;
    int line = 0;
    while (true) {
      const bool ga = static_cast<bool>(std::getline(la, x));
      const bool gb = static_cast<bool>(std::getline(lb, y));
      ++line;
      if (!ga) x = "<end>";
      if (!gb) y = "<end>";
      if (x != y || (!ga && !gb)) break;
    }
    return s + "differs from line " + std::to_string(line) + ": A " + shorten(x) + ", B " +
           shorten(y);
  }
  return s + "differs: A " + shorten(*d.a) + ", B " + shorten(*d.b);
}

std::string component_of(const DatasetResult& d, std::size_t j) {
  return j < d.components.size() ? d.components[j] : std::to_string(j);
}

std::string tolerance_text(const recordings::Tolerance& t) {
  if (t.atol == 0 && t.rtol == 0) return "exact values";
  return "atol " + brief(t.atol) + ", rtol " + brief(t.rtol);
}

// --- JSON ------------------------------------------------------------------------------------

// Finite numbers exactly (%.17g); inf, -inf and nan as the strings "inf", "-inf", "nan".
std::string json_number(double x) {
  if (std::isnan(x)) return "\"nan\"";
  if (std::isinf(x)) return x > 0 ? "\"inf\"" : "\"-inf\"";
  return exact(x);
}

std::string json_point(const std::optional<ElementPoint>& p, const DatasetResult& d) {
  if (!p) return "null";
  return "{\"tick\": " + std::to_string(p->tick) + ", \"time\": " + json_number(p->time) +
         ", \"component\": " + json_string(component_of(d, p->component)) +
         ", \"a\": " + json_number(p->a) + ", \"b\": " + json_number(p->b) +
         ", \"abs_error\": " + json_number(p->abs_error) +
         ", \"rel_error\": " + json_number(p->rel_error) + "}";
}

}  // namespace

std::string missing_loop_tables(const std::string& trace) {
  const std::optional<std::string> attribute =
      recordings::has_attribute(trace, "/", "record")
          ? std::optional<std::string>(recordings::read_string_attribute(trace, "/", "record"))
          : std::nullopt;
  recordings::RecordSelection record;
  try {
    record = recordings::RecordSelection::from_attribute(attribute);
  } catch (const std::invalid_argument& e) {   // a damaged or hand-edited attribute
    return "'" + trace + "' is not a whole graspsim trace: its root attribute record '" + *attribute +
           "' " + e.what();
  }
  const std::vector<std::string> datasets = recordings::list_datasets(trace);
  const auto holds = [&](const std::string& path) { return std::binary_search(datasets.begin(), datasets.end(), path); };
  std::string missing;
  for (const auto loop : {recordings::RecordedLoop::kServo, recordings::RecordedLoop::kHaptic,
                          recordings::RecordedLoop::kPhysics}) {
    if (!record.records(loop)) continue;
    const std::string name(recordings::kRecordedLoopNames[static_cast<std::size_t>(loop)]);
    if (holds("/" + name + "/tick")) continue;
    missing += (missing.empty() ? "" : "; ") + std::string("/") + name +
               (holds("/" + name) ? " is a plain dataset, not a table of ticks" : " is missing");
  }
  if (missing.empty()) return "";
  return "'" + trace + "' is not a whole graspsim trace: " + missing + " (" +
         (attribute ? "its root attribute record is '" + *attribute + "'" : std::string("it has no root attribute record: every loop")) +
         ", and a run writes each loop it records as a table with a tick column)";
}

std::string compare_table(const CompareResult& r, bool all) {
  std::ostringstream o;
  const auto& opt = r.options;
  o << "graspsim compare\n";
  o << "  A  " << r.file_a << "\n";
  o << "  B  " << r.file_b << "\n";
  o << "  schema " << r.schema_version;
  if (r.schema_version_b != r.schema_version) o << " (B: " << r.schema_version_b << ")";
  o << ", rates " << r.rate_servo << " / " << r.rate_haptic
    << " / " << r.rate_physics << " Hz (servo / haptic / physics)\n";
  if (opt.bitwise) {
    o << "  test       bitwise: every element's stored bits equal (NaN equals NaN with the same "
         "bits; -0 differs from 0)\n";
  } else {
    o << "  test       |A - B| <= atol + rtol * max(|A|, |B|); " << tolerance_text(opt.tolerance);
    for (const auto& rule : opt.rules)
      o << "; " << rule.pattern << ": " << tolerance_text(rule.tolerance);
    o << "\n";
  }
  o << "\n  " << pad("loop", 9) << pad("rows A", 10, true) << pad("rows B", 10, true)
    << pad("matched", 10, true) << pad("only A", 10, true) << pad("only B", 10, true) << "\n";
  for (const auto& l : r.loops) {
    o << "  " << pad(l.loop, 9) << pad(std::to_string(l.rows_a), 10, true)
      << pad(std::to_string(l.rows_b), 10, true) << pad(std::to_string(l.matched), 10, true)
      << pad(std::to_string(l.only_a), 10, true) << pad(std::to_string(l.only_b), 10, true);
    if (l.first_only_a) o << "   first only in A: tick " << *l.first_only_a;
    if (l.first_only_b) o << "   first only in B: tick " << *l.first_only_b;
    o << "\n";
  }
  // Tables one trace holds and the other does not: listed, not compared, not a difference.
  for (const auto& t : r.one_sided)
    o << "  " << pad(t.table, 9) << "  only in " << (t.in_a ? "A" : "B") << ": not compared\n";
  if (!opt.only.empty()) {
    o << "  (--only";
    for (const auto& l : opt.only) o << " " << l;
    o << ": other loops not compared)\n";
  }
  o << "\n";

  const std::int64_t differing = r.differing_datasets();
  const std::size_t total = r.datasets.size();
  if (r.same()) {
    o << (opt.bitwise ? "SAME: bitwise identical, " : "SAME within tolerance: ") << total
      << " datasets";
    double worst = 0.0;
    for (const auto& d : r.datasets) worst = std::max(worst, d.max_abs_error);
    if (!opt.bitwise) o << ", largest absolute error " << brief(worst);
    o << "\n";
  } else {
    o << "DIFFERENT:";
    if (differing > 0) {
      const DatasetResult& d = r.datasets.front();
      o << " " << differing << " of " << total << " datasets "
        << (opt.bitwise ? "differ in their bits" : "exceed the tolerance") << "; first at "
        << d.loop << " tick " << d.first->tick << " (t = " << printf_string("%.6g", d.first->time)
        << " s): " << (d.kind.empty() ? "" : d.kind + " " + d.name + " ") << d.quantity;
      const std::string c = component_of(d, d.first->component);
      if (!c.empty()) o << " " << c;
    }
    if (r.counted_attributes() > 0)
      o << (differing > 0 ? ";" : "") << " " << r.counted_attributes()
        << " root attributes differ";
    if (opt.all_ticks && r.unmatched_ticks() > 0)
      o << ((differing > 0 || r.counted_attributes() > 0) ? ";" : "") << " "
        << r.unmatched_ticks() << " ticks are in one trace only";
    o << "\n";
  }

  const auto row = [&](const DatasetResult& d, bool differs) {
    const ElementPoint* p = differs ? &*d.first : (d.worst ? &*d.worst : nullptr);
    o << "  " << pad(p ? std::to_string(p->tick) : "-", 10, true) << "  "
      << pad(p ? printf_string("%.6f", p->time) : "-", 11, true) << "  " << pad(d.loop, 8)
      << pad(d.kind.empty() ? "-" : d.name, 14) << pad(d.quantity, 18)
      << pad(p ? component_of(d, p->component) : "", 5)
      << pad(p ? exact(p->a) : "", 25) << pad(p ? exact(p->b) : "", 25)
      << pad(brief(d.max_abs_error), 10) << pad(brief(d.max_rel_error), 10)
      << std::to_string(d.exceeded) << "/" << std::to_string(d.elements) << "\n";
  };
  const auto header = [&](const char* first) {
    o << "  " << pad(first, 10, true) << "  " << pad("time (s)", 11, true) << "  "
      << pad("loop", 8) << pad("obj/finger", 14) << pad("quantity", 18) << pad("comp", 5)
      << pad("A", 25) << pad("B", 25) << pad("max abs", 10) << pad("max rel", 10)
      << "out/compared\n";
  };
  if (differing > 0) {
    o << "\ndiffering datasets, by first divergence (A and B: the values there):\n";
    header("first tick");
    for (const auto& d : r.datasets)
      if (d.differs()) row(d, true);
  }
  if (all && static_cast<std::size_t>(differing) < total) {
    o << "\ndatasets within tolerance (A and B: where the absolute error is largest):\n";
    header("tick");
    for (const auto& d : r.datasets)
      if (!d.differs()) row(d, false);
  } else if (differing > 0 && static_cast<std::size_t>(differing) < total) {
    o << "  (" << total - static_cast<std::size_t>(differing)
      << " more datasets within tolerance; --all lists them)\n";
  }

  if (!r.attributes.empty() || !r.notes.empty()) {
    o << "\nnotes:\n";
    for (const auto& a : r.attributes)
      o << "  " << attribute_note(a)
        << (a.counted ? "" : " (not counted; --attributes counts it)") << "\n";
    for (const auto& n : r.notes) o << "  " << n << "\n";
  }
  return o.str();
}

std::string compare_json(const CompareResult& r) {
  std::ostringstream o;
  const auto& opt = r.options;
  o << "{\n";
  o << "  \"a\": " << json_string(r.file_a) << ",\n";
  o << "  \"b\": " << json_string(r.file_b) << ",\n";
  o << "  \"same\": " << (r.same() ? "true" : "false") << ",\n";
  o << "  \"exit_code\": " << (r.same() ? 0 : 1) << ",\n";
  o << "  \"schema_version\": " << r.schema_version << ",\n";
  o << "  \"schema_version_b\": " << r.schema_version_b << ",\n";
  o << "  \"rates\": {\"servo\": " << r.rate_servo << ", \"haptic\": " << r.rate_haptic
    << ", \"physics\": " << r.rate_physics << "},\n";
  o << "  \"bitwise\": " << (opt.bitwise ? "true" : "false") << ",\n";
  o << "  \"attributes_counted\": " << (opt.attributes ? "true" : "false") << ",\n";
  o << "  \"all_ticks\": " << (opt.all_ticks ? "true" : "false") << ",\n";
  o << "  \"tolerance\": {\"atol\": " << json_number(opt.tolerance.atol)
    << ", \"rtol\": " << json_number(opt.tolerance.rtol) << "},\n";
  o << "  \"rules\": [";
  for (std::size_t i = 0; i < opt.rules.size(); ++i)
    o << (i ? ", " : "") << "{\"pattern\": " << json_string(opt.rules[i].pattern)
      << ", \"atol\": " << json_number(opt.rules[i].tolerance.atol)
      << ", \"rtol\": " << json_number(opt.rules[i].tolerance.rtol) << "}";
  o << "],\n";
  o << "  \"loops\": [";
  for (std::size_t i = 0; i < r.loops.size(); ++i) {
    const auto& l = r.loops[i];
    o << (i ? "," : "") << "\n    {\"loop\": " << json_string(l.loop) << ", \"rows_a\": " << l.rows_a
      << ", \"rows_b\": " << l.rows_b << ", \"matched\": " << l.matched
      << ", \"only_a\": " << l.only_a << ", \"only_b\": " << l.only_b
      << ", \"first_only_a\": " << (l.first_only_a ? std::to_string(*l.first_only_a) : "null")
      << ", \"first_only_b\": " << (l.first_only_b ? std::to_string(*l.first_only_b) : "null")
      << "}";
  }
  o << "\n  ],\n";
  o << "  \"one_sided_tables\": [";
  for (std::size_t i = 0; i < r.one_sided.size(); ++i)
    o << (i ? ", " : "") << "{\"table\": " << json_string(r.one_sided[i].table) << ", \"in\": \""
      << (r.one_sided[i].in_a ? "a" : "b") << "\"}";
  o << "],\n";
  o << "  \"only\": [";
  for (std::size_t i = 0; i < opt.only.size(); ++i) o << (i ? ", " : "") << json_string(opt.only[i]);
  o << "],\n";
  o << "  \"differing_datasets\": " << r.differing_datasets() << ",\n";
  o << "  \"datasets\": [";
  for (std::size_t i = 0; i < r.datasets.size(); ++i) {
    const auto& d = r.datasets[i];
    o << (i ? "," : "") << "\n    {\"path\": " << json_string(d.path)
      << ", \"loop\": " << json_string(d.loop) << ", \"kind\": " << json_string(d.kind)
      << ", \"name\": " << json_string(d.name) << ", \"quantity\": " << json_string(d.quantity)
      << ", \"components\": [";
    for (std::size_t j = 0; j < d.components.size(); ++j)
      o << (j ? ", " : "") << json_string(d.components[j]);
    o << "], \"units\": " << json_string(d.units) << ", \"integer\": "
      << (d.integer ? "true" : "false") << ", \"atol\": " << json_number(d.tolerance.atol)
      << ", \"rtol\": " << json_number(d.tolerance.rtol) << ", \"rule\": " << json_string(d.rule)
      << ", \"differs\": " << (d.differs() ? "true" : "false")
      << ", \"elements\": " << d.elements << ", \"exceeded\": " << d.exceeded
      << ", \"max_abs_error\": " << json_number(d.max_abs_error)
      << ", \"max_rel_error\": " << json_number(d.max_rel_error)
      << ", \"first\": " << json_point(d.first, d) << ", \"worst\": " << json_point(d.worst, d)
      << "}";
  }
  o << "\n  ],\n";
  o << "  \"attribute_differences\": [";
  for (std::size_t i = 0; i < r.attributes.size(); ++i) {
    const auto& a = r.attributes[i];
    o << (i ? "," : "") << "\n    {\"name\": " << json_string(a.name)
      << ", \"a\": " << (a.a ? json_string(*a.a) : "null")
      << ", \"b\": " << (a.b ? json_string(*a.b) : "null")
      << ", \"counted\": " << (a.counted ? "true" : "false") << "}";
  }
  o << "\n  ],\n";
  o << "  \"notes\": [";
  for (std::size_t i = 0; i < r.notes.size(); ++i)
    o << (i ? ", " : "") << json_string(r.notes[i]);
  o << "]\n}\n";
  return o.str();
}

std::string compare_error_json(const std::string& message) {
  return "{\"exit_code\": 2, \"error\": " + json_string(message) + "}\n";
}

}  // namespace graspsim::app
