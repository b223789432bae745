// Trace comparison (see trace_compare.hpp and recordings/README.md, "Comparing traces").
//
// Each loop's rows are aligned by tick with a merge join of the two (increasing) tick columns,
// so a shorter, cut or decimated trace still compares where ticks match. Every other dataset of
// the loop is then read in hyperslabs of block_rows rows (never row by row) and compared pair
// by pair in tick order, so the first element outside the tolerance is the first divergence.
#include "graspsim/recordings/trace_compare.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <cstring>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <type_traits>
#include <variant>

#include "h5.hpp"
#include "h5_checks.hpp"

namespace graspsim::recordings {
namespace {

std::string quoted(const std::string& text) { return "'" + text + "'"; }

[[noreturn]] void fail(const std::string& message) { throw CompareInputError(message); }

struct OpenTrace {
  std::string name;     // as given
  h5::Handle file;
  bool swmr = false;    // opened in SWMR read mode (the file was not closed cleanly)
};

OpenTrace open_trace(const std::string& path) {
  h5::OpenFile opened = h5::open_read_only(path, "cannot open trace " + quoted(path));
  OpenTrace trace;
  trace.name = path;
  trace.file = std::move(opened.file);
  trace.swmr = opened.swmr;   // skipped the still-open mark, as h5py's swmr=True does
  return trace;
}

// ---- attributes -----------------------------------------------------------------------------

herr_t collect_attribute(hid_t, const char* name, const H5A_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->push_back(name);
  return 0;
}

std::string format_double(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// Any root attribute as text: strings as they are, numbers exactly (%.17g), arrays joined by
// ", ", anything else by its type.
std::string attribute_text(hid_t object, const std::string& name, const std::string& context) {
  h5::Handle attribute = h5::checked(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose,
                                     context + ": cannot open attribute " + quoted(name));
  h5::Handle type = h5::checked(H5Aget_type(attribute.get()), H5Tclose, context);
  h5::Handle space = h5::checked(H5Aget_space(attribute.get()), H5Sclose, context);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  const H5T_class_t type_class = H5Tget_class(type.get());
  // A damaged dataspace may claim any count: 8 bytes each must fit in the file.
  if (n < 0 || static_cast<std::uint64_t>(n) > h5::file_size(object, context) / 8)
    fail(context + ": attribute " + quoted(name) + " claims " + std::to_string(n) + " elements (damaged?)");
  if (type_class == H5T_STRING && n == 1) return h5::read_string_attribute(object, name, context);
  if ((type_class == H5T_INTEGER || type_class == H5T_FLOAT) && n >= 1) {
    std::string text;
    if (type_class == H5T_INTEGER && H5Tget_sign(type.get()) == H5T_SGN_NONE) {
      std::vector<unsigned long long> v(static_cast<std::size_t>(n));
      h5::check(H5Aread(attribute.get(), H5T_NATIVE_ULLONG, v.data()), context);
      for (std::size_t i = 0; i < v.size(); ++i) text += (i ? ", " : "") + std::to_string(v[i]);
    } else if (type_class == H5T_INTEGER) {
      std::vector<long long> v(static_cast<std::size_t>(n));
      h5::check(H5Aread(attribute.get(), H5T_NATIVE_LLONG, v.data()), context);
      for (std::size_t i = 0; i < v.size(); ++i) text += (i ? ", " : "") + std::to_string(v[i]);
    } else {
      std::vector<double> v(static_cast<std::size_t>(n));
      h5::check(H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, v.data()), context);
      for (std::size_t i = 0; i < v.size(); ++i) text += (i ? ", " : "") + format_double(v[i]);
    }
    return text;
  }
  return "<attribute of HDF5 class " + std::to_string(static_cast<int>(type_class)) + ", " +
         std::to_string(n) + " elements>";
}

std::map<std::string, std::string> root_attributes(const OpenTrace& t) {
  const std::string context = "trace " + quoted(t.name);
  std::vector<std::string> names;
  hsize_t index = 0;
  h5::check(H5Aiterate2(t.file.get(), H5_INDEX_NAME, H5_ITER_INC, &index, collect_attribute,
                        &names),
            context + ": cannot list the root attributes");
  std::map<std::string, std::string> out;
  for (const std::string& name : names) out[name] = attribute_text(t.file.get(), name, context);
  return out;
}

std::int64_t int_attribute(const OpenTrace& t, const std::string& name) {
  return h5::read_int_attribute(t.file.get(), name, "trace " + quoted(t.name));
}

// ---- structure ------------------------------------------------------------------------------

herr_t collect_link(hid_t, const char* name, const H5L_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->push_back(name);
  return 0;
}

H5I_type_t object_type(hid_t loc, const std::string& path, const std::string& context) {
  h5::Handle object = h5::checked(H5Oopen(loc, path.c_str(), H5P_DEFAULT), H5Oclose,
                                  context + ": cannot open " + quoted(path));
  return H5Iget_type(object.get());
}

bool is_table_dataset(hid_t loc, const std::string& path, const std::string& context) {
  h5::Handle d = h5::checked(H5Dopen2(loc, path.c_str(), H5P_DEFAULT), H5Dclose,
                             context + ": cannot open " + quoted(path));
  return !h5::member_names(d.get(), context).empty();
}

// Tables at the top of the file, by name: compound datasets (schema 3: one dataset per loop,
// one member per column) or groups of datasets (schema 2 and before).
std::vector<std::string> top_groups(const OpenTrace& t) {
  const std::string context = "trace " + quoted(t.name);
  std::vector<std::string> links, groups;
  hsize_t index = 0;
  h5::check(H5Literate(t.file.get(), H5_INDEX_NAME, H5_ITER_INC, &index, collect_link, &links),
            context + ": cannot list the root group");
  for (const std::string& l : links) {
    const H5I_type_t type = object_type(t.file.get(), l, context);
    if (type == H5I_DATASET && is_table_dataset(t.file.get(), l, context)) groups.push_back(l);
    if (type != H5I_GROUP) continue;
    // A group of tables (/devices/<finger>) is compared table by table; any other
    // group (a schema 2 loop: one dataset per column) as one table.
    std::vector<std::string> children, tables;
    h5::Handle g = h5::checked(H5Gopen2(t.file.get(), l.c_str(), H5P_DEFAULT), H5Gclose,
                               context + ": cannot open group " + quoted("/" + l));
    hsize_t child_index = 0;
    h5::check(H5Literate(g.get(), H5_INDEX_NAME, H5_ITER_INC, &child_index, collect_link, &children),
              context + ": cannot list group " + quoted("/" + l));
    for (const std::string& c : children)
      if (object_type(g.get(), c, context) == H5I_DATASET && is_table_dataset(g.get(), c, context))
        tables.push_back(l + "/" + c);
    if (tables.empty()) groups.push_back(l);
    else groups.insert(groups.end(), tables.begin(), tables.end());
  }
  return groups;
}

// Every column of table `group`, by name: the members of a compound table, or the datasets
// below a group (recursively), as paths relative to it.
std::vector<std::string> datasets_below(const OpenTrace& t, const std::string& group) {
  const std::string context = "trace " + quoted(t.name);
  std::vector<std::string> out;
  if (object_type(t.file.get(), group, context) == H5I_DATASET) {
    h5::Handle d = h5::checked(H5Dopen2(t.file.get(), group.c_str(), H5P_DEFAULT), H5Dclose,
                               context + ": cannot open " + quoted("/" + group));
    out = h5::member_names(d.get(), context);
    std::sort(out.begin(), out.end());
    return out;
  }
  h5::Handle g = h5::checked(H5Gopen2(t.file.get(), group.c_str(), H5P_DEFAULT), H5Gclose,
                             context + ": cannot open group " + quoted("/" + group));
  std::vector<std::string> links;
  h5::check(H5Lvisit(g.get(), H5_INDEX_NAME, H5_ITER_INC, collect_link, &links),
            context + ": cannot list group " + quoted("/" + group));
  for (const std::string& l : links)
    if (object_type(g.get(), l, context) == H5I_DATASET) out.push_back(l);
  std::sort(out.begin(), out.end());
  return out;
}

enum class Kind { kFloat, kSigned, kUnsigned };

// The rows of one compound table of one file, a block at a time, in the file's row layout
// converted to native types (no conversion on a little-endian host). All columns of the table
// decode their members from the same block, so a table is read once however many columns it
// has; row(r) may move back and forth within a block, forward across blocks.
struct TableRows {
  std::string file, path;          // for messages
  hid_t dataset = H5I_INVALID_HID; // not owned (the columns' handles keep it open)
  h5::Handle type;                 // native row type
  std::size_t row_bytes = 0;
  std::int64_t rows = 0;           // rows to read (the usable length)
  std::int64_t block = 1;
  std::int64_t start = 0, count = 0;
  std::vector<unsigned char> bytes;

