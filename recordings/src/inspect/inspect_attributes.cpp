// The schema-free view: an object's attributes listed, a string read, a string or an integer
// written.
#include <cstring>

#include "inspect_detail.hpp"

namespace graspsim::recordings::inspect {

using detail::check;
using detail::Guard;
using detail::own;
using detail::where;

namespace {

herr_t collect_name(hid_t, const char* name, const H5A_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->emplace_back(name);
  return 0;
}

h5::Handle open_attribute(hid_t object, const std::string& name, const std::string& at) {
  return own(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose, at + ": no attribute '" + name + "'");
}

}  // namespace

std::vector<Attribute> File::attributes(const std::string& object) const {
  Guard guard;
  const std::string at = where(path_, object);
  h5::Handle o = detail::open_object(handles_->file.get(), object, at);
  std::vector<std::string> names;
  check(H5Aiterate2(o.get(), H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_name, &names),
        at + ": cannot list its attributes");
  std::vector<Attribute> out;
  for (const std::string& name : names) {
    h5::Handle a = open_attribute(o.get(), name, at);
    h5::Handle type = own(H5Aget_type(a.get()), H5Tclose, at + ": attribute '" + name + "'");
    out.push_back({name, detail::type_of(type.get())});
  }
  return out;
}

bool File::has_attribute(const std::string& object, const std::string& name) const {
  Guard guard;
  const std::string at = where(path_, object);
  h5::Handle o = detail::open_object(handles_->file.get(), object, at);
  const htri_t exists = H5Aexists(o.get(), name.c_str());
  check(exists, at + ": cannot look for attribute '" + name + "'");
  return exists > 0;
}

std::string File::read_string_attribute(const std::string& object, const std::string& name) const {
  Guard guard;
  const std::string at = where(path_, object) + ": attribute '" + name + "'";
  h5::Handle o = detail::open_object(handles_->file.get(), object, where(path_, object));
  h5::Handle a = open_attribute(o.get(), name, where(path_, object));
  h5::Handle space = own(H5Aget_space(a.get()), H5Sclose, at);
  if (H5Sget_simple_extent_npoints(space.get()) != 1) throw InspectError(at + " is not a single value");
  h5::Handle type = own(H5Aget_type(a.get()), H5Tclose, at);
  if (H5Tget_class(type.get()) != H5T_STRING) throw InspectError(at + " is not a string");
  const htri_t variable = H5Tis_variable_str(type.get());
  check(variable, at);
  if (variable > 0) {
    // Read in the stored character set: no conversion of the bytes.
    h5::Handle memory = own(H5Tcopy(H5T_C_S1), H5Tclose, at);
    check(H5Tset_size(memory.get(), H5T_VARIABLE), at);
    check(H5Tset_cset(memory.get(), H5Tget_cset(type.get())), at);
    char* text = nullptr;
    check(H5Aread(a.get(), memory.get(), &text), at + ": cannot read it");
    std::string value = text != nullptr ? text : "";
    H5free_memory(text);
    return value;
  }
  const std::size_t size = H5Tget_size(type.get());
  std::vector<char> buffer(size + 1, '\0');
  check(H5Aread(a.get(), type.get(), buffer.data()), at + ": cannot read it");
  // A fixed-length string may be null-terminated, null-padded or space-padded.
  std::string value(buffer.data(), strnlen(buffer.data(), size));
  if (H5Tget_strpad(type.get()) == H5T_STR_SPACEPAD) value.erase(value.find_last_not_of(' ') + 1);
  return value;
}

void File::write_string_attribute(const std::string& object, const std::string& name, const std::string& value) {
  Guard guard;
  const std::string at = where(path_, object) + ": cannot write attribute '" + name + "'";
  h5::Handle o = detail::open_object(handles_->file.get(), object, where(path_, object));
  h5::Handle type = own(H5Tcopy(H5T_C_S1), H5Tclose, at);
  check(H5Tset_size(type.get(), H5T_VARIABLE), at);
  check(H5Tset_cset(type.get(), H5T_CSET_UTF8), at);
  h5::Handle space = own(H5Screate(H5S_SCALAR), H5Sclose, at);
  const htri_t exists = H5Aexists(o.get(), name.c_str());
  check(exists, at);
  if (exists > 0) check(H5Adelete(o.get(), name.c_str()), at);
  h5::Handle a = own(H5Acreate2(o.get(), name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, at);
  const char* text = value.c_str();
  check(H5Awrite(a.get(), type.get(), &text), at);
}

void File::write_int_attribute(const std::string& object, const std::string& name, std::int64_t value) {
  Guard guard;
  const std::string at = where(path_, object) + ": cannot write attribute '" + name + "'";
  h5::Handle o = detail::open_object(handles_->file.get(), object, where(path_, object));
  const htri_t exists = H5Aexists(o.get(), name.c_str());
  check(exists, at);
  h5::Handle a;
  if (exists > 0) {
    a = open_attribute(o.get(), name, at);
  } else {
    h5::Handle space = own(H5Screate(H5S_SCALAR), H5Sclose, at);
    a = own(H5Acreate2(o.get(), name.c_str(), H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, at);
  }
  check(H5Awrite(a.get(), H5T_NATIVE_INT64, &value), at);
}

}  // namespace graspsim::recordings::inspect
