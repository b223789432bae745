// Internal HDF5 C API helpers for recordings/: an owning hid_t handle, a guard that stops HDF5
// printing its error stack, and attribute read/write used by both the writer and the reader.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>
#include <utility>

namespace graspsim::recordings::h5 {

// Turns HDF5's automatic error printing off for its lifetime, then restores what was there.
// Every entry point of this module that calls HDF5 holds one, so failures become exceptions
// and nothing is printed to stderr.
class Quiet {
 public:
  Quiet();
  ~Quiet();
  Quiet(const Quiet&) = delete;
  Quiet& operator=(const Quiet&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// Debian's HDF5 is built without thread safety, and a trace may be written by a background
// thread (TraceOptions::background) while the same process reads another trace: every entry
// point of this module that calls HDF5 holds this lock (recursive: entry points nest).
class Lock {
 public:
  Lock();
  ~Lock();
  Lock(const Lock&) = delete;
  Lock& operator=(const Lock&) = delete;
};

// Why the last HDF5 call on this thread failed: the innermost message of the error stack, or
// the operating system's reason when the file layer reports one ("No such file or directory").
std::string last_error();

using CloseFn = herr_t (*)(hid_t);

// Owns one HDF5 identifier and closes it with the matching H5?close.
class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, CloseFn close) : id_(id), close_(close) {}
  ~Handle() { reset(); }
  Handle(Handle&& other) noexcept
      : id_(std::exchange(other.id_, H5I_INVALID_HID)), close_(other.close_) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, H5I_INVALID_HID);
      close_ = other.close_;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  void reset() noexcept;
  // Closes now and reports failure (for the file, where a failed close loses data).
  herr_t close();

 private:
  hid_t id_ = H5I_INVALID_HID;
  CloseFn close_ = nullptr;
};

// Wraps a freshly returned id; throws TraceError(context + ": " + last_error()) if it is < 0.
Handle checked(hid_t id, CloseFn close, const std::string& context);
// Throws TraceError(context + ": " + last_error()) if status < 0.
void check(herr_t status, const std::string& context);

// A scalar string attribute (variable-length UTF-8), replacing one of the same name.
void write_string_attribute(hid_t object, const std::string& name, const std::string& value,
                            const std::string& context);
// The same for an attribute known not to exist yet (a new object): one look-up cheaper.
void create_string_attribute(hid_t object, const std::string& name, const std::string& value,
                             const std::string& context);
// A scalar numeric attribute of HDF5 file type `file_type` from memory type `memory_type`.
void write_scalar_attribute(hid_t object, const std::string& name, hid_t file_type,
                            hid_t memory_type, const void* value, const std::string& context);

bool has_attribute(hid_t object, const std::string& name, const std::string& context);
// Variable- or fixed-length string attribute with one element.
std::string read_string_attribute(hid_t object, const std::string& name,
                                  const std::string& context);
// Integer attribute with one element.
std::int64_t read_int_attribute(hid_t object, const std::string& name,
                                const std::string& context);
// Integer or floating-point attribute with one element, converted to double.
double read_double_attribute(hid_t object, const std::string& name, const std::string& context);

}  // namespace graspsim::recordings::h5