  const unsigned char* row(std::int64_t r) {
    if (r < start || r >= start + count) load(r);
    return bytes.data() + static_cast<std::size_t>(r - start) * row_bytes;
  }

  void load(std::int64_t r) {
    const std::string context = "trace '" + file + "', table '" + path + "'";
    start = r;
    count = std::min(block, rows - r);
    bytes.resize(static_cast<std::size_t>(count) * row_bytes);
    h5::Handle file_space = h5::checked(H5Dget_space(dataset), H5Sclose, context);
    const hsize_t offset[1] = {static_cast<hsize_t>(start)};
    const hsize_t n[1] = {static_cast<hsize_t>(count)};
    h5::check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, offset, nullptr, n, nullptr),
              context);
    h5::Handle mem_space = h5::checked(H5Screate_simple(1, n, nullptr), H5Sclose, context);
    h5::check(H5Dread(dataset, type.get(), mem_space.get(), file_space.get(), H5P_DEFAULT,
                      bytes.data()),
              context + ": cannot read rows " + std::to_string(start) + " to " +
                  std::to_string(start + count - 1));
  }
};

// One open dataset of an aligned table: its kind, rows and width.
struct Column {
  std::string file, path;   // path with a leading '/'
  h5::Handle dataset;       // the column's dataset, or its table's (member not empty)
  std::string member;       // the column's member of a compound table, or "" 
  // A member: where its elements sit in a row of the table's native row type, and how to
  // decode them (class, size in bytes, signed), read from the rows the table shares.
  struct TableRows* table_rows = nullptr;
  std::size_t member_offset = 0;
  H5T_class_t element_class = H5T_FLOAT;
  std::size_t element_size = 8;
  bool element_signed = true;
  Kind kind = Kind::kFloat;
  std::int64_t rows = 0;
  std::size_t width = 1;
  int rank = 1;
  std::string units;
  std::vector<std::string> order;   // the "order" attribute split at commas, if any
};

