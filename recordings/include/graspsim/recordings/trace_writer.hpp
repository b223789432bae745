// TraceWriter: writes a run's trace as an HDF5 file of tables, each a group of datasets that
// grow one row at a time together, buffered in blocks and appended to chunked datasets.
#pragma once

#include <bit>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

namespace graspsim::recordings {

// Any failure to write or read a trace. what() names the file and, where relevant, the
// dataset or attribute.
class TraceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// On-disk element type of a dataset (little-endian IEEE double, signed integers, or uint64).
// kUInt64 carries 64 raw bits (a hash) through the row: put them there with uint64_in_row().
enum class DType { kFloat64, kInt64, kInt32, kInt8, kUInt64 };

// The row value of a kUInt64 column: the 64 bits of `value` carried in a double, unchanged
// (written back bit for bit; never do arithmetic on it).
inline double uint64_in_row(std::uint64_t value) { return std::bit_cast<double>(value); }

// A group of datasets that grow together: one append_row() adds one row to every dataset of
// the group at once, so they can never drift apart (the H5MD lesson). Owned by a TraceWriter.
class TraceTable {
 public:
  ~TraceTable();
  TraceTable(const TraceTable&) = delete;
  TraceTable& operator=(const TraceTable&) = delete;

  // Declares dataset `path` (relative to the group, may contain '/', e.g.
  // "fingers/thumb/hip"; intermediate groups are created) with `width` values per row: width 1
  // gives shape (n,), width > 1 gives (n, width). Stored as `dtype`, with string attribute
  // "units" = units. The dataset is created at once with 0 rows. Returns the column's offset
  // into a row. Only allowed before the first row of any table of the file (the layout is then
  // frozen for SWMR); throws TraceError after it, for a bad path, a path used twice, or width < 1.
  std::size_t add_column(const std::string& path, int width, DType dtype,
                         const std::string& units);
  // Pointer to the next row: row_width() doubles in column order; the caller fills all of them.
  // Valid until the next append_row/flush. Integer columns are stored as doubles in the row and
  // converted on flush (exact up to 2^53); a value that is not an integer in the column's range
  // makes the flush throw TraceError naming the dataset and row. Writes the buffered block when
  // it is full (then also flushes the file's metadata, so a run cut short leaves a readable
  // file). The first row of any table freezes the file's layout and, with TraceOptions::swmr,
  // starts SWMR writing. Allocates only on the first call.
  double* append_row();
  std::size_t row_width() const;   // doubles per row
  std::int64_t rows() const;       // rows appended so far (flushed or not)
  void flush();                    // writes buffered rows (no-op if none)
  // String attribute on a dataset or group below this table's group; "." = the group itself.
  // Only before the file's first row (throws TraceError after it).
  void set_attribute(const std::string& dataset_or_dot, const std::string& name,
                     const std::string& value);

 private:
  friend class TraceWriter;
  struct Impl;
  explicit TraceTable(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

struct TraceOptions {
  std::size_t block_rows = 1024;   // rows: buffered per table before a write; also the chunk
                                   // size (per table: TraceWriter::table's block_rows)
  int compression = 0;             // 0 = none, 1..9 = deflate level
  // Crash safety (recordings/README.md): the newest file format and SWMR writing from the first
  // row on, so a process killed at any moment leaves every flushed row readable. false: the
  // default (oldest compatible) format, no SWMR.
  bool swmr = true;
};

class TraceWriter {
 public:
  // Creates (truncates) the file and writes root attribute "status" = "running". Throws
  // TraceError("cannot create trace 'PATH': <reason>"), e.g. for a missing directory, no
  // permission, or bad options.
  explicit TraceWriter(const std::string& path, TraceOptions options = {});
  // Flushes and closes; never throws. If close() was not called, status becomes
  // "incomplete: writer destroyed without close".
  ~TraceWriter();
  TraceWriter(const TraceWriter&) = delete;
  TraceWriter& operator=(const TraceWriter&) = delete;

  // The table of group `group` ("servo" or "/servo"; may be nested, "a/b"), created on first
  // use (only before the file's first row); the same object afterwards. References stay valid
  // until the writer is destroyed. `block_rows`: rows this table buffers before a write, which
  // are also its rows per chunk (0: TraceOptions::block_rows); used only when the table is
  // created. A writer that flushes every N rows of a table should give it N (a flush then writes
  // whole chunks, each chunk once; recordings/README.md "Cost").
  TraceTable& table(const std::string& group, std::size_t block_rows = 0);
  // Root attributes (replacing one of the same name). Before the file's first row they are
  // written at once; after it (SWMR cannot add attributes) they are kept and written by close().
  void set_attribute(const std::string& name, const std::string& value);
  void set_attribute(const std::string& name, double value);
  void set_attribute(const std::string& name, std::int64_t value);
  // Any other integer (int, long long, unsigned) is stored as int64, so set_attribute("seed", 42)
  // is not ambiguous between double and int64.
  template <std::integral T>
    requires(!std::same_as<T, bool> && !std::same_as<T, std::int64_t>)
  void set_attribute(const std::string& name, T value) {
    set_attribute(name, static_cast<std::int64_t>(value));
  }
  void flush();   // every table, then H5Fflush
  // Flushes, closes the file, reopens it without SWMR, writes the kept root attributes and
  // root string attribute "status" (e.g. "complete" or "error: <message>") and closes it. Idempotent: later calls do nothing. If the flush fails the status
  // written is "error: <flush failure>", the file is still closed, and TraceError is thrown.
  void close(const std::string& status);
  bool is_closed() const;
  const std::string& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspsim::recordings
