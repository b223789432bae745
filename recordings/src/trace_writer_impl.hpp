// What TraceWriter and TraceTable are made of, shared by the files that implement them:
// trace_table.cpp (columns, rows, blocks), table_dataset.cpp (a table's dataset, written by the
// worker), trace_writer.cpp (the file, its tables and the jobs), trace_close.cpp (closing, and
// what a failed write leaves). recordings/README.md "Writing" says how it works and why.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "disk_reserve.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "h5.hpp"
#include "row_type.hpp"
#include "writer_worker.hpp"

namespace graspsim::recordings {
namespace writer {

inline std::string quoted(const std::string& text) { return "'" + text + "'"; }

// Checks a relative path: non-empty components, none of them "." or "..", no leading '/'.
bool is_relative_path(const std::string& path);

// Object creation properties without modification times, so that two runs write the same
// object headers.
h5::Handle untimed(hid_t property_class, const std::string& where);

// File access: the newest file format when `swmr` (SWMR needs it).
h5::Handle file_access(bool swmr, const std::string& where);

// Consecutive 8-byte columns copied as they are (float64, and uint64 bits): one memcpy per row.
struct CopyRun {
  std::size_t offset;   // doubles into a row of the block buffer
  std::size_t bytes;    // bytes into a packed row
  std::size_t count;    // doubles
};

// What the writer and its tables share about the file.
struct TraceFileState {
  hid_t file = H5I_INVALID_HID;   // not owned (TraceWriter::Impl::file)
  TraceOptions options;
  bool frozen = false;            // a row was appended: no new table, column or attribute
  std::function<void()> freeze;   // TraceWriter::Impl::freeze
  TraceWriterWorker worker;
};

}  // namespace writer

struct TraceTable::Impl {
  std::string file_path;
  std::string name;              // dataset path without the leading '/': "servo"
  std::size_t block_rows = 0;    // rows per block, and rows per chunk
  writer::TraceFileState* file = nullptr;   // owned by the writer
  std::vector<writer::Column> columns;   // every column, a group's one per entity and field
  std::vector<writer::Group> groups;     // in declaration order
  std::vector<std::pair<std::string, std::string>> attributes;   // name, value; in call order
  std::size_t row_width = 0;     // doubles per row
  std::size_t packed_width = 0;  // bytes per compound row
  bool closed = false;           // the writer closed the file

  // Simulation side (after the first row): the block being filled and the free ones.
  std::vector<std::unique_ptr<writer::Block>> blocks;   // all of them (owned)
  std::vector<writer::Block*> free_blocks;              // guarded by the worker's mutex
  writer::Block* current = nullptr;
  std::int64_t rows = 0;         // rows appended
  bool started = false;          // append_row was called

  // Writer side.
  h5::Handle dataset;
  h5::Handle memory_type;        // the compound row in memory (native types, packed)
  std::vector<writer::CopyRun> runs;     // the 8-byte columns, merged where adjacent
  std::vector<const writer::Column*> integers;   // the columns converted and checked one by one
  bool direct = false;           // whole chunks go to the file as they are (H5Dwrite_chunk)
  std::vector<unsigned char> packed;   // block_rows x packed_width
  std::int64_t written = 0;      // rows handed to HDF5 (in the file once it is flushed)
  std::int64_t durable = 0;      // rows written before the last successful H5Fflush: on disk

  std::string context() const { return "trace " + writer::quoted(file_path); }
  std::string column_context(const std::string& column) const {
    return context() + ", column " + writer::quoted("/" + name + "/" + column);
  }
  void require_open() const {
    if (closed) throw TraceError(context() + ": table " + writer::quoted("/" + name) + " used after close");
  }
  void allocate();                      // at freeze: the blocks (simulation side)
  void create_dataset(hid_t file_id);   // the first job, before SWMR starts (writer side)
  void write_block(writer::Block& block);       // writer side
  void hand_over();                     // simulation side: current block to the worker
  writer::Block* take_free_block();
};

struct TraceWriter::Impl {
  std::string path;
  TraceOptions options;
  h5::Handle file;
  h5::Handle root;
  writer::TraceFileState state;
  // Root attributes set after the first row, written by close() (name, writer), in call order.
  std::vector<std::pair<std::string, std::function<void(hid_t)>>> pending;
  // Ordered by name, so the file's layout does not depend on first use.
  std::map<std::string, std::unique_ptr<TraceTable>> tables;
  std::vector<writer::Job> flush_jobs;   // flush()'s hand-over, one per table and the flush
  DiskReserve reserve;   // given back at close(), for what closing writes
  hsize_t size_limit = 0;   // bytes: the process's file size limit (RLIMIT_FSIZE), 0 for none
  bool closed = false;
  bool marked = false;   // close() wrote the final status

  std::string context() const { return "trace " + writer::quoted(path); }
  void require_open() const {
    if (closed) throw TraceError(context() + ": used after close");
  }
  void set_root_attribute(const std::string& name, std::function<void(hid_t)> write);
  std::string cut_to_last_flush(hid_t file_id);
  void freeze();
  void run(const writer::Job& job);   // on the writer thread (or inline)
};

}  // namespace graspsim::recordings