std::vector<std::string> split_order(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    std::string item = text.substr(start, end - start);
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    out.push_back(item);
    start = end + 1;
  }
  return out;
}

// Opens column `path` of table `group` (path = "/" + group + "/" + name).
Column open_column(const OpenTrace& t, const std::string& group, const std::string& name) {
  Column c;
  c.file = t.name;
  c.path = "/" + group + "/" + name;
  const std::string context = "trace " + quoted(t.name) + ", dataset " + quoted("/" + group + "/" + name);
  h5::Handle type;
  std::string units_key = "units", order_key = "order";
  if (object_type(t.file.get(), group, context) == H5I_DATASET) {
    // A member of a compound table: its attributes are the table's "<member>/<name>".
    c.member = name;
    units_key = name + "/units";
    order_key = name + "/order";
    c.dataset = h5::checked(H5Dopen2(t.file.get(), group.c_str(), H5P_DEFAULT), H5Dclose,
                            context + ": cannot open");
    h5::Member member = h5::member_of(c.dataset.get(), name, context);
    c.member_offset = member.native_offset;   // where it sits in the rows TableRows reads
    c.width = member.width;
    c.rank = member.width > 1 ? 2 : 1;
    type = std::move(member.element);
    h5::Handle space = h5::checked(H5Dget_space(c.dataset.get()), H5Sclose, context);
    if (H5Sget_simple_extent_ndims(space.get()) != 1) fail(context + ": its table is not 1-D");
    hsize_t rows[1] = {0};
    h5::check(H5Sget_simple_extent_dims(space.get(), rows, nullptr), context);
    h5::check_rows(c.dataset.get(), rows[0], context);
    c.rows = static_cast<std::int64_t>(rows[0]);
  } else {
    c.dataset = h5::checked(H5Dopen2(t.file.get(), c.path.c_str(), H5P_DEFAULT), H5Dclose,
                            context + ": cannot open");
    type = h5::checked(H5Dget_type(c.dataset.get()), H5Tclose, context);
    h5::Handle space = h5::checked(H5Dget_space(c.dataset.get()), H5Sclose, context);
    c.rank = H5Sget_simple_extent_ndims(space.get());
    if (c.rank != 1 && c.rank != 2)
      fail(context + ": has " + std::to_string(c.rank) + " dimensions (a trace column has 1 or 2)");
    hsize_t dims[2] = {0, 1};
    h5::check(H5Sget_simple_extent_dims(space.get(), dims, nullptr), context);
    h5::check_rows(c.dataset.get(), dims[0], context);
    if (dims[1] > h5::kMaxColumnWidth) fail(context + ": " + std::to_string(dims[1]) + " values per row (damaged?)");
    c.rows = static_cast<std::int64_t>(dims[0]);
    c.width = c.rank == 2 ? static_cast<std::size_t>(dims[1]) : 1;
  }
  const H5T_class_t type_class = H5Tget_class(type.get());
  c.element_class = type_class;
  c.element_size = H5Tget_size(type.get());
  c.element_signed = type_class == H5T_INTEGER && H5Tget_sign(type.get()) != H5T_SGN_NONE;
  if (type_class == H5T_FLOAT && c.element_size != 4 && c.element_size != 8)
    fail(context + ": floating-point elements of " + std::to_string(c.element_size) + " bytes");
  if (type_class == H5T_INTEGER && c.element_size != 1 && c.element_size != 2 &&
      c.element_size != 4 && c.element_size != 8)
    fail(context + ": integer elements of " + std::to_string(c.element_size) + " bytes");
  if (type_class == H5T_FLOAT) c.kind = Kind::kFloat;
  else if (type_class == H5T_INTEGER)
    c.kind = H5Tget_sign(type.get()) == H5T_SGN_NONE ? Kind::kUnsigned : Kind::kSigned;
  else fail(context + ": elements are neither floating-point numbers nor integers");
  if (h5::has_attribute(c.dataset.get(), units_key, context))
    c.units = attribute_text(c.dataset.get(), units_key, context);
  if (h5::has_attribute(c.dataset.get(), order_key, context))
    c.order = split_order(attribute_text(c.dataset.get(), order_key, context));
  return c;
}

