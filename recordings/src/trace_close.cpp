// TraceWriter::close: the last rows, the kept root attributes and the final status; after a
// failed write, every table cut back to its last flush (recordings/README.md "Crash safety").
#include "trace_writer_impl.hpp"

namespace graspsim::recordings {

using namespace writer;

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

}  // namespace graspsim::recordings
