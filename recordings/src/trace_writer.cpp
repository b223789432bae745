// TraceWriter and TraceTable: rows buffered per table, appended block by block to chunked
// HDF5 datasets (H5Dset_extent + hyperslab + H5Dwrite per column).
#include "graspsim/recordings/trace_writer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <type_traits>
#include <vector>

#include "h5.hpp"

namespace graspsim::recordings {
namespace {

// Checks a relative HDF5 path: non-empty components, none of them ".", no leading '/'.
bool is_relative_path(const std::string& path) {
  if (path.empty() || path.front() == '/' || path.back() == '/') return false;
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t end = std::min(path.find('/', start), path.size());
    const std::string part = path.substr(start, end - start);
    if (part.empty() || part == "." || part == "..") return false;
    start = end + 1;
  }
  return true;
}

hid_t file_type_of(DType dtype) {
  switch (dtype) {
    case DType::kFloat64: return H5T_IEEE_F64LE;
    case DType::kInt64: return H5T_STD_I64LE;
    case DType::kInt32: return H5T_STD_I32LE;
    case DType::kInt8: return H5T_STD_I8LE;
    case DType::kUInt64: return H5T_STD_U64LE;
  }
  return H5T_IEEE_F64LE;
}

const char* name_of(DType dtype) {
  switch (dtype) {
    case DType::kFloat64: return "float64";
    case DType::kInt64: return "int64";
    case DType::kInt32: return "int32";
    case DType::kInt8: return "int8";
    case DType::kUInt64: return "uint64";
  }
  return "?";
}

// Inclusive range of an integer dtype as doubles (both ends exact in double). int64's upper
// end 2^63 - 1 is not a double, so that check is "below 2^63" (see fits()).
double lowest(DType dtype) {
  switch (dtype) {
    case DType::kInt64: return -9223372036854775808.0;   // -2^63
    case DType::kInt32: return -2147483648.0;
    case DType::kInt8: return -128.0;
    case DType::kFloat64: case DType::kUInt64: break;
  }
  return 0.0;
}

double highest(DType dtype) {
  switch (dtype) {
    case DType::kInt64: return 9223372036854775808.0;    // 2^63, exclusive
    case DType::kInt32: return 2147483647.0;
    case DType::kInt8: return 127.0;
    case DType::kFloat64: case DType::kUInt64: break;
  }
  return 0.0;
}

bool fits(double value, DType dtype) {
  if (!(value == std::trunc(value))) return false;   // also rejects NaN and infinities
  if (value < lowest(dtype)) return false;
  return dtype == DType::kInt64 ? value < highest(dtype) : value <= highest(dtype);
}

std::string quoted(const std::string& text) { return "'" + text + "'"; }

struct Column {
  std::string path;      // absolute, e.g. "/servo/fingers/thumb/hip"
  int width;             // values per row
  DType dtype;
  std::size_t offset;    // into a row
  h5::Handle dataset;
};

// What the writer and its tables share about the file: whether its layout is frozen (the first
// row was appended) and SWMR writing started.
struct FileState {
  hid_t file = H5I_INVALID_HID;   // not owned (TraceWriter::Impl::file)
  std::string context;            // "trace 'PATH'"
  bool swmr = true;               // TraceOptions::swmr
  bool frozen = false;            // a row was appended: no new table, column or table attribute

  void freeze() {
    if (frozen) return;
    if (swmr && H5Fstart_swmr_write(file) < 0) {
      throw TraceError(context + ": cannot start SWMR writing: " + h5::last_error());
    }
    frozen = true;
  }
};

// Object creation properties without modification times, so that two runs write the same
// object headers.
h5::Handle untimed(hid_t property_class, const std::string& where) {
  h5::Handle plist = h5::checked(H5Pcreate(property_class), H5Pclose, where);
  h5::check(H5Pset_obj_track_times(plist.get(), 0), where);
  return plist;
}

h5::Handle file_access(bool swmr, const std::string& where) {
  h5::Handle fapl = h5::checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, where);
  if (swmr) h5::check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST), where);
  return fapl;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// TraceTable

