// TraceWriter and TraceTable: each table is one chunked HDF5 dataset of compound rows (one
// member per column), appended block by block (H5Dset_extent + hyperslab + one H5Dwrite per
// block), optionally by a background thread (recordings/README.md "Cost" and "Schema").
#include "graspsim/recordings/trace_writer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>
#include <type_traits>
#include <vector>

#include <sys/resource.h>

#include "disk_reserve.hpp"
#include "h5.hpp"

namespace graspsim::recordings {
namespace {

// Checks a relative path: non-empty components, none of them "." or "..", no leading '/'.
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

hid_t memory_type_of(DType dtype) {
  switch (dtype) {
    case DType::kFloat64: return H5T_NATIVE_DOUBLE;
    case DType::kInt64: return H5T_NATIVE_INT64;
    case DType::kInt32: return H5T_NATIVE_INT32;
    case DType::kInt8: return H5T_NATIVE_INT8;
    case DType::kUInt64: return H5T_NATIVE_UINT64;
  }
  return H5T_NATIVE_DOUBLE;
}

std::size_t size_of(DType dtype) {
  switch (dtype) {
    case DType::kFloat64: case DType::kInt64: case DType::kUInt64: return 8;
    case DType::kInt32: return 4;
    case DType::kInt8: return 1;
  }
  return 8;
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

// The largest compound row type a table may have: HDF5 stores a dataset's datatype in one object
// header message of at most 64 KiB (65535 bytes), kept clear of by 1.5 KB.
constexpr std::size_t kMaxRowTypeBytes = 64000;   // bytes

struct Column {
  std::string name;      // member name, relative to the table: "fingers/thumb/hip"
  int width;             // values per row
  DType dtype;
  std::size_t offset;    // doubles into a row of the block buffer
  std::size_t bytes;     // bytes into a packed compound row
};

// Consecutive 8-byte columns copied as they are (float64, and uint64 bits): one memcpy per row.
struct CopyRun {
  std::size_t offset;   // doubles into a row of the block buffer
  std::size_t bytes;    // bytes into a packed row
  std::size_t count;    // doubles
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

// A block of rows on its way to the file: `count` rows of a table, row-major doubles.
struct Block {
  TraceTable::Impl* table = nullptr;
  std::vector<double> rows;   // block_rows x row_width
  std::size_t count = 0;      // rows filled
};

// One piece of work for the file, done in submission order: append a block, flush, or (the
// first job) create every table's dataset and start SWMR writing.
struct Job {
  Block* block = nullptr;   // nullptr: H5Fflush, or the layout when `create` is set
  bool create = false;
};

}  // namespace

// Everything that touches the file after its layout is frozen goes through here, in the order
// it was submitted: inline (TraceOptions::background false) or on one writer thread. The
// simulation thread only fills blocks and hands them over (recordings/README.md "Cost").
class TraceWriterWorker {
 public:
  using Run = std::function<void(const Job&)>;   // does a job (on the writer thread)

  // `capacity`: the most jobs ever waiting (each block is in at most one, and flushes between
  // two blocks are merged), so the ring never grows after start().
  void start(bool thread, std::size_t capacity, Run run) {
    run_ = std::move(run);
    ring_.assign(capacity + 1, Job{});
    if (thread) worker_ = std::thread([this] { loop(); });   // may throw: then no thread
    threaded_ = thread;
  }

  // Hands a job over (runs it at once without a thread) and returns its ticket: the number of
  // jobs submitted up to it, for wait_for(). Rethrows a failure of an earlier job.
  std::uint64_t submit(const Job& job) {
    // A flush right after a flush (no block between them) adds nothing: dropped here, by the
    // order of submission alone, so the file's HDF5 calls never depend on the writer's timing.
    // Its ticket is the earlier flush's, which leaves the file in the same state.
    const bool flush = job.block == nullptr && !job.create;
    if (flush && last_was_flush_) {
      if (!threaded_) rethrow();
      return submitted_;
    }
    last_was_flush_ = flush;
    if (!threaded_) {
      rethrow();
      try {
        run_(job);
      } catch (...) {
        error_ = std::current_exception();
        throw;
      }
      done_ = ++submitted_;
      return submitted_;
    }
    std::unique_lock lock(mutex_);
    if (error_) std::rethrow_exception(error_);
    ring_[(head_ + size_) % ring_.size()] = job;
    ++size_;
    wake_.notify_one();
    return ++submitted_;
  }

  // Hands jobs[0..n) over in order under one lock with one wake-up of the writer (a flush of
  // every table); returns the last one's ticket. Rethrows a failure of an earlier job.
  std::uint64_t submit_all(const Job* jobs, std::size_t n) {
    if (!threaded_) {
      std::uint64_t ticket = submitted_;
      for (std::size_t i = 0; i < n; ++i) ticket = submit(jobs[i]);
      return ticket;
    }
    std::unique_lock lock(mutex_);
    if (error_) std::rethrow_exception(error_);
    for (std::size_t i = 0; i < n; ++i) {
      const bool flush = jobs[i].block == nullptr && !jobs[i].create;
      if (flush && last_was_flush_) continue;   // as in submit()
      last_was_flush_ = flush;
      ring_[(head_ + size_) % ring_.size()] = jobs[i];
      ++size_;
      ++submitted_;
    }
    wake_.notify_one();
    return submitted_;
  }

  // Waits until the job with this ticket (and every one before it) is done. Rethrows the first
  // failure.
  void wait_for(std::uint64_t ticket) {
    if (threaded_) {
      std::unique_lock lock(mutex_);
      done_cv_.wait(lock, [this, ticket] { return done_ >= ticket || error_; });
    }
    rethrow();
  }

  // Waits until every job submitted so far is done. Rethrows the first failure.
  void drain() {
    if (threaded_) {
      std::unique_lock lock(mutex_);
      idle_.wait(lock, [this] { return size_ == 0 && !busy_; });
    }
    rethrow();
  }

  // Drains, then ends the thread. Never throws; the failure stays for failure().
  void stop() noexcept {
    if (threaded_) {
      {
        std::unique_lock lock(mutex_);
        idle_.wait(lock, [this] { return size_ == 0 && !busy_; });
        stopping_ = true;
      }
      wake_.notify_one();
      if (worker_.joinable()) worker_.join();
      threaded_ = false;
    }
  }

  std::exception_ptr failure() {
    std::lock_guard lock(mutex_);
    return error_;
  }
  void rethrow() {
    std::exception_ptr e = failure();
    if (e) std::rethrow_exception(e);
  }

  // The mutex and condition the block pools share with the writer thread.
  std::mutex& mutex() { return mutex_; }
  std::condition_variable& returned() { return returned_; }

 private:
  void loop() {
    std::unique_lock lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return size_ > 0 || stopping_; });
      if (size_ == 0 && stopping_) return;
      const Job job = ring_[head_];
      busy_ = true;
      lock.unlock();
      std::exception_ptr failed;
      try {
        run_(job);
      } catch (...) {
        failed = std::current_exception();
      }
      lock.lock();
      if (failed && !error_) error_ = failed;
      head_ = (head_ + 1) % ring_.size();
      --size_;
      ++done_;
      busy_ = false;
      done_cv_.notify_all();
      if (size_ == 0) idle_.notify_all();
    }
  }

