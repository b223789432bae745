// Checks on what a trace file says about itself (see h5_checks.hpp).
#include "h5_checks.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

#include "graspsim/recordings/trace_writer.hpp"

namespace graspsim::recordings::h5 {
namespace {

std::string bytes_text(long double bytes) {
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  int u = 0;
  while (bytes >= 1000.0L && u < 6) bytes /= 1000.0L, ++u;
  char buf[48];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0Lf %s" : "%.1Lf %s", bytes, units[u]);
  return buf;
}

// Products and sums of sizes, saturated at 2^64 - 1 instead of wrapping round.
constexpr std::uint64_t kSaturated = ~std::uint64_t{0};
std::uint64_t times(std::uint64_t a, std::uint64_t b) {
  std::uint64_t out = 0;
  return __builtin_mul_overflow(a, b, &out) ? kSaturated : out;
}
std::uint64_t plus(std::uint64_t a, std::uint64_t b) {
  std::uint64_t out = 0;
  return __builtin_add_overflow(a, b, &out) ? kSaturated : out;
}

const char* file_kind(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// ---- the raw reference of a variable-length string ------------------------------------------
//
// On disk (HDF5 file format, "Variable-length" datatype, and H5Tvlen.c's disk class) one value is
// the sequence length (uint32), then a global heap ID: the collection's address (sizeof_addr
// bytes) and the object's index (uint32). A conversion function from a variable-length string
// to an opaque type of that size, registered once, hands those bytes over as they are: HDF5
// copies the attribute's stored value into the conversion buffer and calls it, so nothing is
// read from the heap.

constexpr const char* kReferenceTag = "graspsim: variable-length string reference, as stored";
constexpr std::size_t kReferenceBytes = 4 + 8 + 4;   // with 8-byte file addresses

herr_t keep_stored_bytes(hid_t source, hid_t destination, H5T_cdata_t* cdata, size_t, size_t, size_t,
                         void*, void*, hid_t) {
  if (cdata->command != H5T_CONV_INIT) return 0;   // H5T_CONV_CONV: the bytes stay; H5T_CONV_FREE
  if (H5Tget_class(source) != H5T_STRING || H5Tis_variable_str(source) <= 0) return -1;
  if (H5Tget_class(destination) != H5T_OPAQUE) return -1;
  char* tag = H5Tget_tag(destination);
  const bool ours = tag != nullptr && std::strcmp(tag, kReferenceTag) == 0;
  H5free_memory(tag);
  if (!ours) return -1;
  cdata->need_bkg = H5T_BKG_NO;
  return 0;
}

// The opaque type the references are read as (created and registered once; never closed).
hid_t reference_type() {
  static hid_t type = [] {
    hid_t opaque = H5Tcreate(H5T_OPAQUE, kReferenceBytes);
    hid_t text = H5Tcopy(H5T_C_S1);
    if (opaque < 0 || text < 0 || H5Tset_tag(opaque, kReferenceTag) < 0 || H5Tset_size(text, H5T_VARIABLE) < 0 ||
        H5Tregister(H5T_PERS_SOFT, "graspsim_stored_string_reference", text, opaque, keep_stored_bytes) < 0) {
      opaque = H5I_INVALID_HID;
    }
    if (text >= 0) H5Tclose(text);
    return opaque;
  }();
  return type;
}

std::uint64_t little_endian(const unsigned char* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

// Reads `size` bytes at byte `offset` of the file behind `file` (through HDF5's own descriptor:
// the sec2 driver's, the one every trace is opened with).
bool read_at(hid_t file, std::uint64_t offset, std::size_t size, unsigned char* out) {
  void* handle = nullptr;
  if (H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) < 0 || handle == nullptr) return false;
  const int fd = *static_cast<int*>(handle);
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pread(fd, out + done, size - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

OpenFile open_read_only(const std::string& path, const std::string& where) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) throw TraceError(where + ": no such file");
    throw TraceError(where + ": " + std::strerror(errno));
  }
  if (S_ISDIR(st.st_mode)) throw TraceError(where + ": it is a directory");
  if (!S_ISREG(st.st_mode)) {
    throw TraceError(where + ": it is " + file_kind(st.st_mode) + ", not a regular file (a trace is a file; "
                     "reading from this could block or never end)");
  }
  const htri_t is_hdf5 = H5Fis_hdf5(path.c_str());
  if (is_hdf5 < 0) throw TraceError(where + ": " + last_error());
  if (is_hdf5 == 0) throw TraceError(where + ": not an HDF5 file");
  OpenFile out;
  const hid_t plain = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (plain >= 0) {
    out.file = Handle(plain, H5Fclose);
    return out;
  }
  // A trace still being written, or cut by a crash, is marked as open for SWMR writing: it
  // opens as a SWMR reader (recordings/README.md, "Crash safety"), which skips that mark.
  const std::string reason = last_error();
  H5Eclear2(H5E_DEFAULT);
  Handle fapl = checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, where);
  check(H5Pset_metadata_read_attempts(fapl.get(), kSwmrReadAttempts), where);
  const hid_t swmr = H5Fopen(path.c_str(), H5F_ACC_RDONLY | H5F_ACC_SWMR_READ, fapl.get());
  if (swmr < 0) throw TraceError(where + ": " + reason + " (truncated or damaged?)");
  out.file = Handle(swmr, H5Fclose);
  out.swmr = true;
  return out;
}

std::uint64_t file_size(hid_t object, const std::string& context) {
  Handle file = checked(H5Iget_file_id(object), H5Fclose, context);
  hsize_t size = 0;
  check(H5Fget_filesize(file.get(), &size), context + ": cannot get the file's size");
  return size;
}

void check_rows(hid_t dataset, std::uint64_t rows, const std::string& context) {
  Handle type = checked(H5Dget_type(dataset), H5Tclose, context);
  Handle space = checked(H5Dget_space(dataset), H5Sclose, context);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0 || rank > 2) throw TraceError(context + ": has " + std::to_string(rank) + " dimensions (a trace column has 1 or 2)");
  hsize_t dims[2] = {0, 1};
  if (rank > 0) check(H5Sget_simple_extent_dims(space.get(), dims, nullptr), context);
  // One row: the element (a compound row, or one value) times the second dimension.
  const std::uint64_t row_bytes = times(H5Tget_size(type.get()), rank == 2 ? dims[1] : 1);
  const std::uint64_t bytes = times(row_bytes, rows);
  Handle dcpl = checked(H5Dget_create_plist(dataset), H5Pclose, context);
  const bool filtered = H5Pget_nfilters(dcpl.get()) > 0;
  std::uint64_t chunk = 0;
  if (H5Pget_layout(dcpl.get()) == H5D_CHUNKED) {
    hsize_t chunk_dims[2] = {0, 1};
    if (H5Pget_chunk(dcpl.get(), 2, chunk_dims) >= 1) chunk = times(row_bytes, chunk_dims[0]);
  }
  const std::uint64_t size = file_size(dataset, context);
  const std::uint64_t limit = plus(times(size, filtered ? kMaxFilterRatio : 1), std::min(chunk, kMaxChunkSlack));
  if (bytes > limit) {
    throw TraceError(context + ": its " + std::to_string(rows) + " rows of " +
                     std::to_string(row_bytes) + " bytes (" +
                     (bytes == kSaturated ? "more than 18 EB" : bytes_text(bytes)) + ") cannot be in a file of " + bytes_text(size) +
                     (filtered ? " even compressed (deflate stores at most 1032 bytes in one)"
                               : " (uncompressed, every byte of a row is stored)") +
                     ": its extent is damaged");
  }
}