struct TraceTable::Impl {
  std::string file_path;
  std::string group_path;   // "/servo"
  TraceOptions options;
  std::size_t block_rows = 0;    // rows buffered before a write, and rows per chunk
  FileState* file = nullptr;     // owned by the writer
  h5::Handle group;
  std::vector<Column> columns;
  std::size_t row_width = 0;     // doubles per row
  std::size_t max_width = 0;     // widest column
  std::vector<double> buffer;    // block_rows x row_width, row-major
  // One column's block in its memory type, filled by flush() (sized on the first row).
  std::vector<double> scratch_f64;
  std::vector<std::int64_t> scratch_i64;
  std::vector<std::int32_t> scratch_i32;
  std::vector<std::int8_t> scratch_i8;
  std::vector<std::uint64_t> scratch_u64;
  std::size_t buffered = 0;      // rows in `buffer`
  std::int64_t rows = 0;         // rows appended
  std::int64_t written = 0;      // rows on disk
  bool started = false;          // append_row was called
  bool closed = false;           // the writer closed the file

  std::string context() const { return "trace " + quoted(file_path); }
  std::string context(const std::string& dataset) const {
    return context() + ", dataset " + quoted(dataset);
  }
  void require_open() const {
    if (closed) throw TraceError(context() + ": table " + quoted(group_path) + " used after close");
  }
  void write_column(Column& column);
  void write_block();
};

