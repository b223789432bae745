// Test helpers that edit a closed trace in place, through the HDF5 C API: read or rewrite one
// element of a column, or drop a column. A column "/physics/objects/box/position" is member
// "objects/box/position" of the compound table dataset "/physics" (schema 3); one row of it is
// read and written through a memory type that holds only that member, so nothing else changes.
#pragma once

#include <catch2/catch.hpp>
#include <hdf5.h>

#include <string>
#include <vector>

namespace graspsim::test {

// Row `row` of column `path` of `file`: read into `values` (resized to the column's width), or
// with `write`, written from it.
inline void access_row(const std::string& file, const std::string& path, hsize_t row,
                       std::vector<double>& values, bool write) {
  const hid_t f = H5Fopen(file.c_str(), write ? H5F_ACC_RDWR : H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(f >= 0);
  const std::size_t cut = path.find('/', 1);
  REQUIRE(cut != std::string::npos);
  const std::string table = path.substr(0, cut), member = path.substr(cut + 1);
  const hid_t d = H5Dopen2(f, table.c_str(), H5P_DEFAULT);
  REQUIRE(d >= 0);
  const hid_t row_type = H5Dget_type(d);
  const int index = H5Tget_member_index(row_type, member.c_str());
  INFO("column " << path << " of " << file);
  REQUIRE(index >= 0);
  const hid_t member_type = H5Tget_member_type(row_type, static_cast<unsigned>(index));
  hsize_t width = 1;
  if (H5Tget_class(member_type) == H5T_ARRAY) H5Tget_array_dims2(member_type, &width);
  const hid_t field = width > 1 ? H5Tarray_create2(H5T_NATIVE_DOUBLE, 1, &width) : H5Tcopy(H5T_NATIVE_DOUBLE);
  const hid_t memory_type = H5Tcreate(H5T_COMPOUND, sizeof(double) * width);
  REQUIRE(H5Tinsert(memory_type, member.c_str(), 0, field) >= 0);
  const hid_t space = H5Dget_space(d);
  const hsize_t one = 1;
  REQUIRE(H5Sselect_hyperslab(space, H5S_SELECT_SET, &row, nullptr, &one, nullptr) >= 0);
  const hid_t memory = H5Screate_simple(1, &one, nullptr);
  if (!write) values.assign(width, 0.0);
  REQUIRE(values.size() == width);
  if (write) REQUIRE(H5Dwrite(d, memory_type, memory, space, H5P_DEFAULT, values.data()) >= 0);
  else REQUIRE(H5Dread(d, memory_type, memory, space, H5P_DEFAULT, values.data()) >= 0);
  H5Sclose(memory);
  H5Sclose(space);
  H5Tclose(memory_type);
  H5Tclose(field);
  H5Tclose(member_type);
  H5Tclose(row_type);
  H5Dclose(d);
  H5Fclose(f);
}

// Element (row, component) of column `path`.
inline double get_element(const std::string& file, const std::string& path, hsize_t row,
                          hsize_t component) {
  std::vector<double> values;
  access_row(file, path, row, values, false);
  REQUIRE(component < values.size());
  return values[component];
}

// Sets element (row, component) of column `path` to `value`.
inline void set_element(const std::string& file, const std::string& path, hsize_t row,
                        hsize_t component, double value) {
  std::vector<double> values;
  access_row(file, path, row, values, false);
  REQUIRE(component < values.size());
  values[component] = value;
  access_row(file, path, row, values, true);
}

// Adds `delta` to element (row, component) of column `path`; returns the new value.
inline double add_to_element(const std::string& file, const std::string& path, hsize_t row,
                             hsize_t component, double delta) {
  const double value = get_element(file, path, row, component) + delta;
  set_element(file, path, row, component, value);
  return value;
}

// Rewrites table `table` ("/physics") of `file` without column `member` (a trace one column
// short; the copy is contiguous and keeps no attributes).
inline void drop_column(const std::string& file, const std::string& table, const std::string& member) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  REQUIRE(f >= 0);
  const hid_t d = H5Dopen2(f, table.c_str(), H5P_DEFAULT);
  REQUIRE(d >= 0);
  const hid_t row_type = H5Dget_type(d);
  // The same members but one, packed: H5Dread converts each row to it by member name.
  const int n = H5Tget_nmembers(row_type);
  std::vector<std::pair<std::string, hid_t>> kept;
  std::size_t size = 0;
  for (int k = 0; k < n; ++k) {
    char* name = H5Tget_member_name(row_type, static_cast<unsigned>(k));
    const hid_t t = H5Tget_member_type(row_type, static_cast<unsigned>(k));
    if (member != name) {
      kept.emplace_back(name, t);
      size += H5Tget_size(t);
    } else {
      H5Tclose(t);
    }
    H5free_memory(name);
  }
  REQUIRE(static_cast<int>(kept.size()) == n - 1);
  const hid_t fewer = H5Tcreate(H5T_COMPOUND, size);
  std::size_t offset = 0;
  for (const auto& [name, t] : kept) {
    REQUIRE(H5Tinsert(fewer, name.c_str(), offset, t) >= 0);
    offset += H5Tget_size(t);
    H5Tclose(t);
  }
  const hid_t space = H5Dget_space(d);
  const hssize_t rows = H5Sget_simple_extent_npoints(space);
  std::vector<unsigned char> data(size * static_cast<std::size_t>(rows));
  REQUIRE(H5Dread(d, fewer, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) >= 0);
  H5Dclose(d);
  H5Sclose(space);
  REQUIRE(H5Ldelete(f, table.c_str(), H5P_DEFAULT) >= 0);
  const hsize_t dims[1] = {static_cast<hsize_t>(rows)};
  const hid_t fixed = H5Screate_simple(1, dims, nullptr);   // contiguous: no unlimited rows
  const hid_t copy = H5Dcreate2(f, table.c_str(), fewer, fixed, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  REQUIRE(copy >= 0);
  REQUIRE(H5Dwrite(copy, fewer, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) >= 0);
  H5Dclose(copy);
  H5Sclose(fixed);
  H5Tclose(fewer);
  H5Tclose(row_type);
  H5Fclose(f);
}

}  // namespace graspsim::test
