// Read helpers for traces: open read-only, read one thing, close; HDF5 errors become TraceError.
#include "graspsim/recordings/trace_reader.hpp"

#include <algorithm>
#include <cstring>
#include <map>

#include "h5.hpp"
#include "h5_checks.hpp"
#include "table_layout.hpp"

namespace graspsim::recordings {
namespace {

std::string quoted(const std::string& text) { return "'" + text + "'"; }

h5::Handle open_file(const std::string& file) {
  return h5::open_read_only(file, "cannot open trace " + quoted(file)).file;
}

DType dtype_of(hid_t type, const std::string& context) {
  const H5T_class_t type_class = H5Tget_class(type);
  const std::size_t size = H5Tget_size(type);
  if (type_class == H5T_FLOAT && size == 8) return DType::kFloat64;
  if (type_class == H5T_INTEGER && H5Tget_sign(type) == H5T_SGN_2) {
    if (size == 8) return DType::kInt64;
    if (size == 4) return DType::kInt32;
    if (size == 1) return DType::kInt8;
  }
  if (type_class == H5T_INTEGER && H5Tget_sign(type) == H5T_SGN_NONE && size == 8) {
    return DType::kUInt64;
  }
  throw TraceError(context + ": element type is not float64, int64, int32, int8 or uint64");
}


// Where a logical path lives: a whole dataset (member empty), or column `member` of the table
// dataset `table` ("/physics/objects/box/position" is column "objects/box/position" of dataset
// "/physics", a member of its rows in schema 3, a field of entity "box" of member "objects" in
// schema 4: table_layout.hpp), or an intermediate name of columns ("/physics/objects": a "group").
struct Location {
  h5::Handle object;         // the dataset or group at the path, or the table dataset
  std::string member;        // column name, or column prefix for a group of columns
  bool member_prefix = false;   // `member` names a group of columns, not one
  bool own_member = false;   // `member` is a member of its own, not a field of a group's entity
  std::string attributes;    // a column's: the prefix of its attributes' names on the table
};

// Resolves `path` one link at a time; the first dataset on the way that is a table holds the
// rest of the path as a column (or a prefix of columns). nullopt-like: object invalid.
Location locate(hid_t file, const std::string& path, const std::string& context) {
  Location out;
  std::size_t start = path.find_first_not_of('/');
  if (start == std::string::npos) {
    out.object = h5::checked(H5Oopen(file, "/", H5P_DEFAULT), H5Oclose, context);
    return out;
  }
  std::string prefix;
  while (start < path.size()) {
    std::size_t end = path.find('/', start);
    if (end == std::string::npos) end = path.size();
    prefix += '/';
    prefix.append(path, start, end - start);
    const htri_t found = H5Lexists(file, prefix.c_str(), H5P_DEFAULT);
    h5::check(found, context + ": cannot look up " + quoted(prefix));
    if (found == 0) return Location{};
    const htri_t resolves = H5Oexists_by_name(file, prefix.c_str(), H5P_DEFAULT);
    h5::check(resolves, context + ": cannot look up " + quoted(prefix));
    if (resolves == 0) return Location{};   // dangling soft link
    const std::size_t next = path.find_first_not_of('/', end);
    h5::Handle object = h5::checked(H5Oopen(file, prefix.c_str(), H5P_DEFAULT), H5Oclose,
                                    context + ": cannot open " + quoted(prefix));
    if (next != std::string::npos && H5Iget_type(object.get()) == H5I_DATASET) {
      // The rest names a column of this table, or a prefix of column names.
      std::string rest = path.substr(next);
      while (!rest.empty() && rest.back() == '/') rest.pop_back();
      if (!h5::is_table(object.get(), context)) return out;
      // A member of its own ("tick") is found without reading any group's names.
      if (h5::table_layout(object.get(), context + ", table " + quoted(prefix), false).find(rest) >= 0) {
        out.object = std::move(object);
        out.member = out.attributes = rest;
        out.own_member = true;
        return out;
      }
      const h5::TableLayout layout = h5::table_layout(object.get(), context + ", table " + quoted(prefix));
      // An exact column wins; otherwise a prefix of columns is a "group" of them.
      const std::ptrdiff_t exact = layout.find(rest);
      const bool below = std::any_of(layout.columns.begin(), layout.columns.end(), [&](const h5::StoredColumn& c) {
        return c.name.rfind(rest + "/", 0) == 0;
      });
      if (exact >= 0 || below) {
        out.object = std::move(object);
        out.member = rest;
        out.member_prefix = exact < 0;
        out.attributes = exact >= 0 ? layout.columns[static_cast<std::size_t>(exact)].attributes : rest;
      }
      return out;   // a prefix of columns, or nothing (object invalid)
    }
    if (next == std::string::npos) {
      out.object = std::move(object);
      return out;
    }
    start = next;
  }
  return out;
}

}  // namespace

namespace {

// The DType of a table's column, or a TraceError naming it.
DType dtype_of(const h5::StoredColumn& c, const std::string& context) {
  if (c.element_class == H5T_FLOAT && c.element_size == 8) return DType::kFloat64;
  if (c.element_class == H5T_INTEGER && c.element_signed) {
    if (c.element_size == 8) return DType::kInt64;
    if (c.element_size == 4) return DType::kInt32;
    if (c.element_size == 1) return DType::kInt8;
  }
  if (c.element_class == H5T_INTEGER && !c.element_signed && c.element_size == 8) return DType::kUInt64;
  throw TraceError(context + ", column " + quoted(c.name) + ": element type is not float64, int64, int32, int8 or uint64");
}

// One stored value of a column (dtype_of checked its type) as a double: integers exact to 2^53.
double value_at(const unsigned char* p, DType dtype) {
  switch (dtype) {
    case DType::kFloat64: { double v; std::memcpy(&v, p, 8); return v; }
    case DType::kInt64: { std::int64_t v; std::memcpy(&v, p, 8); return static_cast<double>(v); }
    case DType::kInt32: { std::int32_t v; std::memcpy(&v, p, 4); return static_cast<double>(v); }
    case DType::kInt8: { std::int8_t v; std::memcpy(&v, p, 1); return static_cast<double>(v); }
    case DType::kUInt64: { std::uint64_t v; std::memcpy(&v, p, 8); return static_cast<double>(v); }
  }
  return 0.0;
}

// Columns `wanted` (indices into `layout`) of table `dataset`, every row: the table is read a
// block of whole rows at a time (at most 4 MiB), each block decoded into every wanted column.
std::vector<Dataset> read_columns(hid_t dataset, const h5::TableLayout& layout, const std::vector<std::size_t>& wanted,
                                  const std::string& context) {
  h5::Handle space = h5::checked(H5Dget_space(dataset), H5Sclose, context);
  if (H5Sget_simple_extent_ndims(space.get()) != 1) throw TraceError(context + ": a table is 1-D");
  hsize_t dims[1] = {0};
  h5::check(H5Sget_simple_extent_dims(space.get(), dims, nullptr), context);
  // Its extent, before anything is allocated for it: a damaged one may claim 2^64 rows.
  h5::check_rows(dataset, dims[0], context);
  const std::size_t rows = static_cast<std::size_t>(dims[0]);
  std::vector<Dataset> out(wanted.size());
  std::map<std::string, std::string> units;   // by attribute prefix: entity groups share them
  for (std::size_t k = 0; k < wanted.size(); ++k) {
    const h5::StoredColumn& c = layout.columns[wanted[k]];
    Dataset& d = out[k];
    d.dtype = dtype_of(c, context);
    d.shape.push_back(rows);
    if (c.width > 1) d.shape.push_back(c.width);
    d.values.resize(rows * c.width);
    if (d.dtype == DType::kUInt64) d.bits.resize(rows * c.width);
    const auto known = units.find(c.attributes);
    if (known != units.end()) {
      d.units = known->second;
    } else {
      const std::string key = c.attributes + "/units";
      d.units = h5::has_attribute(dataset, key, context) ? h5::read_string_attribute(dataset, key, context) : "";
      units.emplace(c.attributes, d.units);
    }
  }
  if (rows == 0 || wanted.empty()) return out;
  const std::size_t block = std::clamp<std::size_t>((4u << 20) / std::max<std::size_t>(layout.row_bytes, 1), 1, rows);
  std::vector<unsigned char> buffer(block * layout.row_bytes);
  for (std::size_t start = 0; start < rows; start += block) {
    const hsize_t offset[1] = {start}, count[1] = {std::min(block, rows - start)};
    h5::check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, offset, nullptr, count, nullptr), context);
    h5::Handle memory = h5::checked(H5Screate_simple(1, count, nullptr), H5Sclose, context);
    h5::check(H5Dread(dataset, layout.native.get(), memory.get(), space.get(), H5P_DEFAULT, buffer.data()),
              context + ": cannot read rows " + std::to_string(start) + " to " + std::to_string(start + count[0] - 1));
    for (std::size_t k = 0; k < wanted.size(); ++k) {
      const h5::StoredColumn& c = layout.columns[wanted[k]];
      Dataset& d = out[k];
      for (std::size_t r = 0; r < count[0]; ++r) {
        const unsigned char* p = buffer.data() + r * layout.row_bytes + c.offset;
        const std::size_t at = (start + r) * c.width;
        for (std::size_t j = 0; j < c.width; ++j, p += c.element_size) {
          d.values[at + j] = value_at(p, d.dtype);
          if (d.dtype == DType::kUInt64) std::memcpy(&d.bits[at + j], p, 8);
        }
      }
    }
  }
  return out;
}