TraceTable::TraceTable(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TraceTable::~TraceTable() = default;

std::size_t TraceTable::add_column(const std::string& path, int width, DType dtype,
                                   const std::string& units) {
  Impl& t = *impl_;
  t.require_open();
  const std::string full = t.group_path + "/" + path;
  if (t.started || t.file->frozen) {
    throw TraceError(t.context(full) + ": add_column after the first row of " +
                     quoted(t.group_path) + " or of the file");
  }
  if (!is_relative_path(path)) {
    throw TraceError(t.context(full) + ": column path must be relative, like 'fingers/a/hip'");
  }
  if (width < 1) throw TraceError(t.context(full) + ": width must be at least 1");
  for (const Column& c : t.columns) {
    if (c.path == full) throw TraceError(t.context(full) + ": column declared twice");
  }

  h5::Quiet quiet;
  const std::string where = t.context(full) + ": cannot create dataset";
  // Shape (0,) or (0, width), unlimited rows, one chunk per block.
  const int rank = width == 1 ? 1 : 2;
  const hsize_t dims[2] = {0, static_cast<hsize_t>(width)};
  const hsize_t max_dims[2] = {H5S_UNLIMITED, static_cast<hsize_t>(width)};
  const hsize_t chunk[2] = {static_cast<hsize_t>(t.block_rows),
                            static_cast<hsize_t>(width)};
  h5::Handle space = h5::checked(H5Screate_simple(rank, dims, max_dims), H5Sclose, where);
  h5::Handle dcpl = untimed(H5P_DATASET_CREATE, where);
  h5::check(H5Pset_chunk(dcpl.get(), rank, chunk), where);
  if (t.options.compression > 0) {
    h5::check(H5Pset_deflate(dcpl.get(), static_cast<unsigned>(t.options.compression)), where);
  }
  h5::Handle lcpl = h5::checked(H5Pcreate(H5P_LINK_CREATE), H5Pclose, where);
  h5::check(H5Pset_create_intermediate_group(lcpl.get(), 1), where);
  h5::Handle dataset = h5::checked(H5Dcreate2(t.group.get(), path.c_str(), file_type_of(dtype),
                                              space.get(), lcpl.get(), dcpl.get(), H5P_DEFAULT),
                                   H5Dclose, where);
  h5::write_string_attribute(dataset.get(), "units", units, t.context(full));

  const std::size_t offset = t.row_width;
  t.columns.push_back(Column{full, width, dtype, offset, std::move(dataset)});
  t.row_width += static_cast<std::size_t>(width);
  t.max_width = std::max(t.max_width, static_cast<std::size_t>(width));
  return offset;
}

double* TraceTable::append_row() {
  Impl& t = *impl_;
  t.require_open();
  if (!t.started) {
    // Everything the table will ever need, allocated once.
    const std::size_t block = t.block_rows;
    t.buffer.assign(block * t.row_width, 0.0);
    std::size_t need[5] = {0, 0, 0, 0, 0};
    for (const Column& c : t.columns) need[static_cast<int>(c.dtype)] = block * t.max_width;
    t.scratch_f64.assign(need[static_cast<int>(DType::kFloat64)], 0.0);
    t.scratch_i64.assign(need[static_cast<int>(DType::kInt64)], 0);
    t.scratch_i32.assign(need[static_cast<int>(DType::kInt32)], 0);
    t.scratch_i8.assign(need[static_cast<int>(DType::kInt8)], 0);
    t.scratch_u64.assign(need[static_cast<int>(DType::kUInt64)], 0);
    h5::Quiet quiet;
    t.file->freeze();
    t.started = true;
  }
  if (t.buffered == t.block_rows) {
    h5::Quiet quiet;
    t.write_block();
    // Metadata too, so that a run cut short leaves a readable file up to this block.
    if (H5Fflush(t.group.get(), H5F_SCOPE_LOCAL) < 0) {
      throw TraceError(t.context() + ": cannot flush: " + h5::last_error());
    }
  }
  double* row = t.buffer.data() + t.buffered * t.row_width;
  ++t.buffered;
  ++t.rows;
  return row;
}

std::size_t TraceTable::row_width() const { return impl_->row_width; }

std::int64_t TraceTable::rows() const { return impl_->rows; }

void TraceTable::flush() {
  impl_->require_open();
  h5::Quiet quiet;
  impl_->write_block();
}

void TraceTable::set_attribute(const std::string& dataset_or_dot, const std::string& name,
                               const std::string& value) {
  Impl& t = *impl_;
  t.require_open();
  const std::string full =
      dataset_or_dot == "." ? t.group_path : t.group_path + "/" + dataset_or_dot;
  if (t.file->frozen) {
    throw TraceError(t.context(full) + ": attribute '" + name + "' after the file's first row");
  }
  if (dataset_or_dot != "." && !is_relative_path(dataset_or_dot)) {
    throw TraceError(t.context(full) + ": not a path relative to " + quoted(t.group_path));
  }
  h5::Quiet quiet;
  h5::Handle object = h5::checked(H5Oopen(t.group.get(), dataset_or_dot.c_str(), H5P_DEFAULT),
                                  H5Oclose, t.context() + ": no object " + quoted(full));
  h5::write_string_attribute(object.get(), name, value, t.context() + ", object " + quoted(full));
}

// Appends the buffered rows to every dataset. On failure nothing is forgotten: the rows stay
// buffered and a retry rewrites the same rows of every column.
void TraceTable::Impl::write_block() {
  if (buffered == 0) return;
  for (Column& column : columns) write_column(column);
  written += static_cast<std::int64_t>(buffered);
  buffered = 0;
}

// Allocates nothing on success (messages are built only on failure); HDF5 mallocs its own.
void TraceTable::Impl::write_column(Column& column) {
  const std::size_t n = buffered;
  const std::size_t width = static_cast<std::size_t>(column.width);
  auto fail = [&]() {
    throw TraceError(context(column.path) + ": cannot append rows: " + h5::last_error());
  };

  // Gather the column out of the row-major buffer into its memory type: a plain copy for
  // float64, the raw bits for uint64, a checked conversion for the signed integers.
  const void* data = nullptr;
  hid_t memory_type = H5T_NATIVE_DOUBLE;
  auto gather = [&](auto& out) {
    using T = std::remove_reference_t<decltype(out[0])>;
    const double* src = buffer.data() + column.offset;
    T* dst = out.data();
    if constexpr (std::is_same_v<T, double>) {
      for (std::size_t r = 0; r < n; ++r, src += row_width, dst += width) {
        for (std::size_t c = 0; c < width; ++c) dst[c] = src[c];
      }
    } else if constexpr (std::is_same_v<T, std::uint64_t>) {   // raw bits, see uint64_in_row
      for (std::size_t r = 0; r < n; ++r, src += row_width, dst += width) {
        for (std::size_t c = 0; c < width; ++c) dst[c] = std::bit_cast<std::uint64_t>(src[c]);
      }
    } else {
      for (std::size_t r = 0; r < n; ++r, src += row_width, dst += width) {
        for (std::size_t c = 0; c < width; ++c) {
          const double value = src[c];
          if (!fits(value, column.dtype)) {
            std::ostringstream message;
            message.precision(17);
            message << context(column.path) << ": row " << (written + static_cast<std::int64_t>(r))
                    << " holds " << value << ", which is not an " << name_of(column.dtype);
            throw TraceError(message.str());
          }
          dst[c] = static_cast<T>(value);
        }
      }
    }
    data = out.data();
  };
  switch (column.dtype) {
    case DType::kFloat64: gather(scratch_f64); memory_type = H5T_NATIVE_DOUBLE; break;
    case DType::kInt64: gather(scratch_i64); memory_type = H5T_NATIVE_INT64; break;
    case DType::kInt32: gather(scratch_i32); memory_type = H5T_NATIVE_INT32; break;
    case DType::kInt8: gather(scratch_i8); memory_type = H5T_NATIVE_INT8; break;
    case DType::kUInt64: gather(scratch_u64); memory_type = H5T_NATIVE_UINT64; break;
  }

  // Grow the dataset and write the block into its new rows.
  const int rank = column.width == 1 ? 1 : 2;
  const hsize_t new_dims[2] = {static_cast<hsize_t>(written) + n, width};
  const hsize_t start[2] = {static_cast<hsize_t>(written), 0};
  const hsize_t count[2] = {n, width};
  if (H5Dset_extent(column.dataset.get(), new_dims) < 0) fail();

  h5::Handle file_space(H5Dget_space(column.dataset.get()), H5Sclose);
  if (!file_space.valid()) fail();
  if (H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr) < 0) {
    fail();
  }
  h5::Handle memory_space(H5Screate_simple(rank, count, nullptr), H5Sclose);
  if (!memory_space.valid()) fail();
  if (H5Dwrite(column.dataset.get(), memory_type, memory_space.get(), file_space.get(),
               H5P_DEFAULT, data) < 0) {
    fail();
  }
}

