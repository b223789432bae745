// Columns of a compared table: opening one, and reading a compound table's rows.
#include "compare_columns.hpp"

#include "h5_checks.hpp"

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
  h5::Handle file_space = h5::checked(H5Dget_space(dataset), H5Sclose, context);
  const hsize_t offset[1] = {static_cast<hsize_t>(start)};
  const hsize_t n[1] = {static_cast<hsize_t>(count)};
  h5::check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, offset, nullptr, n, nullptr),
            context);
  h5::Handle mem_space = h5::checked(H5Screate_simple(1, n, nullptr), H5Sclose, context);
  h5::check(H5Dread(dataset, type.get(), mem_space.get(), file_space.get(), H5P_DEFAULT,
                    bytes.data()),
            context + ": cannot read rows " + std::to_string(start) + " to " +
                std::to_string(start + count - 1));
}

// Opens column `path` of table `group` (path = "/" + group + "/" + name).
Column open_column(const OpenTrace& t, const std::string& group, const std::string& name) {
  Column c;
  c.file = t.name;
  c.path = "/" + group + "/" + name;
  const std::string context = "trace " + quoted(t.name) + ", dataset " + quoted("/" + group + "/" + name);
  h5::Handle type;
  std::string units_key = "units", order_key = "order";
  if (object_type(t.file.get(), group, context) == H5I_DATASET) {
    // A member of a compound table: its attributes are the table's "<member>/<name>".
    c.member = name;
    units_key = name + "/units";
    order_key = name + "/order";
    c.dataset = h5::checked(H5Dopen2(t.file.get(), group.c_str(), H5P_DEFAULT), H5Dclose,
                            context + ": cannot open");
    h5::Member member = h5::member_of(c.dataset.get(), name, context);
    c.member_offset = member.native_offset;   // where it sits in the rows TableRows reads
    c.width = member.width;
    c.rank = member.width > 1 ? 2 : 1;
    type = std::move(member.element);
    h5::Handle space = h5::checked(H5Dget_space(c.dataset.get()), H5Sclose, context);
    if (H5Sget_simple_extent_ndims(space.get()) != 1) fail(context + ": its table is not 1-D");
    hsize_t rows[1] = {0};
    h5::check(H5Sget_simple_extent_dims(space.get(), rows, nullptr), context);
    h5::check_rows(c.dataset.get(), rows[0], context);
    c.rows = static_cast<std::int64_t>(rows[0]);
  } else {
    c.dataset = h5::checked(H5Dopen2(t.file.get(), c.path.c_str(), H5P_DEFAULT), H5Dclose,
                            context + ": cannot open");
    type = h5::checked(H5Dget_type(c.dataset.get()), H5Tclose, context);
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
  }
  const H5T_class_t type_class = H5Tget_class(type.get());
  c.element_class = type_class;
  c.element_size = H5Tget_size(type.get());
  c.element_signed = type_class == H5T_INTEGER && H5Tget_sign(type.get()) != H5T_SGN_NONE;
  if (type_class == H5T_FLOAT && c.element_size != 4 && c.element_size != 8)
    fail(context + ": floating-point elements of " + std::to_string(c.element_size) + " bytes");
  if (type_class == H5T_INTEGER && c.element_size != 1 && c.element_size != 2 &&
      c.element_size != 4 && c.element_size != 8)
    fail(context + ": integer elements of " + std::to_string(c.element_size) + " bytes");
  if (type_class == H5T_FLOAT) c.kind = Kind::kFloat;
  else if (type_class == H5T_INTEGER)
    c.kind = H5Tget_sign(type.get()) == H5T_SGN_NONE ? Kind::kUnsigned : Kind::kSigned;
  else fail(context + ": elements are neither floating-point numbers nor integers");
  if (h5::has_attribute(c.dataset.get(), units_key, context))
    c.units = attribute_text(c.dataset.get(), units_key, context);
  if (h5::has_attribute(c.dataset.get(), order_key, context))
    c.order = split_order(attribute_text(c.dataset.get(), order_key, context));
  return c;
}

}  // namespace graspsim::recordings::compare
