// TraceTable: declares columns and attributes, hands out rows, and hands full blocks to the
// writer's worker (the simulation side of a table).
#include <algorithm>

#include "trace_writer_impl.hpp"

namespace graspsim::recordings {

using namespace writer;

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

}  // namespace graspsim::recordings