template <typename T>
hid_t memory_type() {
  if constexpr (std::is_same_v<T, double>) return H5T_NATIVE_DOUBLE;
  else if constexpr (std::is_same_v<T, std::int64_t>) return H5T_NATIVE_INT64;
  else return H5T_NATIVE_UINT64;
}

// Reads a column's rows in hyperslabs of `block` rows; row(r) must be asked in increasing r.
template <typename T>
class BlockReader {
 public:
  BlockReader(const Column& c, std::int64_t rows, std::size_t block)
      : c_(c), rows_(rows), block_(static_cast<std::int64_t>(std::max<std::size_t>(block, 1))) {}

  const T* row(std::int64_t r) {
    if (c_.table_rows != nullptr) return decode(c_.table_rows->row(r));
    if (r < start_ || r >= start_ + count_) load(r);
    return buffer_.data() + static_cast<std::size_t>(r - start_) * c_.width;
  }

 private:
  // The member's elements of one native row, converted to T (integers exactly; float64 and
  // uint64 bits as they are).
  const T* decode(const unsigned char* row) {
    buffer_.resize(c_.width);
    const unsigned char* p = row + c_.member_offset;
    for (std::size_t j = 0; j < c_.width; ++j, p += c_.element_size) {
      if (c_.element_class == H5T_FLOAT) {
        if (c_.element_size == 8) { double v; std::memcpy(&v, p, 8); buffer_[j] = static_cast<T>(v); }
        else { float v; std::memcpy(&v, p, 4); buffer_[j] = static_cast<T>(v); }
      } else if (c_.element_signed) {
        std::int64_t v = 0;
        switch (c_.element_size) {
          case 1: { std::int8_t x; std::memcpy(&x, p, 1); v = x; break; }
          case 2: { std::int16_t x; std::memcpy(&x, p, 2); v = x; break; }
          case 4: { std::int32_t x; std::memcpy(&x, p, 4); v = x; break; }
          default: std::memcpy(&v, p, 8); break;
        }
        buffer_[j] = static_cast<T>(v);
      } else {
        std::uint64_t v = 0;
        switch (c_.element_size) {
          case 1: { std::uint8_t x; std::memcpy(&x, p, 1); v = x; break; }
          case 2: { std::uint16_t x; std::memcpy(&x, p, 2); v = x; break; }
          case 4: { std::uint32_t x; std::memcpy(&x, p, 4); v = x; break; }
          default: std::memcpy(&v, p, 8); break;
        }
        buffer_[j] = static_cast<T>(v);
      }
    }
    return buffer_.data();
  }

