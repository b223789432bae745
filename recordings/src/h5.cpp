// Internal HDF5 C API helpers for recordings/: handles, quiet errors, attributes.
#include "h5.hpp"

#include <cstring>
#include <vector>

#include "graspsim/recordings/trace_writer.hpp"
#include "h5_checks.hpp"

namespace graspsim::recordings::h5 {
namespace {

// HDF5 1.10 frees a file whose H5Fclose fails (a full disk) but keeps its identifier, and the
// handler it registers with atexit (H5_term_library) then closes that file again: SIGSEGV in
// H5F__close_cb after main returns. Every HDF5 object this module opens is closed by its owner
// before exit, so the library need not be shut down then; H5dont_atexit, which must come before
// the library initialises and does not initialise it, keeps the handler from being registered.
// Static initialisation runs before main, and no initialiser of this program calls HDF5.
[[maybe_unused]] const herr_t kNoShutdownAtExit = H5dont_atexit();

// Collects the innermost error of the stack (the walk goes upward, innermost first).
herr_t take_innermost(unsigned n, const H5E_error2_t* error, void* out) {
  if (n == 0 && error != nullptr && error->desc != nullptr) {
    *static_cast<std::string*>(out) = error->desc;
  }
  return 0;
}

Handle string_type() {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!type.valid() || H5Tset_size(type.get(), H5T_VARIABLE) < 0 ||
      H5Tset_cset(type.get(), H5T_CSET_UTF8) < 0) {
    throw TraceError("cannot make an HDF5 string type: " + last_error());
  }
  return type;
}

// Opens attribute `name` and checks that it holds exactly one element.
Handle open_single(hid_t object, const std::string& name, const std::string& context) {
  Handle attribute = checked(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose,
                             context + ": no attribute '" + name + "'");
  Handle space = checked(H5Aget_space(attribute.get()), H5Sclose, context);
  if (H5Sget_simple_extent_npoints(space.get()) != 1) {
    throw TraceError(context + ": attribute '" + name + "' is not a single value");
  }
  return attribute;
}

}  // namespace

// Guards nest (every Handle::reset holds one, often inside another): only the outermost one
// switches HDF5's printing off and back, since each switch costs about a microsecond and a block
// write closes several handles (recordings/README.md "Cost").
namespace {
thread_local int quiet_depth = 0;
}

Quiet::Quiet() {
  if (quiet_depth++ > 0) return;
  H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

Quiet::~Quiet() {
  if (--quiet_depth > 0) return;
  H5Eset_auto2(H5E_DEFAULT, func_, data_);
}

namespace {
std::recursive_mutex& library_mutex() {
  static std::recursive_mutex mutex;
  return mutex;
}
}  // namespace

Lock::Lock() { library_mutex().lock(); }
Lock::~Lock() { library_mutex().unlock(); }

std::string last_error() {
  std::string desc;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, take_innermost, &desc);
  if (desc.empty()) return "unknown HDF5 error";
  // The file driver says "..., errno = 2, error message = 'No such file or directory', ...".
  const std::string marker = "error message = '";
  const auto start = desc.find(marker);
  if (start != std::string::npos) {
    const auto from = start + marker.size();
    const auto end = desc.find('\'', from);
    if (end != std::string::npos) return desc.substr(from, end - from);
  }
  return desc;
}

void Handle::reset() noexcept {
  if (id_ >= 0) {
    Quiet quiet;
    close_(id_);
    id_ = H5I_INVALID_HID;
  }
}

herr_t Handle::close() {
  herr_t status = 0;
  if (id_ >= 0) {
    status = close_(id_);
    id_ = H5I_INVALID_HID;
  }
  return status;
}

Handle checked(hid_t id, CloseFn close, const std::string& context) {
  if (id < 0) throw TraceError(context + ": " + last_error());
  return Handle(id, close);
}

void check(herr_t status, const std::string& context) {
  if (status < 0) throw TraceError(context + ": " + last_error());
}

void write_string_attribute(hid_t object, const std::string& name, const std::string& value,
                            const std::string& context) {
  const std::string where = context + ": cannot write attribute '" + name + "'";
  Handle type = string_type();
  Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, where);
  const htri_t exists = H5Aexists(object, name.c_str());
  check(exists, where);
  if (exists > 0) check(H5Adelete(object, name.c_str()), where);
  Handle attribute = checked(
      H5Acreate2(object, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
      H5Aclose, where);
  const char* text = value.c_str();
  check(H5Awrite(attribute.get(), type.get(), &text), where);
}