// A dataset that is not a table (schema 2's columns, or any other), whole.
Dataset read_plain(hid_t dataset, const std::string& context) {
  h5::Handle space = h5::checked(H5Dget_space(dataset), H5Sclose, context);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) throw TraceError(context + ": " + h5::last_error());
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  if (rank > 0) h5::check(H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr), context);
  // Its extent, before anything is allocated for it: a damaged one may claim 2^64 rows.
  if (rank > 0) h5::check_rows(dataset, dims[0], context);
  Dataset out;
  h5::Handle type = h5::checked(H5Dget_type(dataset), H5Tclose, context);
  out.dtype = dtype_of(type.get(), context);
  std::size_t count = 1;
  for (hsize_t d : dims) {
    out.shape.push_back(static_cast<std::size_t>(d));
    count *= static_cast<std::size_t>(d);
  }
  out.values.resize(count);
  if (count > 0 && out.dtype == DType::kUInt64) {
    out.bits.resize(count);
    h5::check(H5Dread(dataset, H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.bits.data()),
              context + ": cannot read");
    for (std::size_t i = 0; i < count; ++i) out.values[i] = static_cast<double>(out.bits[i]);
  } else if (count > 0) {
    h5::check(H5Dread(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.values.data()),
              context + ": cannot read");
  }
  if (h5::has_attribute(dataset, "units", context)) out.units = h5::read_string_attribute(dataset, "units", context);
  return out;
}