  // A schema 2 dataset's rows (a compound table's columns decode from its TableRows instead).
  void load(std::int64_t r) {
    const std::string context = "trace " + quoted(c_.file) + ", dataset " + quoted(c_.path);
    start_ = r;
    count_ = std::min(block_, rows_ - r);
    buffer_.resize(static_cast<std::size_t>(count_) * c_.width);
    h5::Handle file_space = h5::checked(H5Dget_space(c_.dataset.get()), H5Sclose, context);
    const hsize_t offset[2] = {static_cast<hsize_t>(start_), 0};
    const hsize_t count[2] = {static_cast<hsize_t>(count_), c_.width};
    h5::check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, offset, nullptr, count,
                                  nullptr),
              context);
    h5::Handle mem_space = h5::checked(H5Screate_simple(c_.rank, count, nullptr), H5Sclose,
                                       context);
    h5::check(H5Dread(c_.dataset.get(), memory_type<T>(), mem_space.get(), file_space.get(),
                      H5P_DEFAULT, buffer_.data()),
              context + ": cannot read rows " + std::to_string(start_) + " to " +
                  std::to_string(start_ + count_ - 1));
  }

  const Column& c_;
  std::int64_t rows_;
  std::int64_t block_;
  std::int64_t start_ = 0, count_ = 0;
  std::vector<T> buffer_;
};

template <typename T>
std::vector<T> read_all(const Column& c, std::int64_t rows, std::size_t block) {
  std::vector<T> out(static_cast<std::size_t>(rows) * c.width);
  BlockReader<T> reader(c, rows, block);
  for (std::int64_t r = 0; r < rows; ++r) {
    const T* p = reader.row(r);
    std::copy(p, p + c.width, out.begin() + static_cast<std::ptrdiff_t>(r * c.width));
  }
  return out;
}

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

// Loop order: the three loops of the schema first, then any other table by name.
int loop_rank(const std::string& g) {
  if (g == "servo") return 0;
  if (g == "haptic") return 1;
  if (g == "physics") return 2;
  return 3;
}