  Run run_;
  std::vector<Job> ring_;
  std::size_t head_ = 0, size_ = 0;
  bool threaded_ = false, busy_ = false, stopping_ = false;
  bool last_was_flush_ = false;   // the last job submitted was a flush (submitting thread only)
  std::uint64_t submitted_ = 0;   // jobs submitted (submitting thread only)
  std::uint64_t done_ = 0;        // jobs done, failed ones included (guarded by mutex_)
  std::exception_ptr error_;
  std::mutex mutex_;
  std::condition_variable wake_, idle_, returned_, done_cv_;
  std::thread worker_;
};

// What the writer and its tables share about the file.
struct TraceFileState {
  hid_t file = H5I_INVALID_HID;   // not owned (TraceWriter::Impl::file)
  TraceOptions options;
  bool frozen = false;            // a row was appended: no new table, column or attribute
  std::function<void()> freeze;   // TraceWriter::Impl::freeze
  TraceWriterWorker worker;
};

// ---------------------------------------------------------------------------------------------
// TraceTable

struct TraceTable::Impl {
  std::string file_path;
  std::string name;              // dataset path without the leading '/': "servo"
  std::size_t block_rows = 0;    // rows per block, and rows per chunk
  TraceFileState* file = nullptr;   // owned by the writer
  std::vector<Column> columns;
  std::vector<std::pair<std::string, std::string>> attributes;   // name, value; in call order
  std::size_t row_width = 0;     // doubles per row
  std::size_t packed_width = 0;  // bytes per compound row
  bool closed = false;           // the writer closed the file

  // Simulation side (after the first row): the block being filled and the free ones.
  std::vector<std::unique_ptr<Block>> blocks;   // all of them (owned)
  std::vector<Block*> free_blocks;              // guarded by the worker's mutex
  Block* current = nullptr;
  std::int64_t rows = 0;         // rows appended
  bool started = false;          // append_row was called