// read_dataset, but for running out of memory (a bound read_dataset turns into a TraceError).
Dataset read_dataset_checked(const std::string& file, const std::string& path) {
  h5::Lock lock;
  h5::Quiet quiet;
  const std::string context = "trace " + quoted(file) + ", dataset " + quoted(path);
  h5::Handle handle = open_file(file);
  Location where = locate(handle.get(), path, "trace " + quoted(file));
  if (!where.object.valid()) throw TraceError("trace " + quoted(file) + ": no object " + quoted(path));
  if (where.member_prefix || H5Iget_type(where.object.get()) != H5I_DATASET) {
    throw TraceError(context + ": not a dataset");
  }
  if (where.member.empty()) return read_plain(where.object.get(), context);
  // A column of a table: shape (n,) or (n, width).
  const h5::TableLayout layout = h5::table_layout(where.object.get(), context, !where.own_member);
  const std::size_t k = static_cast<std::size_t>(layout.find(where.member));
  return std::move(read_columns(where.object.get(), layout, {k}, context).front());
}

// Paths below group `group` ("/servo" of a schema 2 trace) of every dataset, relative to it, sorted.
std::vector<std::string> datasets_in(hid_t group, const std::string& context) {
  std::vector<std::string> names;
  const auto collect = [](hid_t, const char* name, const H5O_info_t* info, void* data) -> herr_t {
    if (info->type == H5O_TYPE_DATASET) static_cast<std::vector<std::string>*>(data)->push_back(name);
    return 0;
  };
  h5::check(H5Ovisit2(group, H5_INDEX_NAME, H5_ITER_INC, collect, &names, H5O_INFO_BASIC),
            context + ": cannot list its datasets");
  names.erase(std::remove(names.begin(), names.end(), "."), names.end());
  std::sort(names.begin(), names.end());
  return names;
}

