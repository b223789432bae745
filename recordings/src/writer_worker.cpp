// TraceWriterWorker: the writer's job queue, inline or on one thread.
#include "writer_worker.hpp"

#include <utility>

namespace graspsim::recordings {

void TraceWriterWorker::start(bool thread, std::size_t capacity, Run run) {
  run_ = std::move(run);
  ring_.assign(capacity + 1, Job{});
  if (thread) worker_ = std::thread([this] { loop(); });   // may throw: then no thread
  threaded_ = thread;
}

std::uint64_t TraceWriterWorker::submit(const Job& job) {
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

std::uint64_t TraceWriterWorker::submit_all(const Job* jobs, std::size_t n) {
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

void TraceWriterWorker::wait_for(std::uint64_t ticket) {
  if (threaded_) {
    std::unique_lock lock(mutex_);
    done_cv_.wait(lock, [this, ticket] { return done_ >= ticket || error_; });
  }
  rethrow();
}

void TraceWriterWorker::drain() {
  if (threaded_) {
    std::unique_lock lock(mutex_);
    idle_.wait(lock, [this] { return size_ == 0 && !busy_; });
  }
  rethrow();
}

void TraceWriterWorker::stop() noexcept {
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

std::exception_ptr TraceWriterWorker::failure() {
  std::lock_guard lock(mutex_);
  return error_;
}

void TraceWriterWorker::rethrow() {
  std::exception_ptr e = failure();
  if (e) std::rethrow_exception(e);
}

void TraceWriterWorker::loop() {
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

}  // namespace graspsim::recordings