  // Writer side.
  h5::Handle dataset;
  h5::Handle memory_type;        // the compound row in memory (native types, packed)
  std::vector<CopyRun> runs;     // the 8-byte columns, merged where adjacent
  std::vector<const Column*> integers;   // the columns converted and checked one by one
  bool direct = false;           // whole chunks go to the file as they are (H5Dwrite_chunk)
  std::vector<unsigned char> packed;   // block_rows x packed_width
  std::int64_t written = 0;      // rows handed to HDF5 (in the file once it is flushed)
  std::int64_t durable = 0;      // rows written before the last successful H5Fflush: on disk

  std::string context() const { return "trace " + quoted(file_path); }
  std::string column_context(const std::string& column) const {
    return context() + ", column " + quoted("/" + name + "/" + column);
  }
  void require_open() const {
    if (closed) throw TraceError(context() + ": table " + quoted("/" + name) + " used after close");
  }
  void allocate();                      // at freeze: the blocks (simulation side)
  void create_dataset(hid_t file_id);   // the first job, before SWMR starts (writer side)
  void write_block(Block& block);       // writer side
  void hand_over();                     // simulation side: current block to the worker
  Block* take_free_block();
};

TraceTable::TraceTable(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TraceTable::~TraceTable() = default;

std::size_t TraceTable::add_column(const std::string& path, int width, DType dtype,
                                   const std::string& units) {
  Impl& t = *impl_;
  t.require_open();
  if (t.started || t.file->frozen) {
    throw TraceError(t.column_context(path) + ": add_column after the first row of " +
                     quoted("/" + t.name) + " or of the file");
  }
  if (!is_relative_path(path)) {
    throw TraceError(t.column_context(path) + ": column path must be relative, like 'fingers/a/hip'");
  }
  if (width < 1) throw TraceError(t.column_context(path) + ": width must be at least 1");
  for (const Column& c : t.columns) {
    if (c.name == path) throw TraceError(t.column_context(path) + ": column declared twice");
    // Column paths form a tree, as datasets in groups would (schema 2): "a" and "a/b" cannot both
    // be columns, or "/t/a" would name both a column and a group of columns.
    if (c.name.rfind(path + "/", 0) == 0 || path.rfind(c.name + "/", 0) == 0) {
      throw TraceError(t.column_context(path) + ": column path clashes with column " +
                       quoted(c.name) + " (one would be a group of the other)");
    }
  }
  const std::size_t offset = t.row_width;
  t.columns.push_back(Column{path, width, dtype, offset, t.packed_width});
  t.row_width += static_cast<std::size_t>(width);
  t.packed_width += static_cast<std::size_t>(width) * size_of(dtype);
  t.attributes.emplace_back(path + "/units", units);
  return offset;
}

Block* TraceTable::Impl::take_free_block() {
  std::unique_lock lock(file->worker.mutex());
  // A full pool means the writer is behind: wait for it (back-pressure) rather than grow.
  file->worker.returned().wait(lock, [this] { return !free_blocks.empty(); });
  Block* block = free_blocks.back();
  free_blocks.pop_back();
  block->count = 0;
  return block;
}

void TraceTable::Impl::hand_over() {
  if (current == nullptr || current->count == 0) return;
  // If the writer has failed, submit rethrows and the block stays current (its rows unwritten).
  file->worker.submit(Job{current});
  current = take_free_block();
}

double* TraceTable::append_row() {
  Impl& t = *impl_;
  t.require_open();
  if (!t.started) {
    if (!t.file->frozen) t.file->freeze();
    t.started = true;
  }
  if (t.current->count == t.block_rows) {
    t.hand_over();
    // Metadata too, so that a run cut short leaves a readable file up to this block.
    t.file->worker.submit(Job{nullptr});
  }
  double* row = t.current->rows.data() + t.current->count * t.row_width;
  ++t.current->count;
  ++t.rows;
  return row;
}

std::size_t TraceTable::row_width() const { return impl_->row_width; }

std::int64_t TraceTable::rows() const { return impl_->rows; }

void TraceTable::flush() {
  impl_->require_open();
  if (!impl_->started) return;
  impl_->hand_over();
  impl_->file->worker.drain();
}

void TraceTable::set_attribute(const std::string& dataset_or_dot, const std::string& name,
                               const std::string& value) {
  Impl& t = *impl_;
  t.require_open();
  const std::string full = dataset_or_dot == "." ? "/" + t.name : "/" + t.name + "/" + dataset_or_dot;
  if (t.file->frozen) {
    throw TraceError(t.context() + ", object " + quoted(full) + ": attribute '" + name +
                     "' after the file's first row");
  }
  if (name.empty() || name.find('/') != std::string::npos) {
    throw TraceError(t.context() + ", object " + quoted(full) + ": bad attribute name " + quoted(name));
  }
  std::string key = name;
  if (dataset_or_dot != ".") {
    // A column, or a prefix of columns ("fingers/thumb"), as a group was in schema 2.
    const bool known = std::any_of(t.columns.begin(), t.columns.end(), [&](const Column& c) {
      return c.name == dataset_or_dot || c.name.rfind(dataset_or_dot + "/", 0) == 0;
    });
    if (!known) throw TraceError(t.context() + ": no column " + quoted(full));
    key = dataset_or_dot + "/" + name;
  }
  std::erase_if(t.attributes, [&key](const auto& a) { return a.first == key; });
  t.attributes.emplace_back(key, value);
}

// The compound type of a row: one member per column in declaration order, packed; array
// members for width > 1.
static h5::Handle row_type(const std::vector<Column>& columns, std::size_t bytes, bool memory,
                           const std::string& where) {
  h5::Handle type = h5::checked(H5Tcreate(H5T_COMPOUND, bytes), H5Tclose, where);
  for (const Column& c : columns) {
    const hid_t base = memory ? memory_type_of(c.dtype) : file_type_of(c.dtype);
    if (c.width == 1) {
      h5::check(H5Tinsert(type.get(), c.name.c_str(), c.bytes, base), where);
    } else {
      const hsize_t dims[1] = {static_cast<hsize_t>(c.width)};
      h5::Handle array = h5::checked(H5Tarray_create2(base, 1, dims), H5Tclose, where);
      h5::check(H5Tinsert(type.get(), c.name.c_str(), c.bytes, array.get()), where);
    }
  }
  return type;
}

void TraceTable::Impl::create_dataset(hid_t file_id) {
  const std::string where = context() + ": cannot create table " + quoted("/" + name);
  if (columns.empty()) throw TraceError(where + ": it has no columns");
  h5::Handle file_type = row_type(columns, packed_width, false, where);
  memory_type = row_type(columns, packed_width, true, where);
  // A whole chunk is written straight to the file, past the chunk cache (a copy and its
  // bookkeeping saved), when the packed rows are the file's bytes: no filter, no conversion.
  const htri_t same = H5Tequal(file_type.get(), memory_type.get());
  h5::check(same, where);
  direct = same > 0 && file->options.compression == 0;
  runs.clear();
  integers.clear();
  for (const Column& c : columns) {
    if (c.dtype == DType::kFloat64 || c.dtype == DType::kUInt64) {
      const std::size_t w = static_cast<std::size_t>(c.width);
      if (!runs.empty() && runs.back().offset + runs.back().count == c.offset &&
          runs.back().bytes + 8 * runs.back().count == c.bytes) {
        runs.back().count += w;
      } else {
        runs.push_back(CopyRun{c.offset, c.bytes, w});
      }
    } else {
      integers.push_back(&c);
    }
  }
  // Shape (0,), unlimited rows, one chunk per block.
  const hsize_t dims[1] = {0};
  const hsize_t max_dims[1] = {H5S_UNLIMITED};
  const hsize_t chunk[1] = {static_cast<hsize_t>(block_rows)};
  h5::Handle space = h5::checked(H5Screate_simple(1, dims, max_dims), H5Sclose, where);
  h5::Handle dcpl = untimed(H5P_DATASET_CREATE, where);
  // The column attributes (a hundred or so) stay in the object header: compact storage is several
  // times cheaper to create than the dense storage (fractal heap + B-tree) that the newest file
  // format switches to after 8.
  const unsigned compact = static_cast<unsigned>(std::min<std::size_t>(attributes.size() + 8, 1000));
  h5::check(H5Pset_attr_phase_change(dcpl.get(), compact, compact > 8 ? compact - 8 : 0), where);
  h5::check(H5Pset_chunk(dcpl.get(), 1, chunk), where);
  // Every row is written before it is read: no fill values (they cost a memset of each new chunk).
  h5::check(H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER), where);
  if (file->options.compression > 0) {
    // Byte shuffle first: with a compound element it groups the k-th byte of every row, so
    // each column's slowly changing high bytes sit together for deflate.
    h5::check(H5Pset_shuffle(dcpl.get()), where);
    h5::check(H5Pset_deflate(dcpl.get(), static_cast<unsigned>(file->options.compression)), where);
  }
  h5::Handle lcpl = h5::checked(H5Pcreate(H5P_LINK_CREATE), H5Pclose, where);
  h5::check(H5Pset_create_intermediate_group(lcpl.get(), 1), where);
  dataset = h5::checked(H5Dcreate2(file_id, ("/" + name).c_str(), file_type.get(), space.get(),
                                   lcpl.get(), dcpl.get(), H5P_DEFAULT),
                        H5Dclose, where);
  // Sorted by name, so the file does not depend on the order attributes were set in.
  std::vector<std::pair<std::string, std::string>> sorted = attributes;
  std::sort(sorted.begin(), sorted.end());
  for (const auto& [key, value] : sorted) {
    h5::create_string_attribute(dataset.get(), key, value, context() + ", table " + quoted("/" + name));
  }
  packed.assign(block_rows * packed_width, 0);
}