void check_variable_string(hid_t attribute, const std::string& name, const std::string& context) {
  const std::string where = context + ": attribute '" + name + "'";
  Handle file = checked(H5Iget_file_id(attribute), H5Fclose, where);
  Handle fcpl = checked(H5Fget_create_plist(file.get()), H5Pclose, where);
  size_t sizeof_addr = 0, sizeof_size = 0;
  hsize_t userblock = 0;
  check(H5Pget_sizes(fcpl.get(), &sizeof_addr, &sizeof_size), where);
  check(H5Pget_userblock(fcpl.get(), &userblock), where);
  if (sizeof_addr != 8 || sizeof_size != 8) {
    throw TraceError(where + ": the file uses " + std::to_string(sizeof_addr) + "-byte addresses and " +
                     std::to_string(sizeof_size) + "-byte lengths; its strings are read only with 8 and 8");
  }
  // The stored reference, without a heap read.
  const hid_t reference = reference_type();
  if (reference < 0) throw TraceError(where + ": cannot register the reference reader: " + last_error());
  unsigned char raw[kReferenceBytes] = {};
  check(H5Aread(attribute, reference, raw), where + ": cannot read its stored reference");
  const std::uint64_t length = little_endian(raw, 4);
  const std::uint64_t address = little_endian(raw + 4, 8);
  const std::uint64_t index = little_endian(raw + 12, 4);
  if (address == 0) return;   // a null string: HDF5 reads nothing
  const std::uint64_t size = file_size(file.get(), where);
  const std::uint64_t at = userblock + address;
  const auto damaged = [&](const std::string& why) {
    return TraceError(where + ": its stored string is damaged (" + why + ")");
  };
  if (length > size) throw damaged("a length of " + std::to_string(length) + " bytes in a file of " + bytes_text(size));
  // The global heap collection: "GCOL", version 1, 3 reserved bytes, its size (8 bytes).
  constexpr std::uint64_t kHeader = 16, kObjectHeader = 16, kMinCollection = 4096;
  unsigned char header[kHeader];
  if (at > size || size - at < kHeader || !read_at(file.get(), at, kHeader, header))
    throw damaged("its heap at byte " + std::to_string(at) + " is outside the file");
  if (std::memcmp(header, "GCOL", 4) != 0 || header[4] != 1) throw damaged("no global heap at byte " + std::to_string(at));
  const std::uint64_t collection = little_endian(header + 8, 8);
  if (collection < kMinCollection || collection > size - at)
    throw damaged("a heap of " + std::to_string(collection) + " bytes at byte " + std::to_string(at) + " of " + bytes_text(size));
  std::vector<unsigned char> heap(static_cast<std::size_t>(collection));
  if (!read_at(file.get(), at, heap.size(), heap.data())) throw damaged("its heap cannot be read");
  // Walk the objects as libhdf5 does when it loads the collection (H5HGcache.c): a header of
  // index (2), references (2), reserved (4), size (8); then the data, padded to 8 bytes (index 0,
  // the free space, counts its header in its size and is not padded). A walk that would not
  // advance (libhdf5 loops for ever) or leaves the collection (it reads past it) is refused.
  std::uint64_t found_begin = 0, found_size = 0;
  bool found = false;
  std::uint64_t p = kHeader;
  while (p < collection) {
    if (collection - p < kObjectHeader) break;   // too small for a header: free space
    const std::uint64_t object = little_endian(heap.data() + p, 2);
    const std::uint64_t object_size = little_endian(heap.data() + p + 8, 8);
    std::uint64_t need = object_size;
    if (object > 0) {
      if (object_size > collection) throw damaged("heap object " + std::to_string(object) + " is larger than its heap");
      need = kObjectHeader + ((object_size + 7) / 8) * 8;
    }
    if (need == 0 || need > collection - p) throw damaged("the heap's objects do not tile it");
    if (object == index) {
      found = true;
      found_begin = p;
      found_size = object_size;
    }
    p += need;
  }
  if (!found || index == 0) throw damaged("heap object " + std::to_string(index) + " is not in its heap");
  if (found_size != length || collection - found_begin - kObjectHeader < found_size)
    throw damaged("heap object " + std::to_string(index) + " holds " + std::to_string(found_size) + " bytes, its reference says " +
                  std::to_string(length));
}

}  // namespace graspsim::recordings::h5
