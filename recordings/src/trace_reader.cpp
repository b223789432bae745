// Read helpers for traces: open read-only, read one thing, close; HDF5 errors become TraceError.
#include "graspsim/recordings/trace_reader.hpp"

#include "h5.hpp"

namespace graspsim::recordings {
namespace {

std::string quoted(const std::string& text) { return "'" + text + "'"; }

h5::Handle open_file(const std::string& file) {
  const std::string where = "cannot open trace " + quoted(file);
  const htri_t is_hdf5 = H5Fis_hdf5(file.c_str());
  if (is_hdf5 < 0) throw TraceError(where + ": " + h5::last_error());
  if (is_hdf5 == 0) throw TraceError(where + ": not an HDF5 file");
  const hid_t plain = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (plain >= 0) return h5::Handle(plain, H5Fclose);
  // A trace still being written, or cut by a crash, is marked as open for SWMR writing: it
  // opens as a SWMR reader (recordings/README.md, "Crash safety").
  const std::string reason = h5::last_error();
  const hid_t swmr = H5Fopen(file.c_str(), H5F_ACC_RDONLY | H5F_ACC_SWMR_READ, H5P_DEFAULT);
  if (swmr >= 0) return h5::Handle(swmr, H5Fclose);
  throw TraceError(where + ": " + reason);
}

// Follows `path` one link at a time, so a missing intermediate group gives false, not an error.
bool exists(hid_t file, const std::string& path, const std::string& context) {
  std::size_t start = path.find_first_not_of('/');
  if (start == std::string::npos) return true;   // "/" or ""
  std::string prefix;
  while (start < path.size()) {
    std::size_t end = path.find('/', start);
    if (end == std::string::npos) end = path.size();
    prefix += '/';
    prefix.append(path, start, end - start);
    const htri_t found = H5Lexists(file, prefix.c_str(), H5P_DEFAULT);
    h5::check(found, context + ": cannot look up " + quoted(prefix));
    if (found == 0) return false;
    const htri_t resolves = H5Oexists_by_name(file, prefix.c_str(), H5P_DEFAULT);
    h5::check(resolves, context + ": cannot look up " + quoted(prefix));
    if (resolves == 0) return false;   // dangling soft link
    start = path.find_first_not_of('/', end);
    if (start == std::string::npos) break;
  }
  return true;
}

h5::Handle open_object(hid_t file, const std::string& file_name, const std::string& path) {
  const std::string context = "trace " + quoted(file_name);
  if (!exists(file, path, context)) throw TraceError(context + ": no object " + quoted(path));
  return h5::checked(H5Oopen(file, path.c_str(), H5P_DEFAULT), H5Oclose,
                     context + ": cannot open " + quoted(path));
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

}  // namespace

Dataset read_dataset(const std::string& file, const std::string& path) {
  h5::Quiet quiet;
  const std::string context = "trace " + quoted(file) + ", dataset " + quoted(path);
  h5::Handle handle = open_file(file);
  h5::Handle object = open_object(handle.get(), file, path);
  if (H5Iget_type(object.get()) != H5I_DATASET) throw TraceError(context + ": not a dataset");

  Dataset out;
  h5::Handle type = h5::checked(H5Dget_type(object.get()), H5Tclose, context);
  out.dtype = dtype_of(type.get(), context);
  h5::Handle space = h5::checked(H5Dget_space(object.get()), H5Sclose, context);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) throw TraceError(context + ": " + h5::last_error());
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  if (rank > 0) h5::check(H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr), context);
  std::size_t count = 1;
  for (hsize_t d : dims) {
    out.shape.push_back(static_cast<std::size_t>(d));
    count *= static_cast<std::size_t>(d);
  }
  out.values.resize(count);
  if (count > 0 && out.dtype == DType::kUInt64) {
    out.bits.resize(count);
    h5::check(H5Dread(object.get(), H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                      out.bits.data()),
              context + ": cannot read");
    for (std::size_t i = 0; i < count; ++i) out.values[i] = static_cast<double>(out.bits[i]);
  } else if (count > 0) {
    h5::check(H5Dread(object.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                      out.values.data()),
              context + ": cannot read");
  }
  if (h5::has_attribute(object.get(), "units", context)) {
    out.units = h5::read_string_attribute(object.get(), "units", context);
  }
  return out;
}

std::string read_string_attribute(const std::string& file, const std::string& object_path,
                                  const std::string& name) {
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  h5::Handle object = open_object(handle.get(), file, object_path);
  return h5::read_string_attribute(object.get(), name,
                                   "trace " + quoted(file) + ", object " + quoted(object_path));
}

std::int64_t read_int_attribute(const std::string& file, const std::string& object_path,
                                const std::string& name) {
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  h5::Handle object = open_object(handle.get(), file, object_path);
  return h5::read_int_attribute(object.get(), name,
                                "trace " + quoted(file) + ", object " + quoted(object_path));
}

double read_double_attribute(const std::string& file, const std::string& object_path,
                             const std::string& name) {
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  h5::Handle object = open_object(handle.get(), file, object_path);
  return h5::read_double_attribute(object.get(), name,
                                   "trace " + quoted(file) + ", object " + quoted(object_path));
}

bool has_attribute(const std::string& file, const std::string& object_path,
                   const std::string& name) {
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  h5::Handle object = open_object(handle.get(), file, object_path);
  return h5::has_attribute(object.get(), name,
                           "trace " + quoted(file) + ", object " + quoted(object_path));
}

bool has_object(const std::string& file, const std::string& path) {
  h5::Quiet quiet;
  h5::Handle handle = open_file(file);
  return exists(handle.get(), path, "trace " + quoted(file));
}

}  // namespace graspsim::recordings