void compare_loop(const OpenTrace& a, const OpenTrace& b, const std::string& group,
                  const CompareOptions& options, std::vector<bool>& rule_used,
                  CompareResult& result) {
  const std::vector<std::string> names_a = datasets_below(a, group);
  const std::vector<std::string> names_b = datasets_below(b, group);
  for (const std::string& n : names_a)
    if (!std::binary_search(names_b.begin(), names_b.end(), n))
      fail("dataset " + quoted("/" + group + "/" + n) + " is in " + quoted(a.name) +
           " but missing in " + quoted(b.name));
  for (const std::string& n : names_b)
    if (!std::binary_search(names_a.begin(), names_a.end(), n))
      fail("dataset " + quoted("/" + group + "/" + n) + " is in " + quoted(b.name) +
           " but missing in " + quoted(a.name));
  for (const char* key : {"tick", "time"})
    if (!std::binary_search(names_a.begin(), names_a.end(), key))
      fail("table " + quoted("/" + group) + " of " + quoted(a.name) + " and " + quoted(b.name) +
           " has no " + quoted(key) + " column, so its rows cannot be aligned");

  std::vector<Column> cols_a, cols_b;
  for (const std::string& n : names_a) {
    cols_a.push_back(open_column(a, group, n));
    cols_b.push_back(open_column(b, group, n));
  }
  // A table's datasets grow together; if they do not (a write cut by a crash), only the rows
  // every dataset holds are compared.
  const auto usable_rows = [&](const std::vector<Column>& cols, const OpenTrace& t) {
    std::int64_t lo = cols.front().rows, hi = cols.front().rows;
    for (const Column& c : cols) lo = std::min(lo, c.rows), hi = std::max(hi, c.rows);
    if (lo != hi)
      result.notes.push_back(quoted(t.name) + ": the datasets of /" + group + " hold " +
                             std::to_string(lo) + " to " + std::to_string(hi) +
                             " rows (a write cut short?); the first " + std::to_string(lo) +
                             " are compared");
    return lo;
  };
  const std::int64_t rows_a = usable_rows(cols_a, a), rows_b = usable_rows(cols_b, b);

  const auto index_of = [&](const char* key) {
    return static_cast<std::size_t>(
        std::lower_bound(names_a.begin(), names_a.end(), key) - names_a.begin());
  };
  const std::size_t tick_i = index_of("tick"), time_i = index_of("time");
  for (const Column* c : {&cols_a[tick_i], &cols_b[tick_i]})
    if (c->kind == Kind::kFloat || c->width != 1)
      fail("trace " + quoted(c->file) + ", dataset " + quoted(c->path) +
           ": a tick column holds one integer per row");
  // A compound table is read a block of whole rows at a time, shared by its columns, and
  // compared block by block (every column of a block, then the next block), so each row of
  // the file is read once. A block is at most 4 MiB of rows.
  std::optional<TableRows> table_a, table_b;
  std::int64_t step = static_cast<std::int64_t>(std::max<std::size_t>(options.block_rows, 1));
  if (!cols_a[tick_i].member.empty() && !cols_b[tick_i].member.empty()) {
    const auto share = [&](std::optional<TableRows>& t, std::vector<Column>& cols, const OpenTrace& o,
                           std::int64_t rows) {
      t.emplace();
      t->file = o.name;
      t->path = "/" + group;
      t->dataset = cols[tick_i].dataset.get();
      const std::string context = "trace " + quoted(o.name) + ", table " + quoted("/" + group);
      h5::Handle file_type = h5::checked(H5Dget_type(t->dataset), H5Tclose, context);
      t->type = h5::checked(H5Tget_native_type(file_type.get(), H5T_DIR_ASCEND), H5Tclose, context);
      t->row_bytes = H5Tget_size(t->type.get());
      t->rows = rows;
      t->block = std::max<std::int64_t>(1, std::min<std::int64_t>(
                                               step, static_cast<std::int64_t>((4u << 20) / std::max<std::size_t>(t->row_bytes, 1))));
      for (Column& c : cols) c.table_rows = &*t;
    };
    share(table_a, cols_a, a, rows_a);
    share(table_b, cols_b, b, rows_b);
    step = std::min(table_a->block, table_b->block);
  }

  const std::vector<std::int64_t> ticks_a = read_all<std::int64_t>(cols_a[tick_i], rows_a, options.block_rows);
  const std::vector<std::int64_t> ticks_b = read_all<std::int64_t>(cols_b[tick_i], rows_b, options.block_rows);
  for (const auto* t : {&ticks_a, &ticks_b})
    for (std::size_t r = 1; r < t->size(); ++r)
      if ((*t)[r] <= (*t)[r - 1])
        fail("trace " + quoted(t == &ticks_a ? a.name : b.name) + ", dataset " +
             quoted("/" + group + "/tick") + ": ticks do not increase at row " +
             std::to_string(r) + " (" + std::to_string((*t)[r - 1]) + " then " +
             std::to_string((*t)[r]) + ")");
  const std::vector<double> times_a = read_all<double>(cols_a[time_i], rows_a, options.block_rows);

  LoopAlignment loop;
  loop.loop = group;
  loop.rows_a = rows_a;
  loop.rows_b = rows_b;
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
  result.loops.push_back(loop);

  using Readers = std::variant<std::pair<BlockReader<double>, BlockReader<double>>,
                               std::pair<BlockReader<std::int64_t>, BlockReader<std::int64_t>>,
                               std::pair<BlockReader<std::uint64_t>, BlockReader<std::uint64_t>>>;
  std::vector<DatasetResult> found;
  std::vector<Readers> readers;
  std::vector<std::size_t> widths;
  for (std::size_t k = 0; k < names_a.size(); ++k) {
    if (k == tick_i) continue;   // the key the rows were aligned by
    const Column& ca = cols_a[k];
    const Column& cb = cols_b[k];
    if (ca.rank != cb.rank || ca.width != cb.width)
      fail("dataset " + quoted(ca.path) + " has different shapes: " + shape_text(ca) + " in " +
           quoted(a.name) + ", " + shape_text(cb) + " in " + quoted(b.name));
    if (ca.kind != cb.kind)
      fail(std::string("dataset ") + quoted(ca.path) + " holds " + kind_text(ca.kind) + "s in " +
           quoted(a.name) + " but " + kind_text(cb.kind) + "s in " + quoted(b.name));
    DatasetResult d;
    d.path = group + "/" + names_a[k];
    describe(d, ca);
    d.integer = ca.kind != Kind::kFloat;
    d.tolerance = options.tolerance;
    for (std::size_t r = 0; r < options.rules.size(); ++r) {
      if (tolerance_pattern_matches(options.rules[r].pattern, d.path)) {
        d.tolerance = options.rules[r].tolerance;
        d.rule = options.rules[r].pattern;
        rule_used[r] = true;
      }
    }
    if (options.bitwise) d.tolerance = Tolerance{};
    const std::size_t block = static_cast<std::size_t>(step);
    switch (ca.kind) {
      case Kind::kFloat:
        readers.emplace_back(std::in_place_index<0>, BlockReader<double>(ca, rows_a, block),
                             BlockReader<double>(cb, rows_b, block));
        break;
      case Kind::kSigned:
        readers.emplace_back(std::in_place_index<1>, BlockReader<std::int64_t>(ca, rows_a, block),
                             BlockReader<std::int64_t>(cb, rows_b, block));
        break;
      case Kind::kUnsigned:
        readers.emplace_back(std::in_place_index<2>, BlockReader<std::uint64_t>(ca, rows_a, block),
                             BlockReader<std::uint64_t>(cb, rows_b, block));
        break;
    }
    widths.push_back(ca.width);
    found.push_back(std::move(d));
  }
  // A range of aligned rows whose rows lie in one block of each file (a decimated or cut trace
  // skips rows: its range ends where its rows would leave the block).
  const std::int64_t block_a = table_a ? table_a->block : step, block_b = table_b ? table_b->block : step;
  for (std::size_t k0 = 0, k1 = 0; k0 < al.tick.size(); k0 = k1) {
    k1 = k0 + 1;
    while (k1 < al.tick.size() && al.row_a[k1] - al.row_a[k0] < block_a &&
           al.row_b[k1] - al.row_b[k0] < block_b)
      ++k1;
    for (std::size_t c = 0; c < found.size(); ++c) {
      std::visit([&](auto& pair) { compare_range(pair.first, pair.second, widths[c], k0, k1, al, options, found[c]); },
                 readers[c]);
    }
  }
  for (DatasetResult& d : found) result.datasets.push_back(std::move(d));
}