// Everything the table will ever need, allocated once: a few blocks so the simulation can fill
// one while the writer thread writes others.
void TraceTable::Impl::allocate() {
  const std::size_t pool = file->options.background ? 4 : 1;
  for (std::size_t k = 0; k < pool; ++k) {
    auto block = std::make_unique<Block>();
    block->table = this;
    block->rows.assign(block_rows * row_width, 0.0);
    free_blocks.push_back(block.get());
    blocks.push_back(std::move(block));
  }
  current = free_blocks.back();
  free_blocks.pop_back();
}

// Packs the block's rows into compound rows (checking integer columns) and appends them.
// Allocates nothing on success (messages are built only on failure); HDF5 mallocs its own.
void TraceTable::Impl::write_block(Block& block) {
  const std::size_t n = block.count;
  for (std::size_t r = 0; r < n; ++r) {
    const double* src = block.rows.data() + r * row_width;
    unsigned char* dst = packed.data() + r * packed_width;
    for (const CopyRun& run : runs) std::memcpy(dst + run.bytes, src + run.offset, 8 * run.count);
    for (const Column* column : integers) {
      const Column& c = *column;
      const double* in = src + c.offset;
      unsigned char* out = dst + c.bytes;
      for (std::size_t k = 0; k < static_cast<std::size_t>(c.width); ++k) {
        const double value = in[k];
        if (!fits(value, c.dtype)) {
          std::ostringstream message;
          message.precision(17);
          message << column_context(c.name) << ": row " << (written + static_cast<std::int64_t>(r))
                  << " holds " << value << ", which is not an " << name_of(c.dtype);
          throw TraceError(message.str());
        }
        if (c.dtype == DType::kInt64) {
          const std::int64_t v = static_cast<std::int64_t>(value);
          std::memcpy(out + 8 * k, &v, 8);
        } else if (c.dtype == DType::kInt32) {
          const std::int32_t v = static_cast<std::int32_t>(value);
          std::memcpy(out + 4 * k, &v, 4);
        } else {
          const std::int8_t v = static_cast<std::int8_t>(value);
          std::memcpy(out + k, &v, 1);
        }
      }
    }
  }
  auto fail = [&]() {
    throw TraceError(context() + ", table " + quoted("/" + name) + ": cannot append rows: " +
                     h5::last_error());
  };
  const hsize_t new_dims[1] = {static_cast<hsize_t>(written) + n};
  const hsize_t start[1] = {static_cast<hsize_t>(written)};
  const hsize_t count[1] = {n};
  if (H5Dset_extent(dataset.get(), new_dims) < 0) fail();
  if (direct && n == block_rows && static_cast<std::size_t>(written) % block_rows == 0) {
    // Exactly one whole chunk (the runner's blocks are its chunks): its bytes as they are.
    if (H5Dwrite_chunk(dataset.get(), H5P_DEFAULT, 0, start, n * packed_width, packed.data()) < 0) fail();
    written += static_cast<std::int64_t>(n);
    return;
  }
  h5::Handle file_space(H5Dget_space(dataset.get()), H5Sclose);
  if (!file_space.valid()) fail();
  if (H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr) < 0) {
    fail();
  }
  h5::Handle memory_space(H5Screate_simple(1, count, nullptr), H5Sclose);
  if (!memory_space.valid()) fail();
  if (H5Dwrite(dataset.get(), memory_type.get(), memory_space.get(), file_space.get(),
               H5P_DEFAULT, packed.data()) < 0) {
    fail();
  }
  written += static_cast<std::int64_t>(n);
}

