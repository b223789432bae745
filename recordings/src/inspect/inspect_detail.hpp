// What the files of the schema-free view (h5_inspect.hpp) share: the file's handle, the guard
// every call holds, handles that throw InspectError, and a stored type described.
#pragma once

#include <hdf5.h>

#include <string>

#include "graspsim/recordings/h5_inspect.hpp"
#include "h5.hpp"

namespace graspsim::recordings::inspect {

struct File::Handles {
  h5::Handle file;
};

namespace detail {

// The module's HDF5 lock (a trace may be written by a background thread meanwhile) and no
// printing to stderr: the error becomes InspectError's text instead.
struct Guard {
  h5::Lock lock;
  h5::Quiet quiet;
};

// Owns `id`; throws InspectError(what + ": " + HDF5's reason) when it is < 0.
h5::Handle own(hid_t id, h5::CloseFn close, const std::string& what);
// Throws InspectError(what + ": " + HDF5's reason) when status < 0.
void check(herr_t status, const std::string& what);
// The object (group, dataset) at `path` of `file`.
h5::Handle open_object(hid_t file, const std::string& path, const std::string& what);
h5::Handle open_dataset(hid_t file, const std::string& path, const std::string& what);
// `file` and `path` as an error names them: "f.h5: /servo".
std::string where(const std::string& file, const std::string& path);
Type type_of(hid_t type);

}  // namespace detail
}  // namespace graspsim::recordings::inspect
