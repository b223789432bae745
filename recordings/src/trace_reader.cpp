// Read helpers for traces: open read-only, read one thing, close; HDF5 errors become TraceError.
#include "graspsim/recordings/trace_reader.hpp"

#include <algorithm>

#include "h5.hpp"
#include "h5_checks.hpp"

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


// Where a logical path lives: a whole dataset (member empty), or member `member` of the table
// dataset `table` (schema 3: "/physics/objects/box/position" is member "objects/box/position"
// of dataset "/physics"), or an intermediate name of members ("/physics/objects": a "group").
struct Location {
  h5::Handle object;         // the dataset or group at the path, or the table dataset
  std::string member;        // member name, or member prefix for a group of members
  bool member_prefix = false;   // `member` names a group of members, not one
};

// Resolves `path` one link at a time; the first dataset on the way that is compound holds the
// rest of the path as a member (or a prefix of members). nullopt-like: object invalid.
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
      // The rest names a member of this table, or a prefix of member names.
      std::string rest = path.substr(next);
      while (!rest.empty() && rest.back() == '/') rest.pop_back();
      // An exact member wins; otherwise a prefix of members is a "group" of them.
      bool exact = false, below = false;
      for (const std::string& m : h5::member_names(object.get(), context)) {
        exact = exact || m == rest;
        below = below || m.rfind(rest + "/", 0) == 0;
      }
      if (exact || below) {
        out.object = std::move(object);
        out.member = rest;
        out.member_prefix = !exact;
      }
      return out;   // a prefix of members, or nothing (object invalid)
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

// Reads one member of a compound table into `out` (memory type `element`, width values a row):
// a memory compound type with only that member makes HDF5 pick it out of every row.
void read_member(hid_t dataset, const std::string& member, hid_t element, std::size_t width,
                 void* out, const std::string& context) {
  const std::size_t element_size = H5Tget_size(element);
  h5::Handle field;
  if (width > 1) {
    const hsize_t dims[1] = {static_cast<hsize_t>(width)};
    field = h5::checked(H5Tarray_create2(element, 1, dims), H5Tclose, context);
  } else {
    field = h5::checked(H5Tcopy(element), H5Tclose, context);
  }
  h5::Handle type = h5::checked(H5Tcreate(H5T_COMPOUND, element_size * width), H5Tclose, context);
  h5::check(H5Tinsert(type.get(), member.c_str(), 0, field.get()), context);
  h5::check(H5Dread(dataset, type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out),
            context + ": cannot read");
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
  h5::Handle space = h5::checked(H5Dget_space(where.object.get()), H5Sclose, context);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) throw TraceError(context + ": " + h5::last_error());
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  if (rank > 0) h5::check(H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr), context);

  // Its extent, before anything is allocated for it: a damaged one may claim 2^64 rows.
  if (rank > 0) h5::check_rows(where.object.get(), dims[0], context);
  Dataset out;
  if (!where.member.empty()) {
    // A column of a table: shape (n,) or (n, width).
    if (rank != 1) throw TraceError(context + ": its table is not 1-D");
    const h5::Member m = h5::member_of(where.object.get(), where.member, context);
    out.dtype = dtype_of(m.element.get(), context);
    const std::size_t rows = static_cast<std::size_t>(dims[0]);
    out.shape.push_back(rows);
    if (m.width > 1) out.shape.push_back(m.width);
    const std::size_t count = rows * m.width;
    out.values.resize(count);
    if (count > 0 && out.dtype == DType::kUInt64) {
      out.bits.resize(count);
      read_member(where.object.get(), where.member, H5T_NATIVE_UINT64, m.width,
                          out.bits.data(), context);
      for (std::size_t i = 0; i < count; ++i) out.values[i] = static_cast<double>(out.bits[i]);
    } else if (count > 0) {
      read_member(where.object.get(), where.member, H5T_NATIVE_DOUBLE, m.width,
                          out.values.data(), context);
    }
    const std::string units = where.member + "/units";
    if (h5::has_attribute(where.object.get(), units, context)) {
      out.units = h5::read_string_attribute(where.object.get(), units, context);
    }
    return out;
  }

  h5::Handle type = h5::checked(H5Dget_type(where.object.get()), H5Tclose, context);
  out.dtype = dtype_of(type.get(), context);
  std::size_t count = 1;
  for (hsize_t d : dims) {
    out.shape.push_back(static_cast<std::size_t>(d));
    count *= static_cast<std::size_t>(d);
  }
  out.values.resize(count);
  if (count > 0 && out.dtype == DType::kUInt64) {
    out.bits.resize(count);
    h5::check(H5Dread(where.object.get(), H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                      out.bits.data()),
              context + ": cannot read");
    for (std::size_t i = 0; i < count; ++i) out.values[i] = static_cast<double>(out.bits[i]);
  } else if (count > 0) {
    h5::check(H5Dread(where.object.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                      out.values.data()),
              context + ": cannot read");
  }
  if (h5::has_attribute(where.object.get(), "units", context)) {
    out.units = h5::read_string_attribute(where.object.get(), "units", context);
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

namespace {

struct Visit {
  std::vector<std::string> paths;
  std::string context;
  std::string error;   // the first failure (an exception may not cross the HDF5 C frames)
};

herr_t visit_object(hid_t file, const char* name, const H5O_info_t* info, void* data) {
  auto* visit = static_cast<Visit*>(data);
  if (info->type != H5O_TYPE_DATASET) return 0;
  const std::string path = std::string("/") + name;
  try {
    h5::Handle d = h5::checked(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose, visit->context + ": cannot open " + quoted(path));
    const std::vector<std::string> members = h5::member_names(d.get(), visit->context);
    if (members.empty()) visit->paths.push_back(path);
    for (const std::string& m : members) visit->paths.push_back(path + "/" + m);
  } catch (const TraceError& e) {
    visit->error = e.what();
    return -1;
  }
  return 0;
}

}  // namespace

std::vector<std::string> list_datasets(const std::string& file) {
  h5::Lock lock;
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  Visit visit{{}, "trace " + quoted(file), ""};
  const herr_t status = H5Ovisit2(handle.get(), H5_INDEX_NAME, H5_ITER_INC, visit_object, &visit, H5O_INFO_BASIC);
  if (!visit.error.empty()) throw TraceError(visit.error);
  h5::check(status, visit.context + ": cannot list its datasets");
  std::sort(visit.paths.begin(), visit.paths.end());
  return visit.paths;
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
  std::string key = where.member.empty() ? name : where.member + "/" + name;
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