// ---------------------------------------------------------------------------------------------
// TraceWriter

struct TraceWriter::Impl {
  std::string path;
  TraceOptions options;
  h5::Handle file;
  h5::Handle root;
  TraceFileState state;
  // Root attributes set after the first row, written by close() (name, writer), in call order.
  std::vector<std::pair<std::string, std::function<void(hid_t)>>> pending;
  // Ordered by name, so the file's layout does not depend on first use.
  std::map<std::string, std::unique_ptr<TraceTable>> tables;
  std::vector<Job> flush_jobs;   // flush()'s hand-over, one per table and the flush
  DiskReserve reserve;   // given back at close(), for what closing writes
  hsize_t size_limit = 0;   // bytes: the process's file size limit (RLIMIT_FSIZE), 0 for none
  bool closed = false;
  bool marked = false;   // close() wrote the final status

  std::string context() const { return "trace " + quoted(path); }
  void require_open() const {
    if (closed) throw TraceError(context() + ": used after close");
  }
  void set_root_attribute(const std::string& name, std::function<void(hid_t)> write);
  std::string cut_to_last_flush(hid_t file_id);
  void freeze();
  void run(const Job& job);   // on the writer thread (or inline)
};

// The first row of any table freezes the layout: blocks are allocated here; the first job then
// creates every table's dataset and starts SWMR writing (on the writer thread, if there is one:
// it costs a few milliseconds), and from here on only the worker touches the file.
void TraceWriter::Impl::freeze() {
  std::size_t blocks = 0;
  {
    // Checked here, before the writer thread exists, so a table HDF5 cannot store fails at the
    // first row, not at close: a compound type is stored in one object header message, at most
    // 64 KiB (about 90 objects of /physics with short names).
    h5::Lock lock;
    h5::Quiet quiet;
    for (auto& [name, table] : tables) {
      TraceTable::Impl& t = *table->impl_;
      const std::string where = context() + ": cannot create table " + quoted("/" + name);
      if (t.columns.empty()) throw TraceError(where + ": it has no columns");
      // The datatype message's size in the newest format (version 3 compound and array
      // types, as the file uses): an 8-byte type header, and per member its name with a NUL,
      // a 4-byte offset (at most), an array header of 8 + 1 + 4 bytes if width > 1, and the
      // element type, 20 bytes for a float, 12 for an integer. (H5Tencode would give the
      // oldest format's size, which pads names: 40% more.)
      std::size_t encoded = 8;
      for (const Column& c : t.columns) {
        encoded += c.name.size() + 1 + 4 + (c.width > 1 ? 13 : 0) + (c.dtype == DType::kFloat64 ? 20 : 12);
      }
      if (encoded > kMaxRowTypeBytes) {
        throw TraceError(where + ": its " + std::to_string(t.columns.size()) + " columns need a " +
                         std::to_string(encoded) + "-byte HDF5 row type, more than the " +
                         std::to_string(kMaxRowTypeBytes) +
                         " an object header holds (fewer objects or fingers, or shorter names)");
      }
    }
  }
  for (auto& [name, table] : tables) {
    table->impl_->allocate();
    blocks += table->impl_->blocks.size();
  }
  flush_jobs.reserve(tables.size() + 1);
  state.frozen = true;
  state.worker.start(options.background, 2 * blocks + 3, [this](const Job& job) { run(job); });
  state.worker.submit(Job{nullptr, true});
}

