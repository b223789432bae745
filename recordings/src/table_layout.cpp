// The columns of a stored table, whatever its layout (table_layout.hpp).
#include "table_layout.hpp"

#include <algorithm>
#include <set>

#include "graspsim/recordings/trace_writer.hpp"
#include "h5_checks.hpp"

namespace graspsim::recordings::h5 {
namespace {

std::string quoted(const std::string& text) { return "'" + text + "'"; }

std::string member_name(hid_t compound, unsigned k) {
  char* name = H5Tget_member_name(compound, k);
  std::string text = name != nullptr ? name : "";
  H5free_memory(name);
  return text;
}

// A member of stored type `type`: a number, or a 1-D array of 1 to kMaxColumnWidth numbers. Sets
// the column's width and element.
void set_element(hid_t type, StoredColumn& c, const std::string& where) {
  if (H5Tget_class(type) != H5T_ARRAY) {
    c.width = 1;
    c.element_class = H5Tget_class(type);
    c.element_size = H5Tget_size(type);
    c.element_signed = c.element_class == H5T_INTEGER && H5Tget_sign(type) != H5T_SGN_NONE;
    if (c.element_class == H5T_COMPOUND) throw TraceError(where + " is a compound, which no trace column is (damaged?)");
    return;
  }
  if (H5Tget_array_ndims(type) != 1) throw TraceError(where + ": not a 1-D array member");
  hsize_t dims[1] = {0};
  check(H5Tget_array_dims2(type, dims), where);
  Handle base = checked(H5Tget_super(type), H5Tclose, where);
  // A damaged type may claim any width: it must be sane and agree with the member's bytes.
  const std::size_t element = H5Tget_size(base.get());
  if (dims[0] < 1 || dims[0] > kMaxColumnWidth || element == 0 || dims[0] * element != H5Tget_size(type))
    throw TraceError(where + " is an array of " + std::to_string(dims[0]) + " elements that does not fit its " +
                     std::to_string(H5Tget_size(type)) + " bytes (damaged?)");
  c.width = static_cast<std::size_t>(dims[0]);
  c.element_class = H5Tget_class(base.get());
  if (c.element_class == H5T_COMPOUND || c.element_class == H5T_ARRAY)
    throw TraceError(where + " is an array of arrays or compounds, which no trace column is (damaged?)");
  c.element_size = element;
  c.element_signed = c.element_class == H5T_INTEGER && H5Tget_sign(base.get()) != H5T_SGN_NONE;
}

// The entity names of group `member`: the table's string attribute of that name, one a line.
std::vector<std::string> entity_names(hid_t dataset, const std::string& member, std::size_t count,
                                      const std::string& where) {
  if (!has_attribute(dataset, member, where))
    throw TraceError(where + " is an array of " + std::to_string(count) +
                     " entities, but the table has no attribute " + quoted(member) + " naming them");
  const std::string text = read_string_attribute(dataset, member, where);
  std::vector<std::string> names;
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    names.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  if (!text.empty() && text.back() == '\n') names.pop_back();
  if (names.size() != count)
    throw TraceError(where + " is an array of " + std::to_string(count) + " entities, but its attribute " +
                     quoted(member) + " names " + std::to_string(names.size()) + " (damaged?)");
  for (const std::string& n : names)
    if (n.empty() || n == "." || n == ".." || n.find('/') != std::string::npos)
      throw TraceError(where + ": entity name " + quoted(n) + " in attribute " + quoted(member) +
                       " cannot name a column (empty, '.', '..' or has '/')");
  return names;
}

// Entity group `member` (an array of compound elements) at offset `at`: a column per entity and
// field.
void add_entities(hid_t dataset, hid_t type, const std::string& member, std::size_t at, TableLayout& out,
                  const std::string& where) {
  if (H5Tget_array_ndims(type) != 1) throw TraceError(where + ": not a 1-D array member");
  hsize_t dims[1] = {0};
  check(H5Tget_array_dims2(type, dims), where);
  Handle element = checked(H5Tget_super(type), H5Tclose, where);
  const std::size_t stride = H5Tget_size(element.get());
  if (dims[0] < 1 || stride == 0 || H5Tget_size(type) / stride != dims[0] || H5Tget_size(type) % stride != 0)
    throw TraceError(where + " is an array of " + std::to_string(dims[0]) + " entities that does not fit its " +
                     std::to_string(H5Tget_size(type)) + " bytes (damaged?)");
  const std::vector<std::string> names = entity_names(dataset, member, static_cast<std::size_t>(dims[0]), where);
  const int fields = H5Tget_nmembers(element.get());
  check(fields, where);
  std::vector<StoredColumn> field(static_cast<std::size_t>(fields));
  for (int j = 0; j < fields; ++j) {
    StoredColumn& f = field[static_cast<std::size_t>(j)];
    f.name = member_name(element.get(), static_cast<unsigned>(j));
    const std::string here = where + ", field " + quoted(f.name);
    if (f.name.empty()) throw TraceError(here + ": a field without a name (damaged?)");
    Handle field_type = checked(H5Tget_member_type(element.get(), static_cast<unsigned>(j)), H5Tclose, here);
    set_element(field_type.get(), f, here);
    f.offset = H5Tget_member_offset(element.get(), static_cast<unsigned>(j));
    if (f.offset + f.width * f.element_size > stride) throw TraceError(here + ": lies outside its entity (damaged?)");
    f.attributes = member + "/" + f.name;
  }
  out.columns.reserve(out.columns.size() + names.size() * field.size());
  for (std::size_t e = 0; e < names.size(); ++e) {
    for (const StoredColumn& f : field) {
      StoredColumn c = f;
      c.name = member + "/" + names[e] + "/" + f.name;
      c.offset = at + e * stride + f.offset;
      out.columns.push_back(std::move(c));
    }
  }
}

}  // namespace

std::ptrdiff_t TableLayout::find(const std::string& name) const {
  for (std::size_t k = 0; k < columns.size(); ++k)
    if (columns[k].name == name) return static_cast<std::ptrdiff_t>(k);
  return -1;
}

std::vector<std::string> TableLayout::sorted_names() const {
  std::vector<std::string> names;
  names.reserve(columns.size());
  for (const StoredColumn& c : columns) names.push_back(c.name);
  std::sort(names.begin(), names.end());
  return names;
}

bool is_table(hid_t dataset, const std::string& context) {
  Handle type = checked(H5Dget_type(dataset), H5Tclose, context);
  return H5Tget_class(type.get()) == H5T_COMPOUND;
}

Handle packed_native(hid_t type, const std::string& context) {
  switch (H5Tget_class(type)) {
    case H5T_COMPOUND: {
      Handle out = checked(H5Tcreate(H5T_COMPOUND, H5Tget_size(type)), H5Tclose, context);
      const int members = H5Tget_nmembers(type);
      check(members, context);
      for (unsigned k = 0; k < static_cast<unsigned>(members); ++k) {
        Handle member = checked(H5Tget_member_type(type, k), H5Tclose, context);
        Handle native = packed_native(member.get(), context);
        if (H5Tget_size(native.get()) != H5Tget_size(member.get()))
          throw TraceError(context + ": member " + quoted(member_name(type, k)) + " has no native type of its size");
        check(H5Tinsert(out.get(), member_name(type, k).c_str(), H5Tget_member_offset(type, k), native.get()), context);
      }
      return out;
    }
    case H5T_ARRAY: {
      const int rank = H5Tget_array_ndims(type);
      if (rank < 1 || rank > H5S_MAX_RANK) throw TraceError(context + ": an array of rank " + std::to_string(rank));
      std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
      check(H5Tget_array_dims2(type, dims.data()), context);
      Handle base = checked(H5Tget_super(type), H5Tclose, context);
      Handle native = packed_native(base.get(), context);
      return checked(H5Tarray_create2(native.get(), static_cast<unsigned>(rank), dims.data()), H5Tclose, context);
    }
    default:
      return checked(H5Tget_native_type(type, H5T_DIR_ASCEND), H5Tclose, context);
  }
}

TableLayout table_layout(hid_t dataset, const std::string& context, bool groups) {
  TableLayout out;
  Handle type = checked(H5Dget_type(dataset), H5Tclose, context);
  if (H5Tget_class(type.get()) != H5T_COMPOUND) throw TraceError(context + ": not a table (no compound rows)");
  out.native = packed_native(type.get(), context);
  out.row_bytes = H5Tget_size(type.get());
  const int members = H5Tget_nmembers(type.get());
  check(members, context);
  for (int k = 0; k < members; ++k) {
    const std::string name = member_name(type.get(), static_cast<unsigned>(k));
    const std::string where = context + ", member " + quoted(name);
    if (name.empty()) throw TraceError(where + ": a member without a name (damaged?)");
    Handle member = checked(H5Tget_member_type(type.get(), static_cast<unsigned>(k)), H5Tclose, where);
    const std::size_t at = H5Tget_member_offset(type.get(), static_cast<unsigned>(k));
    if (at + H5Tget_size(member.get()) > out.row_bytes) throw TraceError(where + ": lies outside its row (damaged?)");
    if (H5Tget_class(member.get()) == H5T_ARRAY) {
      Handle base = checked(H5Tget_super(member.get()), H5Tclose, where);
      if (H5Tget_class(base.get()) == H5T_COMPOUND) {
        if (groups) add_entities(dataset, member.get(), name, at, out, where);
        continue;
      }
    }
    StoredColumn c;
    c.name = name;
    c.attributes = name;
    c.offset = at;
    set_element(member.get(), c, where);
    out.columns.push_back(std::move(c));
  }
  // Names that repeat (a group's entity and a member of the same path) would make one column two.
  std::vector<std::string> names = out.sorted_names();
  const auto twice = std::adjacent_find(names.begin(), names.end());
  if (twice != names.end()) throw TraceError(context + ": column " + quoted(*twice) + " is stored twice (damaged?)");
  return out;
}

}  // namespace graspsim::recordings::h5
