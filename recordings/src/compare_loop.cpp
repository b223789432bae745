// One loop of a comparison, step by step: open its columns, align its rows by tick, compare
// every other column on the aligned rows, a block at a time.
#include "compare_loop.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <variant>

#include "compare_columns.hpp"
#include "table_layout.hpp"

namespace graspsim::recordings::compare {
namespace {

// ---- element comparison ---------------------------------------------------------------------

struct Verdict {
  bool exceeded;
  double abs_error, rel_error;
};

Verdict compare_element(double a, double b, const Tolerance& tol, bool bitwise) {
  Verdict v{false, 0.0, 0.0};
  const bool nan_a = std::isnan(a), nan_b = std::isnan(b);
  if (nan_a || nan_b) {
    v.abs_error = v.rel_error = nan_a && nan_b ? 0.0 : std::numeric_limits<double>::infinity();
  } else if (a != b) {
    v.abs_error = std::fabs(a - b);   // inf if either is infinite
    v.rel_error = std::isinf(v.abs_error) ? v.abs_error
                                          : v.abs_error / std::max(std::fabs(a), std::fabs(b));
  }
  if (bitwise) {
    v.exceeded = std::bit_cast<std::uint64_t>(a) != std::bit_cast<std::uint64_t>(b);
  } else if (nan_a || nan_b) {
    v.exceeded = !(nan_a && nan_b);
  } else if (a != b) {
    v.exceeded = !std::isfinite(a) || !std::isfinite(b) ||
                 !(v.abs_error <= tol.atol + tol.rtol * std::max(std::fabs(a), std::fabs(b)));
  }
  return v;
}

// Integers: equal only if equal as integers; the error is the exact difference, in double.
template <typename T>
Verdict compare_integer(T a, T b, const Tolerance& tol) {
  Verdict v{false, 0.0, 0.0};
  if (a == b) return v;
  v.abs_error = a > b ? static_cast<double>(static_cast<std::uint64_t>(a) - static_cast<std::uint64_t>(b))
                      : static_cast<double>(static_cast<std::uint64_t>(b) - static_cast<std::uint64_t>(a));
  const double scale = std::max(std::fabs(static_cast<double>(a)), std::fabs(static_cast<double>(b)));
  v.rel_error = v.abs_error / scale;
  v.exceeded = !(v.abs_error <= tol.atol + tol.rtol * scale);
  return v;
}

// Where the rows of one loop meet: pairs of row indices with the same tick, in tick order.
struct Alignment {
  std::vector<std::int64_t> row_a, row_b, tick;
  std::vector<double> time;   // A's time at each pair
};

template <typename T>
// Compares aligned rows [k0, k1) of one column pair, adding to `out`.
void compare_range(BlockReader<T>& ra, BlockReader<T>& rb, std::size_t width, std::size_t k0,
                   std::size_t k1, const Alignment& al, const CompareOptions& options,
                   DatasetResult& out) {
  for (std::size_t k = k0; k < k1; ++k) {
    const T* pa = ra.row(al.row_a[k]);
    const T* pb = rb.row(al.row_b[k]);
    for (std::size_t j = 0; j < width; ++j) {
      Verdict v;
      if constexpr (std::is_same_v<T, double>) {
        v = compare_element(pa[j], pb[j], out.tolerance, options.bitwise);
      } else {
        v = compare_integer(pa[j], pb[j], out.tolerance);
      }
      ++out.elements;
      if (v.abs_error > out.max_abs_error) {
        out.max_abs_error = v.abs_error;
        out.worst = ElementPoint{al.tick[k], al.time[k], j, static_cast<double>(pa[j]),
                                 static_cast<double>(pb[j]), v.abs_error, v.rel_error};
      }
      out.max_rel_error = std::max(out.max_rel_error, v.rel_error);
      if (v.exceeded) {
        if (out.exceeded == 0)
          out.first = ElementPoint{al.tick[k], al.time[k], j, static_cast<double>(pa[j]),
                                   static_cast<double>(pb[j]), v.abs_error, v.rel_error};
        ++out.exceeded;
      }
    }
  }
}

void describe(DatasetResult& d, const Column& c) {
  std::vector<std::string> seg;
  std::size_t start = 0;
  while (start < d.path.size()) {
    std::size_t end = d.path.find('/', start);
    if (end == std::string::npos) end = d.path.size();
    seg.push_back(d.path.substr(start, end - start));
    start = end + 1;
  }
  d.loop = seg.empty() ? "" : seg[0];
  std::size_t q = 1;
  if (seg.size() >= 4 && (seg[1] == "objects" || seg[1] == "fingers")) {
    d.kind = seg[1] == "objects" ? "object" : "finger";
    d.name = seg[2];
    q = 3;
  }
  for (std::size_t i = q; i < seg.size(); ++i) d.quantity += (i > q ? "/" : "") + seg[i];
  d.units = c.units;
  if (c.rank == 1) d.components = {""};
  else if (c.order.size() == c.width) d.components = c.order;
  else if (c.width == 3) d.components = {"x", "y", "z"};
  else
    for (std::size_t j = 0; j < c.width; ++j) d.components.push_back(std::to_string(j));
}

std::string shape_text(const Column& c) {
  return c.rank == 1 ? "(" + std::to_string(c.rows) + ")"
                     : "(" + std::to_string(c.rows) + ", " + std::to_string(c.width) + ")";
}

const char* kind_text(Kind k) {
  switch (k) {
    case Kind::kFloat: return "floating-point";
    case Kind::kSigned: return "signed integer";
    default: return "unsigned integer";
  }
}


// The columns of one loop in both traces, opened and paired by name.
struct LoopColumns {
  std::vector<std::string> names;          // sorted; the same in both traces
  std::vector<Column> a, b;                // names[k] in each trace
  std::int64_t rows_a = 0, rows_b = 0;     // rows every column of the table holds
  std::size_t tick = 0, time = 0;          // indices of the tick and time columns
};

// A table's datasets grow together; if they do not (a write cut by a crash), only the rows
// every dataset holds are compared, with a note.
std::int64_t usable_rows(const std::vector<Column>& cols, const OpenTrace& t, const std::string& group,
                         CompareResult& result) {
  std::int64_t lo = cols.front().rows, hi = cols.front().rows;
  for (const Column& c : cols) lo = std::min(lo, c.rows), hi = std::max(hi, c.rows);
  if (lo != hi)
    result.notes.push_back(quoted(t.name) + ": the datasets of /" + group + " hold " +
                           std::to_string(lo) + " to " + std::to_string(hi) +
                           " rows (a write cut short?); the first " + std::to_string(lo) +
                           " are compared");
  return lo;
}

// Opens the columns of loop `group` in both traces: the same names in each, a tick and a time
// column, and a tick column of one integer per row.
LoopColumns open_loop(const OpenTrace& a, const OpenTrace& b, const std::string& group,
                      CompareResult& result) {
  LoopColumns cols;
  cols.names = datasets_below(a, group);
  const std::vector<std::string> names_b = datasets_below(b, group);
  for (const std::string& n : cols.names)
    if (!std::binary_search(names_b.begin(), names_b.end(), n))
      fail("dataset " + quoted("/" + group + "/" + n) + " is in " + quoted(a.name) +
           " but missing in " + quoted(b.name));
  for (const std::string& n : names_b)
    if (!std::binary_search(cols.names.begin(), cols.names.end(), n))
      fail("dataset " + quoted("/" + group + "/" + n) + " is in " + quoted(b.name) +
           " but missing in " + quoted(a.name));
  for (const char* key : {"tick", "time"})
    if (!std::binary_search(cols.names.begin(), cols.names.end(), key))
      fail("table " + quoted("/" + group) + " of " + quoted(a.name) + " and " + quoted(b.name) +
           " has no " + quoted(key) + " column, so its rows cannot be aligned");
  cols.a = open_columns(a, group, cols.names);
  cols.b = open_columns(b, group, cols.names);
  cols.rows_a = usable_rows(cols.a, a, group, result);
  cols.rows_b = usable_rows(cols.b, b, group, result);
  const auto index_of = [&](const char* key) {
    return static_cast<std::size_t>(
        std::lower_bound(cols.names.begin(), cols.names.end(), key) - cols.names.begin());
  };
  cols.tick = index_of("tick");
  cols.time = index_of("time");
  for (const Column* c : {&cols.a[cols.tick], &cols.b[cols.tick]})
    if (c->kind == Kind::kFloat || c->width != 1)
      fail("trace " + quoted(c->file) + ", dataset " + quoted(c->path) +
           ": a tick column holds one integer per row");
  return cols;
}

// The rows a compound table's columns share, in each trace, and the rows compared at a time.
struct SharedRows {
  std::optional<TableRows> a, b;   // empty for a schema 2 group of datasets
  std::int64_t step = 1;           // rows per block of every column reader
};

// A compound table is read a block of whole rows at a time, shared by its columns, and
// compared block by block (every column of a block, then the next block), so each row of the
// file is read once. A block is at most 4 MiB of rows and at most `block_rows`. The columns
// point at `shared`, which must stay where it is while they are read.
void share_table_rows(SharedRows& shared, LoopColumns& cols, const OpenTrace& a, const OpenTrace& b,
                      const std::string& group, std::size_t block_rows) {
  shared.step = static_cast<std::int64_t>(std::max<std::size_t>(block_rows, 1));
  if (cols.a[cols.tick].member.empty() || cols.b[cols.tick].member.empty()) return;
  const auto share = [&](std::optional<TableRows>& t, std::vector<Column>& columns,
                         const OpenTrace& o, std::int64_t rows) {
    t.emplace();
    t->file = o.name;
    t->path = "/" + group;
    const std::string context = "trace " + quoted(o.name) + ", table " + quoted("/" + group);
    t->dataset = h5::checked(H5Dopen2(o.file.get(), group.c_str(), H5P_DEFAULT), H5Dclose, context + ": cannot open");
    h5::Handle file_type = h5::checked(H5Dget_type(t->dataset.get()), H5Tclose, context);
    t->type = h5::packed_native(file_type.get(), context);   // the offsets table_layout gives the columns
    t->row_bytes = H5Tget_size(t->type.get());
    t->rows = rows;
    t->block = std::max<std::int64_t>(
        1, std::min<std::int64_t>(shared.step, static_cast<std::int64_t>((4u << 20) / std::max<std::size_t>(t->row_bytes, 1))));
    for (Column& c : columns) c.table_rows = &*t;
  };
  share(shared.a, cols.a, a, cols.rows_a);
  share(shared.b, cols.b, b, cols.rows_b);
  shared.step = std::min(shared.a->block, shared.b->block);
}

// Throws unless the ticks of `c` (read whole) strictly increase, or with `repeats` (a table of
// several rows per tick, /contacts) never decrease.
void check_increasing(const std::vector<std::int64_t>& ticks, const Column& c, bool repeats) {
  for (std::size_t r = 1; r < ticks.size(); ++r)
    if (ticks[r] < ticks[r - 1] || (!repeats && ticks[r] == ticks[r - 1]))
      fail("trace " + quoted(c.file) + ", dataset " + quoted(c.path) + ": ticks do not increase at row " +
           std::to_string(r) + " (" + std::to_string(ticks[r - 1]) + " then " +
           std::to_string(ticks[r]) + ")");
}

// Pairs the rows of A and B with the same tick (a merge join of two increasing tick columns),
// counting the ticks found in one trace only in `loop`. Where a tick has several rows, its k-th
// row in A meets its k-th in B, and rows beyond the shorter run count as found in one only.
Alignment align(const std::vector<std::int64_t>& ticks_a, const std::vector<std::int64_t>& ticks_b,
                const std::vector<double>& times_a, LoopAlignment& loop) {
  Alignment al;
  std::size_t i = 0, j = 0;
  while (i < ticks_a.size() || j < ticks_b.size()) {
    if (j == ticks_b.size() || (i < ticks_a.size() && ticks_a[i] < ticks_b[j])) {
      if (!loop.first_only_a) loop.first_only_a = ticks_a[i];
      ++loop.only_a, ++i;
    } else if (i == ticks_a.size() || ticks_b[j] < ticks_a[i]) {
      if (!loop.first_only_b) loop.first_only_b = ticks_b[j];
      ++loop.only_b, ++j;
    } else {
      al.row_a.push_back(static_cast<std::int64_t>(i));
      al.row_b.push_back(static_cast<std::int64_t>(j));
      al.tick.push_back(ticks_a[i]);
      al.time.push_back(times_a[i]);
      ++i, ++j;
    }
  }
  loop.matched = static_cast<std::int64_t>(al.tick.size());
  return al;
}

// One column compared: its result so far, and the readers of its rows in A and B.
struct ColumnPair {
  using Readers = std::variant<std::pair<BlockReader<double>, BlockReader<double>>,
                               std::pair<BlockReader<std::int64_t>, BlockReader<std::int64_t>>,
                               std::pair<BlockReader<std::uint64_t>, BlockReader<std::uint64_t>>>;
  DatasetResult result;
  Readers readers;
  std::size_t width = 1;
};

// The tolerance of dataset `d`: the last rule whose pattern matches it, else the global one;
// none in bitwise mode. Marks the rule used.
void set_tolerance(DatasetResult& d, const CompareOptions& options, std::vector<bool>& rule_used) {
  d.tolerance = options.tolerance;
  for (std::size_t r = 0; r < options.rules.size(); ++r) {
    if (tolerance_pattern_matches(options.rules[r].pattern, d.path)) {
      d.tolerance = options.rules[r].tolerance;
      d.rule = options.rules[r].pattern;
      rule_used[r] = true;
    }
  }
  if (options.bitwise) d.tolerance = Tolerance{};
}

// Every column but the tick (the key the rows were aligned by), checked to have the same shape
// and kind in both traces, described, given its tolerance and its readers.
std::vector<ColumnPair> pair_columns(const LoopColumns& cols, const OpenTrace& a, const OpenTrace& b,
                                     const std::string& group, const CompareOptions& options,
                                     std::int64_t step, std::vector<bool>& rule_used) {
  std::vector<ColumnPair> pairs;
  const std::size_t block = static_cast<std::size_t>(step);
  for (std::size_t k = 0; k < cols.names.size(); ++k) {
    if (k == cols.tick) continue;
    const Column& ca = cols.a[k];
    const Column& cb = cols.b[k];
    if (ca.rank != cb.rank || ca.width != cb.width)
      fail("dataset " + quoted(ca.path) + " has different shapes: " + shape_text(ca) + " in " +
           quoted(a.name) + ", " + shape_text(cb) + " in " + quoted(b.name));
    if (ca.kind != cb.kind)
      fail(std::string("dataset ") + quoted(ca.path) + " holds " + kind_text(ca.kind) + "s in " +
           quoted(a.name) + " but " + kind_text(cb.kind) + "s in " + quoted(b.name));
    DatasetResult d;
    d.path = group + "/" + cols.names[k];
    describe(d, ca);
    d.integer = ca.kind != Kind::kFloat;
    set_tolerance(d, options, rule_used);
    const auto readers = [&]() -> ColumnPair::Readers {
      switch (ca.kind) {
        case Kind::kFloat:
          return ColumnPair::Readers(std::in_place_index<0>, BlockReader<double>(ca, cols.rows_a, block),
                                     BlockReader<double>(cb, cols.rows_b, block));
        case Kind::kSigned:
          return ColumnPair::Readers(std::in_place_index<1>, BlockReader<std::int64_t>(ca, cols.rows_a, block),
                                     BlockReader<std::int64_t>(cb, cols.rows_b, block));
        default:
          return ColumnPair::Readers(std::in_place_index<2>, BlockReader<std::uint64_t>(ca, cols.rows_a, block),
                                     BlockReader<std::uint64_t>(cb, cols.rows_b, block));
      }
    };
    pairs.push_back(ColumnPair{std::move(d), readers(), ca.width});
  }
  return pairs;
}

// Compares every column over the aligned rows, a range at a time whose rows lie in one block of
// each file (a decimated or cut trace skips rows: its range ends where its rows would leave the
// block), so each block is read once for all columns.
void compare_aligned(std::vector<ColumnPair>& pairs, const Alignment& al, const SharedRows& shared,
                     const CompareOptions& options) {
  const std::int64_t block_a = shared.a ? shared.a->block : shared.step;
  const std::int64_t block_b = shared.b ? shared.b->block : shared.step;
  for (std::size_t k0 = 0, k1 = 0; k0 < al.tick.size(); k0 = k1) {
    k1 = k0 + 1;
    while (k1 < al.tick.size() && al.row_a[k1] - al.row_a[k0] < block_a &&
           al.row_b[k1] - al.row_b[k0] < block_b)
      ++k1;
    for (ColumnPair& p : pairs) {
      std::visit([&](auto& r) { compare_range(r.first, r.second, p.width, k0, k1, al, options, p.result); },
                 p.readers);
    }
  }
}

}  // namespace

// One loop (a table with a tick column): open its columns, align its rows by tick, compare
// every other column on the aligned rows.
void compare_loop(const OpenTrace& a, const OpenTrace& b, const std::string& group,
                  const CompareOptions& options, std::vector<bool>& rule_used,
                  CompareResult& result) {
  LoopColumns cols = open_loop(a, b, group, result);
  SharedRows shared;
  share_table_rows(shared, cols, a, b, group, options.block_rows);

  const auto ticks_a = read_all<std::int64_t>(cols.a[cols.tick], cols.rows_a, options.block_rows);
  const auto ticks_b = read_all<std::int64_t>(cols.b[cols.tick], cols.rows_b, options.block_rows);
  const bool repeats = group == "contacts";
  check_increasing(ticks_a, cols.a[cols.tick], repeats);
  check_increasing(ticks_b, cols.b[cols.tick], repeats);
  const auto times_a = read_all<double>(cols.a[cols.time], cols.rows_a, options.block_rows);
  LoopAlignment loop;
  loop.loop = group;
  loop.rows_a = cols.rows_a;
  loop.rows_b = cols.rows_b;
  const Alignment al = align(ticks_a, ticks_b, times_a, loop);
  result.loops.push_back(loop);

  std::vector<ColumnPair> pairs = pair_columns(cols, a, b, group, options, shared.step, rule_used);
  compare_aligned(pairs, al, shared, options);
  for (ColumnPair& p : pairs) result.datasets.push_back(std::move(p.result));
}

}  // namespace graspsim::recordings::compare