void TraceWriter::Impl::run(const Job& job) {
  h5::Lock lock;
  h5::Quiet quiet;
  if (job.create) {
    for (auto& [name, table] : tables) table->impl_->create_dataset(file.get());
    if (options.swmr && H5Fstart_swmr_write(file.get()) < 0) {
      throw TraceError(context() + ": cannot start SWMR writing: " + h5::last_error());
    }
    return;
  }
  if (job.block == nullptr) {
    if (state.worker.failure()) return;   // after a failure nothing more reaches the file
    if (H5Fflush(file.get(), H5F_SCOPE_LOCAL) < 0) {
      throw TraceError(context() + ": cannot flush: " + h5::last_error());
    }
    for (auto& [name, table] : tables) table->impl_->durable = table->impl_->written;
    return;
  }
  Block& block = *job.block;
  TraceTable::Impl& table = *block.table;
  // The block goes back to its pool whatever happens, so the simulation never waits forever.
  struct GiveBack {
    TraceFileState& state;
    TraceTable::Impl& table;
    Block& block;
    ~GiveBack() {
      {
        std::lock_guard guard(state.worker.mutex());
        table.free_blocks.push_back(&block);
      }
      state.worker.returned().notify_all();
    }
  } give_back{state, table, block};
  if (state.worker.failure()) return;   // after a failure, later rows are not written
  if (size_limit > 0) {
    // A write past RLIMIT_FSIZE fails with EFBIG, and then closing could not write either: stop
    // short of it by the reserve's size, as a full disk stops the writer with the reserve held.
    hsize_t size = 0;
    const hsize_t bytes = static_cast<hsize_t>(block.count * table.packed_width);
    if (H5Fget_filesize(file.get(), &size) >= 0 && size + bytes + options.reserve_bytes > size_limit) {
      throw TraceError(context() + ", table " + quoted("/" + table.name) + ": cannot append rows: the file would pass " +
                       std::to_string(size_limit) + " bytes, this process's file size limit (ulimit -f), less " +
                       std::to_string(options.reserve_bytes) + " kept for closing it");
    }
  }
  table.write_block(block);
}

