// Row types of a trace table: dtype to HDF5 type, the compound row, its encoded size.
#include "row_type.hpp"

namespace graspsim::recordings::writer {

hid_t file_type_of(DType dtype) {
  switch (dtype) {
    case DType::kFloat64: return H5T_IEEE_F64LE;
    case DType::kInt64: return H5T_STD_I64LE;
    case DType::kInt32: return H5T_STD_I32LE;
    case DType::kInt8: return H5T_STD_I8LE;
    case DType::kUInt64: return H5T_STD_U64LE;
  }
  return H5T_IEEE_F64LE;
}

hid_t memory_type_of(DType dtype) {
  switch (dtype) {
    case DType::kFloat64: return H5T_NATIVE_DOUBLE;
    case DType::kInt64: return H5T_NATIVE_INT64;
    case DType::kInt32: return H5T_NATIVE_INT32;
    case DType::kInt8: return H5T_NATIVE_INT8;
    case DType::kUInt64: return H5T_NATIVE_UINT64;
  }
  return H5T_NATIVE_DOUBLE;
}

namespace {

// Inserts column `c` as member `name` at `bytes` of `type`: a number, or an array of them.
void insert_column(hid_t type, const std::string& name, std::size_t bytes, const Column& c, bool memory,
                   const std::string& where) {
  const hid_t base = memory ? memory_type_of(c.dtype) : file_type_of(c.dtype);
  if (c.width == 1) {
    h5::check(H5Tinsert(type, name.c_str(), bytes, base), where);
    return;
  }
  const hsize_t dims[1] = {static_cast<hsize_t>(c.width)};
  h5::Handle array = h5::checked(H5Tarray_create2(base, 1, dims), H5Tclose, where);
  h5::check(H5Tinsert(type, name.c_str(), bytes, array.get()), where);
}

// The member of group `g`: an array of one compound element per entity, a member per field.
h5::Handle group_type(const Group& g, bool memory, const std::string& where) {
  h5::Handle entity = h5::checked(H5Tcreate(H5T_COMPOUND, g.entity_bytes), H5Tclose, where);
  for (const Column& f : g.fields) insert_column(entity.get(), f.name, f.bytes, f, memory, where);
  const hsize_t dims[1] = {static_cast<hsize_t>(g.entities.size())};
  return h5::checked(H5Tarray_create2(entity.get(), 1, dims), H5Tclose, where);
}

// Bytes of a column's member in a version 3 type message (see encoded_row_type_bytes).
std::size_t encoded_member_bytes(const std::string& name, const Column& c) {
  return name.size() + 1 + 4 + (c.width > 1 ? 13 : 0) + (c.dtype == DType::kFloat64 ? 20 : 12);
}

}  // namespace

h5::Handle row_type(const std::vector<Column>& columns, const std::vector<Group>& groups, std::size_t bytes,
                    bool memory, const std::string& where) {
  h5::Handle type = h5::checked(H5Tcreate(H5T_COMPOUND, bytes), H5Tclose, where);
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const Column& c = columns[k];
    if (c.group < 0) {
      insert_column(type.get(), c.name, c.bytes, c, memory, where);
    } else if (groups[static_cast<std::size_t>(c.group)].first == k) {
      const Group& g = groups[static_cast<std::size_t>(c.group)];
      h5::Handle array = group_type(g, memory, where);
      h5::check(H5Tinsert(type.get(), g.name.c_str(), c.bytes, array.get()), where);
    }
  }
  return type;
}

// Version 3 compound and array types, as the file uses: an 8-byte type header, and per member
// its name with a NUL, a 4-byte offset (at most), an array header of 8 + 1 + 4 bytes if width >
// 1, and the element type, 20 bytes for a float, 12 for an integer; a group's member is an array
// header and a compound of its fields. (H5Tencode would give the oldest format's size, which pads
// names: 40% more.)
std::size_t encoded_row_type_bytes(const std::vector<Column>& columns, const std::vector<Group>& groups) {
  std::size_t encoded = 8;
  for (const Column& c : columns)
    if (c.group < 0) encoded += encoded_member_bytes(c.name, c);
  for (const Group& g : groups) {
    encoded += g.name.size() + 1 + 4 + 13 + 8;
    for (const Column& f : g.fields) encoded += encoded_member_bytes(f.name, f);
  }
  return encoded;
}

}  // namespace graspsim::recordings::writer
