// What a trace keeps when writing it fails, and how far behind the writer thread may be: the
// rows of the last successful flush, no more and no less, and a flush ticket that is on disk
// once wait(ticket) returns, however slow the writer.
#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "tests/support/library.hpp"

using namespace graspsim::recordings;

namespace {

std::string tmp_path(const std::string& name) { return graspsim::test::fresh_tmp_path("recordings_", name); }

// Rows of table /t a reader sees now (0 before the table is in the file).
std::int64_t rows_on_disk(const std::string& file) {
  if (!has_object(file, "/t/tick")) return 0;
  return static_cast<std::int64_t>(read_dataset(file, "/t/tick").shape.at(0));
}

}  // namespace

// A write that fails (here a value that is not an int64, as a full disk fails a block write)
// leaves rows after the last flush that may be only partly on disk. close() cuts the table back
// to the rows of the last successful flush, says so in the status, and the file holds exactly
// those rows, tick = row. Swept over where the last flush falls (0: none, so nothing is kept),
// with and without the writer thread.
TEST_CASE("a trace whose writing fails keeps exactly the rows of its last flush", "[trace_writer][errors]") {
  for (const bool background : {false, true}) {
    for (const std::int64_t flushed : {0, 50, 64, 96}) {
      const std::string file = tmp_path("cut_at_flush.h5");
      TraceOptions options{32, 0};
      options.background = background;
      TraceWriter writer(file, options);
      TraceTable& t = writer.table("t");
      t.add_column("tick", 1, DType::kInt64, "tick");
      for (std::int64_t r = 0; r < flushed; ++r) *t.append_row() = static_cast<double>(r);
      // Blocks of 32 rows fill (and are written and flushed) on their own; then a flush by hand.
      if (flushed > 0) writer.wait(writer.flush());
      try {
        for (std::int64_t r = flushed; r < flushed + 40; ++r)
          *t.append_row() = r == flushed + 5 ? 0.5 : static_cast<double>(r);   // 0.5: not an int64
        writer.flush();
        writer.wait();
        FAIL("the bad value was written");
      } catch (const TraceError& e) {
        CHECK_THAT(e.what(), Catch::Contains("not an int64"));
      }
      INFO("background " << background << ", flushed " << flushed);
      try {
        writer.close("complete");
        FAIL("close did not report the failure");
      } catch (const TraceError& e) {
        CHECK_THAT(e.what(), Catch::Contains("kept up to the last flush: '/t' " + std::to_string(flushed) + " rows"));
      }
      const std::string status = read_string_attribute(file, "/", "status");
      CHECK_THAT(status, Catch::StartsWith("error: ") && Catch::Contains("not an int64") &&
                             Catch::Contains("'/t' " + std::to_string(flushed) + " rows"));
      const Dataset tick = read_dataset(file, "/t/tick");
      REQUIRE(static_cast<std::int64_t>(tick.shape.at(0)) == flushed);
      for (std::int64_t r = 0; r < flushed; ++r) CHECK(tick.values[static_cast<std::size_t>(r)] == static_cast<double>(r));
    }
  }
}

// The runner's flush rule (app/run_trace.cpp): before it hands over flush k it waits for flush
// k - 1, so the file is never more than one flush interval behind the rows handed over. Here
// the writer thread is slowed by a thread that holds the HDF5 lock for `stall` ms at a time (a
// disk that stalls); whatever the stall, after wait(ticket of flush k - 1) returns, a reader sees
// at least (k - 1) intervals of rows. Without the wait the writer would fall up to 4 blocks
// behind (its pool), and this check fails at stalls of 20 ms and more.
TEST_CASE("after wait(ticket) the flush's rows are on disk, however slow the writer", "[trace_writer][background]") {
  constexpr std::int64_t kInterval = 100;   // rows per flush (= block_rows, as the runner sizes them)
  for (const int stall : {0, 20, 60}) {
    const std::string file = tmp_path("flush_ticket.h5");
    TraceOptions options{kInterval, 0};
    options.background = true;
    TraceWriter writer(file, options);
    TraceTable& t = writer.table("t");
    t.add_column("tick", 1, DType::kInt64, "tick");
    struct Stalls {
      std::atomic<bool> stop{false};
      std::thread thread;
      ~Stalls() {
        stop.store(true);
        if (thread.joinable()) thread.join();
      }
    } stalls;
    std::atomic<bool>& stop = stalls.stop;
    stalls.thread = std::thread([&] {
      while (!stop.load()) {
        {
          graspsim::recordings::inspect::LibraryLock hold;   // the writer thread cannot touch the file
          std::this_thread::sleep_for(std::chrono::milliseconds(stall));
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    });
    std::uint64_t previous = 0;
    std::int64_t worst_lag = 0;   // rows handed over but not on disk, after each wait
    for (std::int64_t k = 1; k <= 8; ++k) {
      for (std::int64_t r = (k - 1) * kInterval; r < k * kInterval; ++r) *t.append_row() = static_cast<double>(r);
      writer.wait(previous);
      if (k > 1) {   // before the first flush the table may not be in the file yet
        const std::int64_t on_disk = rows_on_disk(file);
        CHECK(on_disk >= (k - 1) * kInterval);
        worst_lag = std::max(worst_lag, k * kInterval - on_disk);
      }
      previous = writer.flush();
    }
    stop.store(true);
    stalls.thread.join();
    INFO("stall " << stall << " ms: worst lag " << worst_lag << " rows");
    CHECK(worst_lag <= 2 * kInterval);
    writer.close("complete");
    CHECK(rows_on_disk(file) == 8 * kInterval);
  }
}