Table read_table_checked(const std::string& file, const std::string& path, const std::vector<std::string>& names) {
  h5::Lock lock;
  h5::Quiet quiet;
  const std::string context = "trace " + quoted(file) + ", table " + quoted(path);
  h5::Handle handle = open_file(file);
  Location where = locate(handle.get(), path, "trace " + quoted(file));
  if (!where.object.valid()) throw TraceError("trace " + quoted(file) + ": no object " + quoted(path));
  const bool dataset = H5Iget_type(where.object.get()) == H5I_DATASET;
  if (!where.member.empty() || (dataset && !h5::is_table(where.object.get(), context)))
    throw TraceError(context + ": not a table");
  Table out;
  if (dataset) {
    const h5::TableLayout layout = h5::table_layout(where.object.get(), context);
    out.names = names.empty() ? layout.sorted_names() : names;
    std::map<std::string, std::size_t> index;
    for (std::size_t k = 0; k < layout.columns.size(); ++k) index.emplace(layout.columns[k].name, k);
    std::vector<std::size_t> wanted;
    for (const std::string& n : out.names) {
      const auto found = index.find(n);
      if (found == index.end()) throw TraceError(context + ": no column " + quoted(n));
      wanted.push_back(found->second);
    }
    out.columns = read_columns(where.object.get(), layout, wanted, context);
    return out;
  }
  // A schema 2 table: a group of datasets, each read on its own.
  out.names = names.empty() ? datasets_in(where.object.get(), context) : names;
  for (const std::string& n : out.names) {
    const htri_t found = H5Lexists(where.object.get(), n.c_str(), H5P_DEFAULT);
    if (found <= 0) throw TraceError(context + ": no column " + quoted(n));
    h5::Handle d = h5::checked(H5Dopen2(where.object.get(), n.c_str(), H5P_DEFAULT), H5Dclose,
                               context + ": column " + quoted(n) + " is not a dataset");
    out.columns.push_back(read_plain(d.get(), context + ", column " + quoted(n)));
  }
  return out;
}

}  // namespace

Dataset read_dataset(const std::string& file, const std::string& path) {
  try {
    return read_dataset_checked(file, path);
  } catch (const std::bad_alloc&) {
    throw TraceError("trace " + quoted(file) + ", dataset " + quoted(path) + ": not enough memory to read it");
  }
}

const Dataset& Table::column(const std::string& name) const {
  if (sorted.size() == names.size()) {
    const auto at = std::lower_bound(sorted.begin(), sorted.end(), name,
                                     [this](std::size_t k, const std::string& n) { return names[k] < n; });
    if (at != sorted.end() && names[*at] == name) return columns[*at];
  } else {
    for (std::size_t k = 0; k < names.size(); ++k)
      if (names[k] == name) return columns[k];
  }
  throw TraceError("table: no column " + quoted(name) + " was read");
}

Table read_table(const std::string& file, const std::string& table, const std::vector<std::string>& names) {
  try {
    Table out = read_table_checked(file, table, names);
    out.sorted.resize(out.names.size());
    for (std::size_t k = 0; k < out.sorted.size(); ++k) out.sorted[k] = k;
    std::sort(out.sorted.begin(), out.sorted.end(),
              [&out](std::size_t a, std::size_t b) { return out.names[a] < out.names[b]; });
    return out;
  } catch (const std::bad_alloc&) {
    throw TraceError("trace " + quoted(file) + ", table " + quoted(table) + ": not enough memory to read it");
  }
}