// ---------------------------------------------------------------------------------------------
// TraceWriter

struct TraceWriter::Impl {
  std::string path;
  TraceOptions options;
  h5::Handle file;
  h5::Handle root;
  FileState state;
  // Root attributes set after the first row, written by close() (name, writer), in call order.
  std::vector<std::pair<std::string, std::function<void(hid_t)>>> pending;
  // Ordered by name, so flush order (and the file's layout) does not depend on first use.
  std::map<std::string, std::unique_ptr<TraceTable>> tables;
  bool closed = false;

  std::string context() const { return "trace " + quoted(path); }
  void require_open() const {
    if (closed) throw TraceError(context() + ": used after close");
  }
  void set_root_attribute(const std::string& name, std::function<void(hid_t)> write);
};

TraceWriter::TraceWriter(const std::string& path, TraceOptions options)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->options = options;
  const std::string where = "cannot create trace " + quoted(path);
  if (options.block_rows < 1) throw TraceError(where + ": block_rows must be at least 1");
  if (options.compression < 0 || options.compression > 9) {
    throw TraceError(where + ": compression must be 0 (none) or a deflate level 1..9");
  }
  h5::Quiet quiet;
  h5::Handle fapl = file_access(options.swmr, where);
  impl_->file = h5::checked(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()),
                            H5Fclose, where);
  impl_->state.file = impl_->file.get();
  impl_->state.context = impl_->context();
  impl_->state.swmr = options.swmr;
  impl_->root = h5::checked(H5Gopen2(impl_->file.get(), "/", H5P_DEFAULT), H5Gclose, where);
  h5::write_string_attribute(impl_->root.get(), "status", "running", where);
  h5::check(H5Fflush(impl_->file.get(), H5F_SCOPE_LOCAL), where);
}

TraceWriter::~TraceWriter() {
  try {
    close("incomplete: writer destroyed without close");
  } catch (...) {
    // A destructor must not throw; close() has already released the file.
  }
}

TraceTable& TraceWriter::table(const std::string& group, std::size_t block_rows) {
  Impl& w = *impl_;
  w.require_open();
  const std::string name = !group.empty() && group.front() == '/' ? group.substr(1) : group;
  if (const auto found = w.tables.find(name); found != w.tables.end()) return *found->second;
  if (!is_relative_path(name)) {
    throw TraceError(w.context() + ": bad table name " + quoted(group));
  }
  if (w.state.frozen) {
    throw TraceError(w.context() + ": table " + quoted(group) + " created after the file's first row");
  }
  h5::Quiet quiet;
  const std::string where = w.context() + ": cannot create group " + quoted("/" + name);
  h5::Handle lcpl = h5::checked(H5Pcreate(H5P_LINK_CREATE), H5Pclose, where);
  h5::check(H5Pset_create_intermediate_group(lcpl.get(), 1), where);
  h5::Handle gcpl = untimed(H5P_GROUP_CREATE, where);
  auto impl = std::make_unique<TraceTable::Impl>();
  impl->file = &w.state;
  impl->file_path = w.path;
  impl->group_path = "/" + name;
  impl->options = w.options;
  impl->block_rows = block_rows > 0 ? block_rows : w.options.block_rows;
  impl->group = h5::checked(
      H5Gcreate2(w.root.get(), name.c_str(), lcpl.get(), gcpl.get(), H5P_DEFAULT), H5Gclose,
      where);
  auto table = std::unique_ptr<TraceTable>(new TraceTable(std::move(impl)));
  return *w.tables.emplace(name, std::move(table)).first->second;
}

