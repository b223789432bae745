// The writer's queue: every job that touches the file after its layout is frozen (append a
// block, flush, create the datasets) runs in submission order, inline or on one writer thread
// (TraceOptions::background; recordings/README.md "Writing" and "Cost").
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "graspsim/recordings/trace_writer.hpp"

namespace graspsim::recordings {
namespace writer {

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

}  // namespace writer

// Everything that touches the file after its layout is frozen goes through here, in the order
// it was submitted: inline (TraceOptions::background false) or on one writer thread. The
// simulation thread only fills blocks and hands them over (recordings/README.md "Cost").
class TraceWriterWorker {
 public:
  using Job = writer::Job;
  using Run = std::function<void(const Job&)>;   // does a job (on the writer thread)

  // `capacity`: the most jobs ever waiting (each block is in at most one, and flushes between
  // two blocks are merged), so the ring never grows after start().
  void start(bool thread, std::size_t capacity, Run run);

  // Hands a job over (runs it at once without a thread) and returns its ticket: the number of
  // jobs submitted up to it, for wait_for(). Rethrows a failure of an earlier job.
  std::uint64_t submit(const Job& job);

  // Hands jobs[0..n) over in order under one lock with one wake-up of the writer (a flush of
  // every table); returns the last one's ticket. Rethrows a failure of an earlier job.
  std::uint64_t submit_all(const Job* jobs, std::size_t n);

  // Waits until the job with this ticket (and every one before it) is done. Rethrows the first
  // failure.
  void wait_for(std::uint64_t ticket);

  // Waits until every job submitted so far is done. Rethrows the first failure.
  void drain();

  // Drains, then ends the thread. Never throws; the failure stays for failure().
  void stop() noexcept;

  std::exception_ptr failure();   // the first job's failure, or null
  void rethrow();                 // throws failure() if there is one

  // The mutex and condition the block pools share with the writer thread.
  std::mutex& mutex() { return mutex_; }
  std::condition_variable& returned() { return returned_; }

 private:
  void loop();

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

}  // namespace graspsim::recordings
