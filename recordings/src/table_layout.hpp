// The columns of a stored table as every reader here sees them, whatever the layout: where each
// column's values sit in a row of the table's native row type, its element type, and where its
// attributes are. One place knows the layouts (recordings/README.md "Schema"):
//   - schema 3 and 4: a plain member of the compound row is one column ("tick",
//     "objects/box/position" in schema 3), its attributes "<member>/<name>" on the table;
//   - schema 4: a member that is an array of compound elements is a group of entities (bodies,
//     fingers), named by the table's string attribute of the member's name (one name a line);
//     field f of entity e is column "<member>/<e>/<f>", its attributes "<member>/<f>/<name>",
//     shared by every entity.
// The trace reader, compare and through them replay, the viewer and Python read tables only
// through this.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "h5.hpp"

namespace graspsim::recordings::h5 {

// One column of a table: a member, or one entity's field of an entity group.
struct StoredColumn {
  std::string name;          // relative to the table: "tick", "objects/box/position"
  std::string attributes;    // prefix of its attributes' names on the table: its name, or
                             //   "objects/position" for a field of an entity group
  std::size_t offset = 0;    // bytes into a row (TableLayout::native, the stored offsets)
  std::size_t width = 1;     // values per row
  H5T_class_t element_class = H5T_FLOAT;   // H5T_FLOAT, H5T_INTEGER, or another class (unread)
  std::size_t element_size = 8;            // bytes of one value
  bool element_signed = true;              // integers
};

struct TableLayout {
  Handle native;             // what a row is read as: packed_native(the table's type)
  std::size_t row_bytes = 0; // its size, the stored row's
  std::vector<StoredColumn> columns;   // in stored order (an entity group's entity by entity)
  // The index of column `name`, or -1.
  std::ptrdiff_t find(const std::string& name) const;
  // The names of the columns, sorted.
  std::vector<std::string> sorted_names() const;
};

// `type` with every number in its native form at the same offsets, in the same sizes: the
// stored type itself for a trace written on a little-endian machine (as graspsim writes them), so
// HDF5 reads rows without converting them. (H5Tget_native_type would align the members instead,
// and converting an array of compound elements costs libhdf5 1.10 a zeroed buffer of the array's
// size times its length per row: 14 GB a row for 20,000 entities of 36 bytes.)
Handle packed_native(hid_t type, const std::string& context);

// Whether `dataset` is a table (a dataset of compound rows).
bool is_table(hid_t dataset, const std::string& context);

// The columns of table `dataset`. Throws TraceError(context + ...) for a type no graspsim writes
// or a damaged one: an array member that is not 1-D or wider than kMaxColumnWidth, an entity
// group without its names attribute or with another number of names than elements, a field of
// an entity that is itself a compound or a nested array, names that repeat.
// `groups` false: only the members of their own, without reading any group's names (what a reader
// of `tick` needs, even where a group's names are damaged).
TableLayout table_layout(hid_t dataset, const std::string& context, bool groups = true);

}  // namespace graspsim::recordings::h5
