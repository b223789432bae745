// The HDF5 side of a table's row: each column's dtype as a file and a memory type, the compound
// row type built from the columns, and the check that a value fits an integer column.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "graspsim/recordings/trace_writer.hpp"
#include "h5.hpp"

namespace graspsim::recordings::writer {

struct Column {
  std::string name;      // member name, relative to the table: "fingers/thumb/hip"
  int width;             // values per row
  DType dtype;
  std::size_t offset;    // doubles into a row of the block buffer
  std::size_t bytes;     // bytes into a packed compound row
};

hid_t file_type_of(DType dtype);     // little-endian, as stored
hid_t memory_type_of(DType dtype);   // native

// Whether a row value (a double) is an integer in the range of integer dtype `dtype`: false for
// a fraction, NaN or an infinity, or a value out of range.
bool fits(double value, DType dtype);

// The compound type of a row: one member per column in declaration order, packed into `bytes`;
// array members for width > 1. `memory`: native types, else the file's.
h5::Handle row_type(const std::vector<Column>& columns, std::size_t bytes, bool memory,
                    const std::string& where);

// The size of the datatype message of a row of `columns` in the newest file format, which HDF5
// stores in one object header message of at most 64 KiB (kMaxRowTypeBytes).
std::size_t encoded_row_type_bytes(const std::vector<Column>& columns);

// The largest compound row type a table may have: 64 KiB (65535 bytes), kept clear of by 1.5 KB.
inline constexpr std::size_t kMaxRowTypeBytes = 64000;   // bytes

}  // namespace graspsim::recordings::writer
