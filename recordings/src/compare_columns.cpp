// Columns of a compared table: opening one, and reading a compound table's rows.
#include "compare_columns.hpp"

#include <map>
#include <utility>

#include "h5_checks.hpp"
#include "table_layout.hpp"

namespace graspsim::recordings::compare {
namespace {

std::vector<std::string> split_order(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    std::string item = text.substr(start, end - start);
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    out.push_back(item);
    start = end + 1;
  }
  return out;
}

}  // namespace

void TableRows::load(std::int64_t r) {
  const std::string context = "trace '" + file + "', table '" + path + "'";
  start = r;
  count = std::min(block, rows - r);
  bytes.resize(static_cast<std::size_t>(count) * row_bytes);
  h5::Handle file_space = h5::checked(H5Dget_space(dataset.get()), H5Sclose, context);
  const hsize_t offset[1] = {static_cast<hsize_t>(start)};
  const hsize_t n[1] = {static_cast<hsize_t>(count)};
  h5::check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, offset, nullptr, n, nullptr),
            context);
  h5::Handle mem_space = h5::checked(H5Screate_simple(1, n, nullptr), H5Sclose, context);
  h5::check(H5Dread(dataset.get(), type.get(), mem_space.get(), file_space.get(), H5P_DEFAULT,
                    bytes.data()),
            context + ": cannot read rows " + std::to_string(start) + " to " +
                std::to_string(start + count - 1));
}

namespace {

// A column's element type checked and turned into its kind.
void set_kind(Column& c, const std::string& context) {
  if (c.element_class == H5T_FLOAT && c.element_size != 4 && c.element_size != 8)
    fail(context + ": floating-point elements of " + std::to_string(c.element_size) + " bytes");
  if (c.element_class == H5T_INTEGER && c.element_size != 1 && c.element_size != 2 &&
      c.element_size != 4 && c.element_size != 8)
    fail(context + ": integer elements of " + std::to_string(c.element_size) + " bytes");
  if (c.element_class == H5T_FLOAT) c.kind = Kind::kFloat;
  else if (c.element_class == H5T_INTEGER) c.kind = c.element_signed ? Kind::kSigned : Kind::kUnsigned;
  else fail(context + ": elements are neither floating-point numbers nor integers");
}

// A schema 2 column: dataset "/" + group + "/" + name of its own.
Column open_dataset_column(const OpenTrace& t, const std::string& group, const std::string& name) {
  Column c;
  c.file = t.name;
  c.path = "/" + group + "/" + name;
  const std::string context = "trace " + quoted(t.name) + ", dataset " + quoted(c.path);
  c.dataset = h5::checked(H5Dopen2(t.file.get(), c.path.c_str(), H5P_DEFAULT), H5Dclose, context + ": cannot open");
  h5::Handle type = h5::checked(H5Dget_type(c.dataset.get()), H5Tclose, context);
  h5::Handle space = h5::checked(H5Dget_space(c.dataset.get()), H5Sclose, context);
  c.rank = H5Sget_simple_extent_ndims(space.get());
  if (c.rank != 1 && c.rank != 2)
    fail(context + ": has " + std::to_string(c.rank) + " dimensions (a trace column has 1 or 2)");
  hsize_t dims[2] = {0, 1};
  h5::check(H5Sget_simple_extent_dims(space.get(), dims, nullptr), context);
  h5::check_rows(c.dataset.get(), dims[0], context);
  if (dims[1] > h5::kMaxColumnWidth) fail(context + ": " + std::to_string(dims[1]) + " values per row (damaged?)");
  c.rows = static_cast<std::int64_t>(dims[0]);
  c.width = c.rank == 2 ? static_cast<std::size_t>(dims[1]) : 1;
  c.element_class = H5Tget_class(type.get());
  c.element_size = H5Tget_size(type.get());
  c.element_signed = c.element_class == H5T_INTEGER && H5Tget_sign(type.get()) != H5T_SGN_NONE;
  set_kind(c, context);
  if (h5::has_attribute(c.dataset.get(), "units", context)) c.units = attribute_text(c.dataset.get(), "units", context);
  if (h5::has_attribute(c.dataset.get(), "order", context))
    c.order = split_order(attribute_text(c.dataset.get(), "order", context));
  return c;
}

// The columns `names` of compound table `group`, from its layout; a column's attributes are the
// table's "<prefix>/units" and "<prefix>/order" (StoredColumn::attributes), read once per prefix.
std::vector<Column> open_table_columns(const OpenTrace& t, const std::string& group,
                                       const std::vector<std::string>& names) {
  const std::string context = "trace " + quoted(t.name) + ", table " + quoted("/" + group);
  h5::Handle table = h5::checked(H5Dopen2(t.file.get(), group.c_str(), H5P_DEFAULT), H5Dclose, context + ": cannot open");
  const h5::TableLayout layout = h5::table_layout(table.get(), context);
  h5::Handle space = h5::checked(H5Dget_space(table.get()), H5Sclose, context);
  if (H5Sget_simple_extent_ndims(space.get()) != 1) fail(context + ": is not 1-D");
  hsize_t rows[1] = {0};
  h5::check(H5Sget_simple_extent_dims(space.get(), rows, nullptr), context);
  h5::check_rows(table.get(), rows[0], context);
  std::map<std::string, std::size_t> index;
  for (std::size_t k = 0; k < layout.columns.size(); ++k) index.emplace(layout.columns[k].name, k);
  std::map<std::string, std::pair<std::string, std::vector<std::string>>> attributes;   // by prefix
  std::vector<Column> out;
  out.reserve(names.size());
  for (const std::string& name : names) {
    const std::string where = "trace " + quoted(t.name) + ", dataset " + quoted("/" + group + "/" + name);
    const auto found = index.find(name);
    if (found == index.end()) fail(where + ": no such column");
    const h5::StoredColumn& s = layout.columns[found->second];
    Column& c = out.emplace_back();
    c.file = t.name;
    c.path = "/" + group + "/" + name;
    c.member = name;
    c.member_offset = s.offset;   // where it sits in the rows TableRows reads
    c.width = s.width;
    c.rank = s.width > 1 ? 2 : 1;
    c.rows = static_cast<std::int64_t>(rows[0]);
    c.element_class = s.element_class;
    c.element_size = s.element_size;
    c.element_signed = s.element_signed;
    set_kind(c, where);
    auto known = attributes.find(s.attributes);
    if (known == attributes.end()) {
      std::pair<std::string, std::vector<std::string>> a;
      const std::string units = s.attributes + "/units", order = s.attributes + "/order";
      if (h5::has_attribute(table.get(), units, where)) a.first = attribute_text(table.get(), units, where);
      if (h5::has_attribute(table.get(), order, where)) a.second = split_order(attribute_text(table.get(), order, where));
      known = attributes.emplace(s.attributes, std::move(a)).first;
    }
    c.units = known->second.first;
    c.order = known->second.second;
  }
  return out;
}

}  // namespace

std::vector<Column> open_columns(const OpenTrace& t, const std::string& group, const std::vector<std::string>& names) {
  const std::string context = "trace " + quoted(t.name) + ", table " + quoted("/" + group);
  if (object_type(t.file.get(), group, context) == H5I_DATASET) return open_table_columns(t, group, names);
  std::vector<Column> out;
  for (const std::string& name : names) out.push_back(open_dataset_column(t, group, name));
  return out;
}

}  // namespace graspsim::recordings::compare