TraceWriter::TraceWriter(const std::string& path, TraceOptions options)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->options = options;
  const std::string where = "cannot create trace " + quoted(path);
  if (options.block_rows < 1) throw TraceError(where + ": block_rows must be at least 1");
  if (options.compression < 0 || options.compression > 9) {
    throw TraceError(where + ": compression must be 0 (none) or a deflate level 1..9");
  }
  h5::Lock lock;
  h5::Quiet quiet;
  // On failure the handles made so far are closed here, under the lock (not after it, as the
  // members' destructors would).
  struct Release {
    Impl* impl;
    ~Release() {
      if (impl != nullptr) {
        impl->root.reset();
        impl->file.reset();
      }
    }
  } release{impl_.get()};
  h5::Handle fapl = file_access(options.swmr, where);
  // The root group too is created without time stamps (the file creation list is an object
  // creation list): with them, two runs' files differed in the root's header whenever they
  // started in different seconds.
  h5::Handle fcpl = untimed(H5P_FILE_CREATE, where);
  impl_->file = h5::checked(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()),
                            H5Fclose, where);
  impl_->state.file = impl_->file.get();
  impl_->state.options = options;
  impl_->state.freeze = [impl = impl_.get()] { impl->freeze(); };
  impl_->root = h5::checked(H5Gopen2(impl_->file.get(), "/", H5P_DEFAULT), H5Gclose, where);
  h5::write_string_attribute(impl_->root.get(), "status", "running", where);
  h5::check(H5Fflush(impl_->file.get(), H5F_SCOPE_LOCAL), where);
  release.impl = nullptr;
  const std::string directory = std::filesystem::path(path).parent_path().string();
  impl_->reserve = DiskReserve(directory.empty() ? "." : directory, options.reserve_bytes);
  struct rlimit limit{};
  if (getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    impl_->size_limit = static_cast<hsize_t>(limit.rlim_cur);
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
  for (const auto& [other, table] : w.tables) {
    if (name.rfind(other + "/", 0) == 0 || other.rfind(name + "/", 0) == 0) {
      throw TraceError(w.context() + ": table " + quoted("/" + name) + " would nest in table " +
                       quoted("/" + other));
    }
  }
  auto impl = std::make_unique<TraceTable::Impl>();
  impl->file = &w.state;
  impl->file_path = w.path;
  impl->name = name;
  impl->block_rows = block_rows > 0 ? block_rows : w.options.block_rows;
  auto table = std::unique_ptr<TraceTable>(new TraceTable(std::move(impl)));
  return *w.tables.emplace(name, std::move(table)).first->second;
}

