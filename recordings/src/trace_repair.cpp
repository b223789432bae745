// repair_trace: the h5clear -s --increment step, done through the HDF5 C API.
#include "graspsim/recordings/trace_repair.hpp"

#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "h5.hpp"

namespace graspsim::recordings {
namespace {

// The file-access property h5clear sets to open a file whose status flags say it is still open
// for (SWMR) writing; HDF5 1.10 registers it on every file-access list under this name
// (H5F_ACS_CLEAR_STATUS_FLAGS_NAME in H5Fprivate.h).
constexpr const char* kClearStatusFlags = "clear_status_flags";
// What h5clear --increment adds by default: the EOA becomes max(EOA, EOF) + 1 MiB, so space the
// writer allocated but whose superblock EOA never reached the disk is not cut off at close.
constexpr hsize_t kIncrement = 1024 * 1024;   // bytes

}  // namespace

RepairResult repair_trace(const std::string& path) {
  const std::string context = "trace '" + path + "'";
  RepairResult result;
  // What it is, read as a SWMR reader if need be (throws for a file that is not HDF5).
  if (!has_attribute(path, "/", "status") || !has_attribute(path, "/", "schema_version")) {
    throw TraceError(context + ": not a graspsim trace (no root attribute 'status' or 'schema_version')");
  }
  result.status_before = read_string_attribute(path, "/", "status");
  result.status_after = result.status_before;
  if (result.status_before == "running") {
    h5::Lock lock;
    h5::Quiet quiet;
    const std::string where = context + ": cannot repair";
    h5::Handle fapl = h5::checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, where);
    hbool_t clear = 1;
    h5::check(H5Pset(fapl.get(), kClearStatusFlags, &clear), where);
    h5::Handle file = h5::checked(H5Fopen(path.c_str(), H5F_ACC_RDWR, fapl.get()), H5Fclose, where);
    h5::check(H5Fincrement_filesize(file.get(), kIncrement), where);
    h5::Handle root = h5::checked(H5Gopen2(file.get(), "/", H5P_DEFAULT), H5Gclose, where);
    h5::write_string_attribute(root.get(), "status", "cut: repaired", context);
    root.reset();
    if (file.close() < 0) throw TraceError(where + ": " + h5::last_error());
    result.repaired = true;
    result.status_after = "cut: repaired";
  }
  // It must now open as a plain reader (no SWMR), as h5dump does.
  {
    h5::Lock lock;
    h5::Quiet quiet;
    const hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (id < 0) throw TraceError(context + ": still does not open without SWMR: " + h5::last_error());
    H5Fclose(id);
  }
  result.servo_rows = has_object(path, "/servo/tick")
                          ? static_cast<std::int64_t>(read_dataset(path, "/servo/tick").shape.at(0))
                          : -1;
  return result;
}

}  // namespace graspsim::recordings
