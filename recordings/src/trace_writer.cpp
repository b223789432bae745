// TraceWriter: the file, its tables and root attributes, and the jobs that reach the file
// after its layout is frozen (appended blocks, flushes). Each table is one chunked HDF5 dataset
// of compound rows (trace_table.cpp, table_dataset.cpp); closing is in trace_close.cpp
// (recordings/README.md "Writing" and "Crash safety").
#include <filesystem>

#include <sys/resource.h>

#include "trace_writer_impl.hpp"

namespace graspsim::recordings {
namespace writer {

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

}  // namespace writer

using namespace writer;

// The first row of any table freezes the layout: blocks are allocated here; the first job then
// creates every table's dataset and starts SWMR writing (on the writer thread, if there is one:
// it costs a few milliseconds), and from here on only the worker touches the file.
void TraceWriter::Impl::freeze() {
  std::size_t blocks = 0;
  {
    // Checked here, before the writer thread exists, so a table HDF5 cannot store fails at the
    // first row, not at close: a compound type is stored in one object header message, at most
    // 64 KiB (a group counts once, however many entities it has), and a chunk holds less than
    // 4 GiB.
    h5::Lock lock;
    h5::Quiet quiet;
    for (auto& [name, table] : tables) {
      TraceTable::Impl& t = *table->impl_;
      const std::string where = context() + ": cannot create table " + quoted("/" + name);
      if (t.columns.empty()) throw TraceError(where + ": it has no columns");
      const std::size_t encoded = encoded_row_type_bytes(t.columns, t.groups);
      if (encoded > kMaxRowTypeBytes) {
        throw TraceError(where + ": its " + std::to_string(t.columns.size()) + " columns need a " +
                         std::to_string(encoded) + "-byte HDF5 row type, more than the " +
                         std::to_string(kMaxRowTypeBytes) +
                         " an object header holds (fewer columns, or shorter names)");
      }
      if (t.packed_width > kMaxChunkBytes / t.block_rows) {
        throw TraceError(where + ": a chunk of " + std::to_string(t.block_rows) + " rows of " +
                         std::to_string(t.packed_width) + " bytes is more than HDF5's chunk limit of " +
                         std::to_string(kMaxChunkBytes) + " bytes (4 GiB - 1)");
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

bool TraceWriter::is_closed() const { return impl_->closed; }

bool TraceWriter::marked() const { return impl_->marked; }

const std::string& TraceWriter::path() const { return impl_->path; }

}  // namespace graspsim::recordings
