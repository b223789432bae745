// TraceWriter: writes a run's trace as an HDF5 file of tables, each one chunked dataset of
// compound rows (one member per column) that grows one row at a time, buffered in blocks and
// appended block by block, optionally by a background writer thread.
#pragma once

#include <bit>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

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

// Bytes of one stored element.
constexpr std::size_t size_of(DType dtype) {
  switch (dtype) {
    case DType::kFloat64: case DType::kInt64: case DType::kUInt64: return 8;
    case DType::kInt32: return 4;
    case DType::kInt8: return 1;
  }
  return 8;
}

// The name recordings/README.md gives the type ("float64", "int32", ...).
constexpr const char* name_of(DType dtype) {
  switch (dtype) {
    case DType::kFloat64: return "float64";
    case DType::kInt64: return "int64";
    case DType::kInt32: return "int32";
    case DType::kInt8: return "int8";
    case DType::kUInt64: return "uint64";
  }
  return "?";
}

// The most bytes HDF5 stores in one chunk (2^32 - 1): a table's chunk, `block_rows` rows, must
// fit in it, which bounds one row of a table to just under 4 GiB (recordings/README.md "Limits").
inline constexpr std::size_t kMaxChunkBytes = 0xFFFFFFFFu;   // bytes

// The row value of a kUInt64 column: the 64 bits of `value` carried in a double, unchanged
// (written back bit for bit; never do arithmetic on it).
inline double uint64_in_row(std::uint64_t value) { return std::bit_cast<double>(value); }

// A table: one HDF5 dataset of compound rows, one member per column (or per group of columns
// repeated per entity: add_group), so its columns can never drift apart, not even in a file cut
// by a crash (the H5MD lesson, taken one step further than a group of datasets). Owned by a
// TraceWriter.
class TraceTable {
 public:
  struct Impl;   // opaque
  ~TraceTable();
  TraceTable(const TraceTable&) = delete;
  TraceTable& operator=(const TraceTable&) = delete;

  // Declares column `path` (relative to the table, may contain '/', e.g. "fingers/thumb/hip"):
  // a member of that name of the row type, with `width` values per row (width > 1: an array
  // member), stored as `dtype`; the table gets string attribute "<path>/units" = units. Readers
  // see it as dataset "/<table>/<path>" of shape (n,) or (n, width) (trace_reader.hpp). Returns
  // the column's offset into a row. Only allowed before the first row of any table of the file
  // (the layout is then frozen for SWMR); throws TraceError after it, for a bad path, a path
  // used twice, or width < 1.
  std::size_t add_column(const std::string& path, int width, DType dtype,
                         const std::string& units);
  // One field of the entities of a group (add_group): its path below the entity ("position"),
  // values per row, stored type and units.
  struct Field {
    std::string name;
    int width = 1;
    DType dtype = DType::kFloat64;
    std::string units;
  };
  // Declares the columns "<group>/<entity>/<field>" of every entity (a body, a finger) and field,
  // entity by entity in the order given, fields in order: readers see each as add_column's. They
  // are stored as one member `group` of the row, an array of one compound element per entity with
  // a member per field, so the row type stays the same size however many entities there are
  // (recordings/README.md "Schema"); the table gets string attribute `group` = the entity names
  // joined by newlines, and per field "<group>/<field>/units" (a field's other attributes:
  // set_attribute("<group>/<field>", ...)). Returns the offset into a row of the first entity's
  // first field; entity k's fields follow at that offset + k * (the fields' widths summed), in
  // field order. Only before the first row (as add_column); throws TraceError for no entity, a
  // name that cannot be a path component or has a newline, one used twice, a field path that is
  // not relative or width < 1, or a group path that clashes with a column.
  std::size_t add_group(const std::string& group, const std::vector<std::string>& entities,
                        const std::vector<Field>& fields);
  // Pointer to the next row: row_width() doubles in column order; the caller fills all of them.
  // Valid until the next append_row/flush. Integer columns are stored as doubles in the row and
  // converted when the block is written (exact up to 2^53); a value that is not an integer in
  // the column's range makes that write fail with a TraceError naming the column and row (with
  // TraceOptions::background, thrown by a later call: the next hand-over, wait() or close()).
  // Hands the block to the writer when it is full (then also flushes the file's metadata, so a
  // run cut short leaves a readable file). The first row of any table freezes the file's layout:
  // every table's dataset is created and, with TraceOptions::swmr, SWMR writing starts.
  // Allocates only on the first call.
  double* append_row();
  std::size_t row_width() const;   // doubles per row
  std::int64_t rows() const;       // rows appended so far (flushed or not)
  void flush();                    // writes buffered rows and waits for the writer
  // String attribute of the table ("."; stored as attribute `name` of the dataset), of one of
  // its columns (stored as attribute "<column>/<name>"), or of a field of a group's entities,
  // "<group>/<field>" (stored as "<group>/<field>/<name>", one for every entity). Only before the
  // file's first row (throws TraceError after it, for an unknown column, a column of a group's
  // entity, or a name that is empty or has '/').
  void set_attribute(const std::string& dataset_or_dot, const std::string& name,
                     const std::string& value);

 private:
  friend class TraceWriter;
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
  // Writes blocks and flushes on a background thread, in the order they were handed over, so the
  // thread that appends rows only fills memory (it waits only when the writer is 4 blocks per
  // table behind). Errors surface at a later call. The file is the same either way.
  bool background = false;
  // Room held on the file's file system (an unlinked, preallocated file beside it) and given
  // back just before close(), so that a trace cut by a full disk can still be closed and marked
  // (recordings/README.md "A full disk"). Halved down to 16 KiB where there is less room; 0:
  // none.
  std::size_t reserve_bytes = 128 * 1024;   // bytes
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

  // The table at dataset path `group` ("servo" or "/servo"; may be below a group, "a/b", but not
  // below another table), created on first use (only before the file's first row); the same
  // object afterwards. References stay valid
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
  // Hands every table's buffered rows to the writer, then an H5Fflush (done by the time this
  // returns without TraceOptions::background; with it, queued: see wait()). Returns the flush's
  // ticket for wait(ticket).
  std::uint64_t flush();
  // Waits until everything handed to the writer is on disk; rethrows a failure of the writer.
  void wait();
  // Waits until the flush that returned `ticket`, and everything handed over before it, is on
  // disk (later blocks may still be queued); rethrows a failure of the writer. A runner that
  // waits for flush k - 1 before it hands over flush k keeps the writer at most one flush
  // interval behind: a process killed at any moment loses at most two intervals of rows.
  void wait(std::uint64_t ticket);
  // Flushes, closes the file, reopens it without SWMR, writes the kept root attributes and
  // root string attribute "status" (e.g. "complete" or "error: <message>") and closes it.
  // Idempotent: later calls do nothing. If writing failed (a full disk), every table is cut
  // back to the rows of the last successful flush (rows after it may be only partly on disk),
  // the status written is "error: <failure>; kept up to the last flush: <table> <rows>, ...",
  // the file is still closed, and TraceError is thrown with that text. If even the status cannot
  // be written, the message says so (the file then says "running": `graspsim repair`).
  void close(const std::string& status);
  bool is_closed() const;
  // Closed with its final status in the file ("complete" or "error: ..."): a file that may
  // replace an earlier one. False while open, and when close() could not write the status.
  bool marked() const;
  const std::string& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace graspsim::recordings