void TraceWriter::Impl::set_root_attribute(const std::string& name,
                                           std::function<void(hid_t)> write) {
  require_open();
  if (!state.frozen) {
    h5::Lock lock;
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

std::uint64_t TraceWriter::flush() {
  Impl& w = *impl_;
  w.require_open();
  if (!w.state.frozen) {
    h5::Lock lock;
    h5::Quiet quiet;
    h5::check(H5Fflush(w.file.get(), H5F_SCOPE_LOCAL), w.context() + ": cannot flush");
    return 0;
  }
  if (!w.options.background) {
    // Inline: each block is written as it is handed over (a table's only block comes back).
    for (auto& [name, table] : w.tables) {
      if (table->impl_->started) table->impl_->hand_over();
    }
    return w.state.worker.submit(Job{nullptr});
  }
  // Every table's block, then the flush, handed over together: one wake-up of the writer. A
  // table takes its next block first (from a pool of 4, the writer returns them as it goes).
  std::vector<Job>& jobs = w.flush_jobs;   // sized at freeze: no allocation here
  jobs.clear();
  for (auto& [name, table] : w.tables) {
    TraceTable::Impl& t = *table->impl_;
    if (!t.started || t.current == nullptr || t.current->count == 0) continue;
    jobs.push_back(Job{t.current});
    t.current = t.take_free_block();
  }
  jobs.push_back(Job{nullptr});
  return w.state.worker.submit_all(jobs.data(), jobs.size());
}

void TraceWriter::wait() {
  impl_->require_open();
  if (impl_->state.frozen) impl_->state.worker.drain();
}

void TraceWriter::wait(std::uint64_t ticket) {
  impl_->require_open();
  if (impl_->state.frozen) impl_->state.worker.wait_for(ticket);
}

void TraceWriter::close(const std::string& status) {
  Impl& w = *impl_;
  if (w.closed) return;
  w.closed = true;
  std::string failure;
  if (!w.state.frozen && !w.tables.empty()) {
    // No row was ever appended: the tables are still created, with 0 rows.
    try {
      w.freeze();
    } catch (const TraceError& e) {
      failure = e.what();
    }
  }
  if (w.state.frozen) {
    for (auto& [name, table] : w.tables) {
      try {
        if (table->impl_->started) table->impl_->hand_over();
      } catch (const TraceError& e) {
        if (failure.empty()) failure = e.what();
      } catch (...) {
      }
    }
    w.state.worker.stop();
    if (const std::exception_ptr e = w.state.worker.failure(); e && failure.empty()) {
      try {
        std::rethrow_exception(e);
      } catch (const std::exception& error) {
        failure = error.what();
      } catch (...) {
        failure = w.context() + ": unknown failure while writing";
      }
    }
  }
  // The room set aside for this moment goes back to the file system: what follows writes
  // metadata and attributes even when the disk is full.
  w.reserve.release();
  h5::Lock lock;
  h5::Quiet quiet;
  // After a failure, rows past the last successful flush may be only partly on disk: every
  // table is cut back to its last flush, so the file holds nothing it cannot vouch for.
  std::string kept;
  if (!failure.empty() && w.state.frozen) kept = w.cut_to_last_flush(w.file.get());
  // Every object of the file is closed before the file itself, so H5Fclose really closes it
  // (and ends SWMR writing, clearing the superblock's status flags).
  for (auto& [name, table] : w.tables) {
    table->impl_->closed = true;
    table->impl_->dataset.reset();
    table->impl_->memory_type.reset();
  }
  w.root.reset();
  if (w.file.close() < 0) {
    // HDF5 1.10 frees a file whose close failed but keeps its identifier (h5.cpp: the library is
    // then never shut down at exit, which would close it again): nothing more is done with it.
    if (failure.empty()) failure = w.context() + ": cannot close: " + h5::last_error();
    w.pending.clear();
    throw TraceError(failure + (kept.empty() ? "" : "; " + kept) +
                     "; its status could not be written (it says \"running\": graspsim repair " + w.path + ")");
  }
  // Reopened without SWMR for what SWMR cannot write: the kept attributes and the status.
  bool marked = false;
  try {
    const std::string where = w.context() + ": cannot reopen to write the status";
    h5::Handle fapl = file_access(w.options.swmr, where);
    // A SWMR reader (h5py following the run) holds the file's lock: without this the reopen
    // fails and the status stays "running". The reader sees the final attributes on reopening.
    h5::check(H5Pset_file_locking(fapl.get(), 0, 1), where);
    h5::Handle file = h5::checked(H5Fopen(w.path.c_str(), H5F_ACC_RDWR, fapl.get()), H5Fclose, where);
    if (!failure.empty() && kept.empty() && w.state.frozen) kept = w.cut_to_last_flush(file.get());
    h5::Handle root = h5::checked(H5Gopen2(file.get(), "/", H5P_DEFAULT), H5Gclose, where);
    for (const auto& [name, write] : w.pending) {
      try {
        write(root.get());
      } catch (const TraceError& e) {
        if (failure.empty()) failure = e.what();
      }
    }
    const std::string text = failure + (kept.empty() ? "" : "; " + kept);
    h5::write_string_attribute(root.get(), "status", failure.empty() ? status : "error: " + text, w.context());
    root.reset();
    if (file.close() < 0) throw TraceError(w.context() + ": cannot close: " + h5::last_error());
    marked = true;
    w.marked = true;
  } catch (const TraceError& e) {
    if (failure.empty()) failure = e.what();
  }
  w.pending.clear();
  if (!failure.empty()) {
    throw TraceError(failure + (kept.empty() ? "" : "; " + kept) +
                     (marked ? "" : "; its status could not be written (graspsim repair " + w.path + ")"));
  }
}

// Sets every table's extent back to the rows of its last successful flush (H5Fflush), and says
// what is kept: "kept up to the last flush: /haptic 240 rows, /physics 24 rows, /servo 1440 rows".
// A table that cannot be cut is named with its rows as they are.
std::string TraceWriter::Impl::cut_to_last_flush(hid_t file_id) {
  std::string kept;
  bool cut = true;
  for (auto& [name, table] : tables) {
    TraceTable::Impl& t = *table->impl_;
    const hsize_t rows[1] = {static_cast<hsize_t>(t.durable)};
    h5::Handle opened;
    hid_t dataset = t.dataset.get();
    if (!t.dataset.valid()) {
      opened = h5::Handle(H5Dopen2(file_id, ("/" + name).c_str(), H5P_DEFAULT), H5Dclose);
      dataset = opened.get();
    }
    if (dataset < 0 || H5Dset_extent(dataset, rows) < 0) cut = false;
    kept += (kept.empty() ? "" : ", ") + quoted("/" + name) + " " + std::to_string(t.durable) + " rows";
  }
  if (!cut) return "";   // tried again after reopening without SWMR
  return "kept up to the last flush: " + kept;
}

bool TraceWriter::is_closed() const { return impl_->closed; }

bool TraceWriter::marked() const { return impl_->marked; }

const std::string& TraceWriter::path() const { return impl_->path; }

}  // namespace graspsim::recordings
