// The HDF5 side of a table's row: each column's dtype as a file and a memory type, the compound
// row type built from the columns, and the check that a value fits an integer column.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "graspsim/recordings/trace_writer.hpp"
#include "h5.hpp"

namespace graspsim::recordings::writer {

struct Column {
  std::string name;      // column path, relative to the table: "tick", "fingers/thumb/hip"
  int width;             // values per row
  DType dtype;
  std::size_t offset;    // doubles into a row of the block buffer
  std::size_t bytes;     // bytes into a packed compound row
  int group = -1;        // the entity group it is a field of (index into the groups), or -1:
                         //   a member of its own
};

// Columns repeated per entity (a body, a finger), stored as one member of the row: an array of
// one compound element per entity, a member per field (recordings/README.md "Schema"). Its
// columns are also listed one per entity and field (Column::group), contiguous, entity by entity,
// so that rows are packed as any other columns are.
struct Group {
  std::string name;                     // member name: "objects"
  std::vector<std::string> entities;    // in row order
  std::vector<Column> fields;           // field name, width, dtype; offset and bytes within an entity
  std::size_t first = 0;                // index of its first column (entity 0, field 0)
  std::size_t entity_bytes = 0;         // bytes of one entity's packed fields
};

hid_t file_type_of(DType dtype);     // little-endian, as stored
hid_t memory_type_of(DType dtype);   // native

// Inclusive range of an integer dtype as doubles (both ends exact in double). int64's upper
// end 2^63 - 1 is not a double, so that check is "below 2^63" (see fits()).
constexpr double lowest(DType dtype) {
  switch (dtype) {
    case DType::kInt64: return -9223372036854775808.0;   // -2^63
    case DType::kInt32: return -2147483648.0;
    case DType::kInt8: return -128.0;
    case DType::kFloat64: case DType::kUInt64: break;
  }
  return 0.0;
}

constexpr double highest(DType dtype) {
  switch (dtype) {
    case DType::kInt64: return 9223372036854775808.0;    // 2^63, exclusive
    case DType::kInt32: return 2147483647.0;
    case DType::kInt8: return 127.0;
    case DType::kFloat64: case DType::kUInt64: break;
  }
  return 0.0;
}

// Whether a row value (a double) is an integer in the range of integer dtype `dtype`: false for
// a fraction, NaN or an infinity, or a value out of range. Inline: called for every integer
// value of every row written.
inline bool fits(double value, DType dtype) {
  if (!(value == std::trunc(value))) return false;   // also rejects NaN and infinities
  if (value < lowest(dtype)) return false;
  return dtype == DType::kInt64 ? value < highest(dtype) : value <= highest(dtype);
}

// The compound type of a row: one member per column of no group in declaration order, array
// members for width > 1, and one member per group, where its first column is, an array of one
// compound element per entity; packed into `bytes`. `memory`: native types, else the file's.
h5::Handle row_type(const std::vector<Column>& columns, const std::vector<Group>& groups, std::size_t bytes,
                    bool memory, const std::string& where);

// The size of the datatype message of that row type in the newest file format, which HDF5 stores
// in one object header message of at most 64 KiB (kMaxRowTypeBytes). A group counts once,
// whatever its number of entities.
std::size_t encoded_row_type_bytes(const std::vector<Column>& columns, const std::vector<Group>& groups);

// The largest compound row type a table may have: 64 KiB (65535 bytes), kept clear of by 1.5 KB.
inline constexpr std::size_t kMaxRowTypeBytes = 64000;   // bytes

}  // namespace graspsim::recordings::writer