CompareResult compare_impl(const std::string& file_a, const std::string& file_b,
                           const CompareOptions& options) {
  if (!(options.tolerance.atol >= 0) || !(options.tolerance.rtol >= 0))
    fail("tolerances must be >= 0");
  for (const ToleranceRule& r : options.rules)
    if (!(r.tolerance.atol >= 0) || !(r.tolerance.rtol >= 0) || r.pattern.empty())
      fail("tolerance rule " + quoted(r.pattern) + ": needs a pattern and tolerances >= 0");

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

  const auto attrs_a = root_attributes(a);
  const auto attrs_b = root_attributes(b);
  for (const auto* t : {&a, &b}) {
    const auto& attrs = t == &a ? attrs_a : attrs_b;
    if (!attrs.count("schema_version"))
      fail("trace " + quoted(t->name) +
           " is not a graspsim trace (it has no root attribute 'schema_version')");
  }
  result.schema_version = int_attribute(a, "schema_version");
  const std::int64_t version_b = int_attribute(b, "schema_version");
  if (result.schema_version != version_b)
    fail("the traces have different schema versions: " + quoted(a.name) + " has " +
         std::to_string(result.schema_version) + ", " + quoted(b.name) + " has " +
         std::to_string(version_b));

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

  // Root attributes other than the ones checked above.
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

  std::vector<std::string> groups_a = top_groups(a), groups_b = top_groups(b);
  for (const std::string& g : groups_a)
    if (std::find(groups_b.begin(), groups_b.end(), g) == groups_b.end())
      fail("group " + quoted("/" + g) + " is in " + quoted(a.name) + " but missing in " +
           quoted(b.name));
  for (const std::string& g : groups_b)
    if (std::find(groups_a.begin(), groups_a.end(), g) == groups_a.end())
      fail("group " + quoted("/" + g) + " is in " + quoted(b.name) + " but missing in " +
           quoted(a.name));
  std::stable_sort(groups_a.begin(), groups_a.end(), [](const std::string& x, const std::string& y) {
    return loop_rank(x) < loop_rank(y);
  });
  for (const char* required : {"servo", "haptic", "physics"})
    if (std::find(groups_a.begin(), groups_a.end(), required) == groups_a.end())
      fail("trace " + quoted(a.name) + " has no group " + quoted(std::string("/") + required) +
           " (not a graspsim trace?)");

  std::vector<bool> rule_used(options.rules.size(), false);
  for (const std::string& g : groups_a) {
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
