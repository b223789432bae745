// TraceTable: declares columns and attributes, hands out rows, and hands full blocks to the
// writer's worker (the simulation side of a table).
#include <algorithm>
#include <set>

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
  // A group's path is one member of the row: no column of its own below it (nor above it).
  for (const Group& g : t.groups) {
    if (path == g.name || path.rfind(g.name + "/", 0) == 0 || g.name.rfind(path + "/", 0) == 0)
      throw TraceError(t.column_context(path) + ": column path clashes with group " + quoted(g.name));
  }
  const std::size_t offset = t.row_width;
  t.columns.push_back(Column{path, width, dtype, offset, t.packed_width});
  t.row_width += static_cast<std::size_t>(width);
  t.packed_width += static_cast<std::size_t>(width) * size_of(dtype);
  t.attributes.emplace_back(path + "/units", units);
  return offset;
}

namespace {

// Whether `a` and `b` would be one a group of the other ("a" and "a/b"), or the same.
bool clash(const std::string& a, const std::string& b) {
  return a == b || a.rfind(b + "/", 0) == 0 || b.rfind(a + "/", 0) == 0;
}

}  // namespace

std::size_t TraceTable::add_group(const std::string& group, const std::vector<std::string>& entities,
                                  const std::vector<Field>& fields) {
  Impl& t = *impl_;
  t.require_open();
  const std::string where = t.context() + ", group " + quoted("/" + t.name + "/" + group);
  if (t.started || t.file->frozen) throw TraceError(where + ": add_group after the first row of the file");
  if (!is_relative_path(group)) throw TraceError(where + ": group path must be relative, like 'objects'");
  if (entities.empty() || fields.empty()) throw TraceError(where + ": a group needs an entity and a field");
  std::set<std::string> seen;
  for (const std::string& e : entities) {
    if (e.empty() || e == "." || e == ".." || e.find_first_of("/\n") != std::string::npos)
      throw TraceError(where + ": entity name " + quoted(e) +
                       " cannot be a column path component (empty, '.', '..', or has '/' or a newline)");
    if (!seen.insert(e).second) throw TraceError(where + ": entity " + quoted(e) + " named twice");
  }
  Group g{group, entities, {}, t.columns.size(), 0};
  std::size_t values = 0;
  for (const Field& f : fields) {
    if (!is_relative_path(f.name) || f.width < 1)
      throw TraceError(where + ", field " + quoted(f.name) + ": a field needs a relative path and a width of at least 1");
    for (const Column& other : g.fields)
      if (clash(other.name, f.name)) throw TraceError(where + ", field " + quoted(f.name) + ": clashes with field " + quoted(other.name));
    g.fields.push_back(Column{f.name, f.width, f.dtype, values, g.entity_bytes});
    values += static_cast<std::size_t>(f.width);
    g.entity_bytes += static_cast<std::size_t>(f.width) * size_of(f.dtype);
  }
  for (const Column& c : t.columns)
    if (clash(c.name, group)) throw TraceError(where + ": clashes with column " + quoted(c.name));
  const std::size_t offset = t.row_width;
  const int index = static_cast<int>(t.groups.size());
  t.columns.reserve(t.columns.size() + entities.size() * g.fields.size());
  std::string names;
  for (const std::string& e : entities) {
    names += (names.empty() ? "" : "\n") + e;
    for (const Column& f : g.fields) {
      t.columns.push_back(Column{group + "/" + e + "/" + f.name, f.width, f.dtype, t.row_width, t.packed_width, index});
      t.row_width += static_cast<std::size_t>(f.width);
      t.packed_width += static_cast<std::size_t>(f.width) * size_of(f.dtype);
    }
  }
  t.attributes.emplace_back(group, names);
  for (const Field& f : fields) t.attributes.emplace_back(group + "/" + f.name + "/units", f.units);
  t.groups.push_back(std::move(g));
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
    // A column, or a prefix of columns ("fingers/thumb"), as a group was in schema 2; or a field
    // of a group's entities ("objects/quaternion"), stored once for all of them.
    const bool known = std::any_of(t.columns.begin(), t.columns.end(), [&](const Column& c) {
      return c.group < 0 && (c.name == dataset_or_dot || c.name.rfind(dataset_or_dot + "/", 0) == 0);
    }) || std::any_of(t.groups.begin(), t.groups.end(), [&](const Group& g) {
      return std::any_of(g.fields.begin(), g.fields.end(),
                         [&](const Column& f) { return g.name + "/" + f.name == dataset_or_dot; });
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