void create_string_attribute(hid_t object, const std::string& name, const std::string& value,
                             const std::string& context) {
  const std::string where = context + ": cannot write attribute '" + name + "'";
  Handle type = string_type();
  Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, where);
  Handle attribute = checked(
      H5Acreate2(object, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
      H5Aclose, where);
  const char* text = value.c_str();
  check(H5Awrite(attribute.get(), type.get(), &text), where);
}

void write_scalar_attribute(hid_t object, const std::string& name, hid_t file_type,
                            hid_t memory_type, const void* value, const std::string& context) {
  const std::string where = context + ": cannot write attribute '" + name + "'";
  Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, where);
  const htri_t exists = H5Aexists(object, name.c_str());
  check(exists, where);
  if (exists > 0) check(H5Adelete(object, name.c_str()), where);
  Handle attribute = checked(
      H5Acreate2(object, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
      H5Aclose, where);
  check(H5Awrite(attribute.get(), memory_type, value), where);
}

bool has_attribute(hid_t object, const std::string& name, const std::string& context) {
  const htri_t exists = H5Aexists(object, name.c_str());
  check(exists, context + ": cannot look for attribute '" + name + "'");
  return exists > 0;
}

std::string read_string_attribute(hid_t object, const std::string& name,
                                  const std::string& context) {
  const std::string where = context + ": cannot read attribute '" + name + "'";
  Handle attribute = open_single(object, name, context);
  Handle file_type = checked(H5Aget_type(attribute.get()), H5Tclose, where);
  if (H5Tget_class(file_type.get()) != H5T_STRING) {
    throw TraceError(context + ": attribute '" + name + "' is not a string");
  }
  const htri_t variable = H5Tis_variable_str(file_type.get());
  check(variable, where);
  if (variable > 0) {
    // libhdf5 trusts the stored length and heap object of a variable-length string: check both.
    check_variable_string(attribute.get(), name, context);
    Handle memory_type = string_type();
    check(H5Tset_cset(memory_type.get(), H5Tget_cset(file_type.get())), where);
    char* text = nullptr;
    check(H5Aread(attribute.get(), memory_type.get(), &text), where);
    std::string value = text != nullptr ? text : "";
    H5free_memory(text);
    return value;
  }
  const std::size_t size = H5Tget_size(file_type.get());
  if (size == 0 || size > file_size(attribute.get(), where))
    throw TraceError(where + ": a fixed-length string of " + std::to_string(size) + " bytes cannot be in its file (damaged?)");
  Handle memory_type = checked(H5Tcopy(file_type.get()), H5Tclose, where);
  std::vector<char> buffer(size + 1, '\0');
  check(H5Aread(attribute.get(), memory_type.get(), buffer.data()), where);
  // Fixed-length strings may be null-terminated, null-padded or space-padded.
  std::string value(buffer.data(), strnlen(buffer.data(), size));
  if (H5Tget_strpad(file_type.get()) == H5T_STR_SPACEPAD) {
    value.erase(value.find_last_not_of(' ') + 1);
  }
  return value;
}

std::int64_t read_int_attribute(hid_t object, const std::string& name,
                                const std::string& context) {
  Handle attribute = open_single(object, name, context);
  Handle file_type = checked(H5Aget_type(attribute.get()), H5Tclose, context);
  if (H5Tget_class(file_type.get()) != H5T_INTEGER) {
    throw TraceError(context + ": attribute '" + name + "' is not an integer");
  }
  std::int64_t value = 0;
  check(H5Aread(attribute.get(), H5T_NATIVE_INT64, &value),
        context + ": cannot read attribute '" + name + "'");
  return value;
}

double read_double_attribute(hid_t object, const std::string& name, const std::string& context) {
  Handle attribute = open_single(object, name, context);
  Handle file_type = checked(H5Aget_type(attribute.get()), H5Tclose, context);
  const H5T_class_t type_class = H5Tget_class(file_type.get());
  if (type_class != H5T_FLOAT && type_class != H5T_INTEGER) {
    throw TraceError(context + ": attribute '" + name + "' is not a number");
  }
  double value = 0.0;
  check(H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, &value),
        context + ": cannot read attribute '" + name + "'");
  return value;
}

}  // namespace graspsim::recordings::h5
