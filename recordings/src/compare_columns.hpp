// The columns of a compared table and how their rows are read: a compound table a block of
// whole rows at a time, shared by its columns (TableRows), each column decoding its member
// from it (BlockReader); a schema 2 dataset in hyperslabs of its own.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "compare_input.hpp"
#include "h5.hpp"

namespace graspsim::recordings::compare {

enum class Kind { kFloat, kSigned, kUnsigned };

// The rows of one compound table of one file, a block at a time, in the file's row layout with
// native numbers (h5::packed_native: no conversion of a trace written on a little-endian host).
// All columns of the table decode their members from the same block, so a table is read once
// however many columns it has; row(r) may move back and forth within a block, forward across
// blocks.
struct TableRows {
  std::string file, path;          // for messages
  h5::Handle dataset;              // the table
  h5::Handle type;                 // the row type read: h5::packed_native of the table's
  std::size_t row_bytes = 0;
  std::int64_t rows = 0;           // rows to read (the usable length)
  std::int64_t block = 1;
  std::int64_t start = 0, count = 0;
  std::vector<unsigned char> bytes;

  const unsigned char* row(std::int64_t r) {
    if (r < start || r >= start + count) load(r);
    return bytes.data() + static_cast<std::size_t>(r - start) * row_bytes;
  }

  void load(std::int64_t r);   // reads the block of rows from r on
};

// One open dataset of an aligned table: its kind, rows and width.
struct Column {
  std::string file, path;   // path with a leading '/'
  h5::Handle dataset;       // the column's dataset (schema 2; not opened for a table's column)
  std::string member;       // the column of a compound table (table_layout.hpp), or "" 
  // A member: where its elements sit in a row as TableRows reads it, and how to
  // decode them (class, size in bytes, signed), read from the rows the table shares.
  TableRows* table_rows = nullptr;
  std::size_t member_offset = 0;
  H5T_class_t element_class = H5T_FLOAT;
  std::size_t element_size = 8;
  bool element_signed = true;
  Kind kind = Kind::kFloat;
  std::int64_t rows = 0;
  std::size_t width = 1;
  int rank = 1;
  std::string units;
  std::vector<std::string> order;   // the "order" attribute split at commas, if any
};

// Opens columns `names` of table `group` (a column's path is "/" + group + "/" + name): their
// kind, rows, width, units and components (the `order` attribute). A compound table's layout is
// read once for all of them (table_layout.hpp), each distinct attribute once.
std::vector<Column> open_columns(const OpenTrace& t, const std::string& group, const std::vector<std::string>& names);

// The native HDF5 type a column is read as: float64, int64 or uint64.
template <typename T>
hid_t memory_type() {
  if constexpr (std::is_same_v<T, double>) return H5T_NATIVE_DOUBLE;
  else if constexpr (std::is_same_v<T, std::int64_t>) return H5T_NATIVE_INT64;
  else return H5T_NATIVE_UINT64;
}

// Reads a column's rows in hyperslabs of `block` rows; row(r) must be asked in increasing r.
template <typename T>
class BlockReader {
 public:
  BlockReader(const Column& c, std::int64_t rows, std::size_t block)
      : c_(c), rows_(rows), block_(static_cast<std::int64_t>(std::max<std::size_t>(block, 1))) {}

  const T* row(std::int64_t r) {
    if (c_.table_rows != nullptr) return decode(c_.table_rows->row(r));
    if (r < start_ || r >= start_ + count_) load(r);
    return buffer_.data() + static_cast<std::size_t>(r - start_) * c_.width;
  }

 private:
  // The member's elements of one native row, converted to T (integers exactly; float64 and
  // uint64 bits as they are).
  const T* decode(const unsigned char* row) {
    buffer_.resize(c_.width);
    const unsigned char* p = row + c_.member_offset;
    for (std::size_t j = 0; j < c_.width; ++j, p += c_.element_size) {
      if (c_.element_class == H5T_FLOAT) {
        if (c_.element_size == 8) { double v; std::memcpy(&v, p, 8); buffer_[j] = static_cast<T>(v); }
        else { float v; std::memcpy(&v, p, 4); buffer_[j] = static_cast<T>(v); }
      } else if (c_.element_signed) {
        std::int64_t v = 0;
        switch (c_.element_size) {
          case 1: { std::int8_t x; std::memcpy(&x, p, 1); v = x; break; }
          case 2: { std::int16_t x; std::memcpy(&x, p, 2); v = x; break; }
          case 4: { std::int32_t x; std::memcpy(&x, p, 4); v = x; break; }
          default: std::memcpy(&v, p, 8); break;
        }
        buffer_[j] = static_cast<T>(v);
      } else {
        std::uint64_t v = 0;
        switch (c_.element_size) {
          case 1: { std::uint8_t x; std::memcpy(&x, p, 1); v = x; break; }
          case 2: { std::uint16_t x; std::memcpy(&x, p, 2); v = x; break; }
          case 4: { std::uint32_t x; std::memcpy(&x, p, 4); v = x; break; }
          default: std::memcpy(&v, p, 8); break;
        }
        buffer_[j] = static_cast<T>(v);
      }
    }
    return buffer_.data();
  }

  // A schema 2 dataset's rows (a compound table's columns decode from its TableRows instead).
  void load(std::int64_t r) {
    const std::string context = "trace " + quoted(c_.file) + ", dataset " + quoted(c_.path);
    start_ = r;
    count_ = std::min(block_, rows_ - r);
    buffer_.resize(static_cast<std::size_t>(count_) * c_.width);
    h5::Handle file_space = h5::checked(H5Dget_space(c_.dataset.get()), H5Sclose, context);
    const hsize_t offset[2] = {static_cast<hsize_t>(start_), 0};
    const hsize_t count[2] = {static_cast<hsize_t>(count_), c_.width};
    h5::check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, offset, nullptr, count,
                                  nullptr),
              context);
    h5::Handle mem_space = h5::checked(H5Screate_simple(c_.rank, count, nullptr), H5Sclose,
                                       context);
    h5::check(H5Dread(c_.dataset.get(), memory_type<T>(), mem_space.get(), file_space.get(),
                      H5P_DEFAULT, buffer_.data()),
              context + ": cannot read rows " + std::to_string(start_) + " to " +
                  std::to_string(start_ + count_ - 1));
  }

  const Column& c_;
  std::int64_t rows_;
  std::int64_t block_;
  std::int64_t start_ = 0, count_ = 0;
  std::vector<T> buffer_;
};

// The first `rows` rows of a column, whole, row-major (its tick or time column).
template <typename T>
std::vector<T> read_all(const Column& c, std::int64_t rows, std::size_t block) {
  std::vector<T> out(static_cast<std::size_t>(rows) * c.width);
  BlockReader<T> reader(c, rows, block);
  for (std::int64_t r = 0; r < rows; ++r) {
    const T* p = reader.row(r);
    std::copy(p, p + c.width, out.begin() + static_cast<std::ptrdiff_t>(r * c.width));
  }
  return out;
}

}  // namespace graspsim::recordings::compare