namespace {

struct Visit {
  std::vector<std::string> tables, plain;   // paths of the table datasets, and of the others
  std::string context;
  std::string error;   // the first failure (an exception may not cross the HDF5 C frames)
};

herr_t visit_object(hid_t file, const char* name, const H5O_info_t* info, void* data) {
  auto* visit = static_cast<Visit*>(data);
  if (info->type != H5O_TYPE_DATASET) return 0;
  const std::string path = std::string("/") + name;
  try {
    h5::Handle d = h5::checked(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose, visit->context + ": cannot open " + quoted(path));
    (h5::is_table(d.get(), visit->context) ? visit->tables : visit->plain).push_back(path);
  } catch (const TraceError& e) {
    visit->error = e.what();
    return -1;
  }
  return 0;
}

Visit visit_datasets(hid_t file, const std::string& context) {
  Visit visit{{}, {}, context, ""};
  const herr_t status = H5Ovisit2(file, H5_INDEX_NAME, H5_ITER_INC, visit_object, &visit, H5O_INFO_BASIC);
  if (!visit.error.empty()) throw TraceError(visit.error);
  h5::check(status, context + ": cannot list its datasets");
  return visit;
}

}  // namespace

std::vector<std::string> list_datasets(const std::string& file) {
  h5::Lock lock;
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  const std::string context = "trace " + quoted(file);
  const Visit visit = visit_datasets(handle.get(), context);
  std::vector<std::string> paths = visit.plain;
  for (const std::string& t : visit.tables) {
    h5::Handle d = h5::checked(H5Dopen2(handle.get(), t.c_str(), H5P_DEFAULT), H5Dclose, context + ": cannot open " + quoted(t));
    for (const h5::StoredColumn& c : h5::table_layout(d.get(), context + ", table " + quoted(t)).columns)
      paths.push_back(t + "/" + c.name);
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

std::vector<std::pair<std::string, Dataset>> read_trace(const std::string& file) {
  std::vector<std::string> tables, plain;
  {
    h5::Lock lock;
    h5::Quiet quiet;
    h5::Handle handle = open_file(file);
    Visit visit = visit_datasets(handle.get(), "trace " + quoted(file));
    tables = std::move(visit.tables);
    plain = std::move(visit.plain);
  }
  std::vector<std::pair<std::string, Dataset>> out;
  for (const std::string& t : tables) {
    Table table = read_table(file, t);
    for (std::size_t k = 0; k < table.names.size(); ++k)
      out.emplace_back(t + "/" + table.names[k], std::move(table.columns[k]));
  }
  for (const std::string& p : plain) out.emplace_back(p, read_dataset(file, p));
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  return out;
}

namespace {

// The object holding attribute `name` of `object_path`, and the attribute's name there: a
// column's attributes are attributes "<column>/<name>" of its table.
std::pair<h5::Handle, std::string> attribute_of(hid_t file, const std::string& file_name,
                                                const std::string& object_path,
                                                const std::string& name) {
  const std::string context = "trace " + quoted(file_name);
  Location where = locate(file, object_path, context);
  if (!where.object.valid()) throw TraceError(context + ": no object " + quoted(object_path));
  std::string key = where.member.empty() ? name : where.attributes + "/" + name;
  return {std::move(where.object), std::move(key)};
}

}  // namespace

std::string read_string_attribute(const std::string& file, const std::string& object_path,
                                  const std::string& name) {
  h5::Lock lock;
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  auto [object, key] = attribute_of(handle.get(), file, object_path, name);
  return h5::read_string_attribute(object.get(), key,
                                   "trace " + quoted(file) + ", object " + quoted(object_path));
}

std::int64_t read_int_attribute(const std::string& file, const std::string& object_path,
                                const std::string& name) {
  h5::Lock lock;
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  auto [object, key] = attribute_of(handle.get(), file, object_path, name);
  return h5::read_int_attribute(object.get(), key,
                                "trace " + quoted(file) + ", object " + quoted(object_path));
}

double read_double_attribute(const std::string& file, const std::string& object_path,
                             const std::string& name) {
  h5::Lock lock;
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  auto [object, key] = attribute_of(handle.get(), file, object_path, name);
  return h5::read_double_attribute(object.get(), key,
                                   "trace " + quoted(file) + ", object " + quoted(object_path));
}

bool has_attribute(const std::string& file, const std::string& object_path,
                   const std::string& name) {
  h5::Lock lock;
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  auto [object, key] = attribute_of(handle.get(), file, object_path, name);
  return h5::has_attribute(object.get(), key,
                           "trace " + quoted(file) + ", object " + quoted(object_path));
}

bool has_object(const std::string& file, const std::string& path) {
  h5::Lock lock;
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  return locate(handle.get(), path, "trace " + quoted(file)).object.valid();
}

}  // namespace graspsim::recordings