void TraceWriter::Impl::set_root_attribute(const std::string& name,
                                           std::function<void(hid_t)> write) {
  require_open();
  if (!state.frozen) {
    h5::Quiet quiet;
    write(root.get());
    return;
  }
  // SWMR cannot add attributes: keep it (replacing one of the same name) for close().
  std::erase_if(pending, [&name](const auto& p) { return p.first == name; });
  pending.emplace_back(name, std::move(write));
}

void TraceWriter::set_attribute(const std::string& name, const std::string& value) {
  impl_->set_root_attribute(name, [name, value, context = impl_->context()](hid_t root) {
    h5::write_string_attribute(root, name, value, context);
  });
}

void TraceWriter::set_attribute(const std::string& name, double value) {
  impl_->set_root_attribute(name, [name, value, context = impl_->context()](hid_t root) {
    h5::write_scalar_attribute(root, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value, context);
  });
}

void TraceWriter::set_attribute(const std::string& name, std::int64_t value) {
  impl_->set_root_attribute(name, [name, value, context = impl_->context()](hid_t root) {
    h5::write_scalar_attribute(root, name, H5T_STD_I64LE, H5T_NATIVE_INT64, &value, context);
  });
}

void TraceWriter::flush() {
  impl_->require_open();
  h5::Quiet quiet;
  for (auto& [name, table] : impl_->tables) table->impl_->write_block();
  h5::check(H5Fflush(impl_->file.get(), H5F_SCOPE_LOCAL), impl_->context() + ": cannot flush");
}

void TraceWriter::close(const std::string& status) {
  Impl& w = *impl_;
  if (w.closed) return;
  w.closed = true;
  h5::Quiet quiet;
  std::string failure;
  for (auto& [name, table] : w.tables) {
    try {
      table->impl_->write_block();
    } catch (const TraceError& e) {
      if (failure.empty()) failure = e.what();
    }
  }
  // Every object of the file is closed before the file itself, so H5Fclose really closes it
  // (and ends SWMR writing, clearing the superblock's status flags).
  for (auto& [name, table] : w.tables) {
    table->impl_->closed = true;
    for (Column& column : table->impl_->columns) column.dataset.reset();
    table->impl_->group.reset();
  }
  w.root.reset();
  if (w.file.close() < 0 && failure.empty()) {
    failure = w.context() + ": cannot close: " + h5::last_error();
  }
  // Reopened without SWMR for what SWMR cannot write: the kept attributes and the status.
  try {
    const std::string where = w.context() + ": cannot reopen to write the status";
    h5::Handle fapl = file_access(w.options.swmr, where);
    h5::Handle file = h5::checked(H5Fopen(w.path.c_str(), H5F_ACC_RDWR, fapl.get()), H5Fclose, where);
    h5::Handle root = h5::checked(H5Gopen2(file.get(), "/", H5P_DEFAULT), H5Gclose, where);
    for (const auto& [name, write] : w.pending) {
      try {
        write(root.get());
      } catch (const TraceError& e) {
        if (failure.empty()) failure = e.what();
      }
    }
    h5::write_string_attribute(root.get(), "status",
                               failure.empty() ? status : "error: " + failure, w.context());
    root.reset();
    if (file.close() < 0) throw TraceError(w.context() + ": cannot close: " + h5::last_error());
  } catch (const TraceError& e) {
    if (failure.empty()) failure = e.what();
  }
  w.pending.clear();
  if (!failure.empty()) throw TraceError(failure);
}

bool TraceWriter::is_closed() const { return impl_->closed; }

const std::string& TraceWriter::path() const { return impl_->path; }

}  // namespace graspsim::recordings
