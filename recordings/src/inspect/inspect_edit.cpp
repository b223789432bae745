// The schema-free view: one row of a compound member read or written, and the edits fault tests
// make (an extent set, a member dropped, groups and datasets created).
#include <algorithm>
#include <cstring>

#include "inspect_detail.hpp"

namespace graspsim::recordings::inspect {

using detail::check;
using detail::Guard;
using detail::own;
using detail::where;

namespace {

// Row `row` of member `member` of compound dataset `dataset`, through a memory type that holds
// only that member as doubles: HDF5 converts it and leaves every other member alone.
void access_member_row(hid_t file, const std::string& at, const std::string& dataset, const std::string& member,
                       std::uint64_t row, std::vector<double>& values, bool write) {
  const std::string here = at + ": member '" + member + "'";
  h5::Handle d = detail::open_dataset(file, dataset, at);
  h5::Handle row_type = own(H5Dget_type(d.get()), H5Tclose, at);
  if (H5Tget_class(row_type.get()) != H5T_COMPOUND) throw InspectError(at + " is not a compound dataset");
  const int index = H5Tget_member_index(row_type.get(), member.c_str());
  if (index < 0) throw InspectError(here + " does not exist");
  h5::Handle member_type = own(H5Tget_member_type(row_type.get(), static_cast<unsigned>(index)), H5Tclose, here);
  h5::Handle field;
  std::size_t width = 1;
  if (H5Tget_class(member_type.get()) == H5T_ARRAY) {
    const int rank = H5Tget_array_ndims(member_type.get());
    check(rank, here);
    std::vector<hsize_t> extent(static_cast<std::size_t>(rank));
    check(H5Tget_array_dims2(member_type.get(), extent.data()), here);
    for (hsize_t e : extent) width *= e;
    field = own(H5Tarray_create2(H5T_NATIVE_DOUBLE, static_cast<unsigned>(rank), extent.data()), H5Tclose, here);
  } else {
    field = own(H5Tcopy(H5T_NATIVE_DOUBLE), H5Tclose, here);
  }
  h5::Handle memory_type = own(H5Tcreate(H5T_COMPOUND, sizeof(double) * width), H5Tclose, here);
  check(H5Tinsert(memory_type.get(), member.c_str(), 0, field.get()), here);
  h5::Handle space = own(H5Dget_space(d.get()), H5Sclose, at);
  const hsize_t start = row, one = 1;
  check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, &start, nullptr, &one, nullptr), here);
  h5::Handle memory = own(H5Screate_simple(1, &one, nullptr), H5Sclose, here);
  const std::string row_text = here + ", row " + std::to_string(row);
  if (write) {
    if (values.size() != width)
      throw InspectError(row_text + ": " + std::to_string(values.size()) + " values for a width of " + std::to_string(width));
    check(H5Dwrite(d.get(), memory_type.get(), memory.get(), space.get(), H5P_DEFAULT, values.data()),
          row_text + ": cannot write it");
  } else {
    values.assign(width, 0.0);
    check(H5Dread(d.get(), memory_type.get(), memory.get(), space.get(), H5P_DEFAULT, values.data()),
          row_text + ": cannot read it");
  }
}

// Row `row` of field `field` of element `index` of member `member` (an array of compound
// elements) of compound dataset `dataset`: the member's row is read as stored, the field's values
// converted to doubles by H5Tconvert (and back, for a write, which rewrites the member's row).
void access_element_row(hid_t file, const std::string& at, const std::string& dataset, const std::string& member,
                        std::uint64_t index, const std::string& field, std::uint64_t row, std::vector<double>& values,
                        bool write) {
  const std::string here = at + ": member '" + member + "' element " + std::to_string(index) + " field '" + field + "'";
  h5::Handle d = detail::open_dataset(file, dataset, at);
  h5::Handle row_type = own(H5Dget_type(d.get()), H5Tclose, at);
  if (H5Tget_class(row_type.get()) != H5T_COMPOUND) throw InspectError(at + " is not a compound dataset");
  const int k = H5Tget_member_index(row_type.get(), member.c_str());
  if (k < 0) throw InspectError(here + ": no such member");
  h5::Handle array = own(H5Tget_member_type(row_type.get(), static_cast<unsigned>(k)), H5Tclose, here);
  if (H5Tget_class(array.get()) != H5T_ARRAY) throw InspectError(here + ": the member is not an array");
  h5::Handle element = own(H5Tget_super(array.get()), H5Tclose, here);
  const int f = H5Tget_member_index(element.get(), field.c_str());
  if (H5Tget_class(element.get()) != H5T_COMPOUND || f < 0) throw InspectError(here + ": no such field");
  const std::size_t element_bytes = H5Tget_size(element.get());
  if (index >= H5Tget_size(array.get()) / element_bytes) throw InspectError(here + ": no such element");
  h5::Handle field_type = own(H5Tget_member_type(element.get(), static_cast<unsigned>(f)), H5Tclose, here);
  std::size_t width = 1;
  h5::Handle base = own(H5Tcopy(field_type.get()), H5Tclose, here);
  if (H5Tget_class(field_type.get()) == H5T_ARRAY) {
    width = H5Tget_size(field_type.get());
    base = own(H5Tget_super(field_type.get()), H5Tclose, here);
    width /= H5Tget_size(base.get());
  }
  // The member alone, as stored, picked out of the row.
  h5::Handle memory_type = own(H5Tcreate(H5T_COMPOUND, H5Tget_size(array.get())), H5Tclose, here);
  check(H5Tinsert(memory_type.get(), member.c_str(), 0, array.get()), here);
  h5::Handle space = own(H5Dget_space(d.get()), H5Sclose, at);
  const hsize_t start = row, one = 1;
  check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, &start, nullptr, &one, nullptr), here);
  h5::Handle memory = own(H5Screate_simple(1, &one, nullptr), H5Sclose, here);
  std::vector<unsigned char> bytes(H5Tget_size(array.get()));
  const std::string row_text = here + ", row " + std::to_string(row);
  check(H5Dread(d.get(), memory_type.get(), memory.get(), space.get(), H5P_DEFAULT, bytes.data()), row_text + ": cannot read it");
  unsigned char* at_field = bytes.data() + index * element_bytes + H5Tget_member_offset(element.get(), static_cast<unsigned>(f));
  const std::size_t stored = H5Tget_size(base.get());
  std::vector<unsigned char> buffer(width * std::max<std::size_t>(stored, sizeof(double)));
  if (!write) {
    std::memcpy(buffer.data(), at_field, width * stored);
    check(H5Tconvert(base.get(), H5T_NATIVE_DOUBLE, width, buffer.data(), nullptr, H5P_DEFAULT), row_text);
    values.assign(width, 0.0);
    std::memcpy(values.data(), buffer.data(), width * sizeof(double));
    return;
  }
  if (values.size() != width)
    throw InspectError(row_text + ": " + std::to_string(values.size()) + " values for a width of " + std::to_string(width));
  std::memcpy(buffer.data(), values.data(), width * sizeof(double));
  check(H5Tconvert(H5T_NATIVE_DOUBLE, base.get(), width, buffer.data(), nullptr, H5P_DEFAULT), row_text);
  std::memcpy(at_field, buffer.data(), width * stored);
  check(H5Dwrite(d.get(), memory_type.get(), memory.get(), space.get(), H5P_DEFAULT, bytes.data()),
        row_text + ": cannot write it");
}

void create_1d(hid_t file, const std::string& at, const std::string& path, hid_t file_type, hid_t memory_type,
               const void* values, std::size_t count, std::uint64_t chunk_rows) {
  const hsize_t dims[1] = {count}, max_dims[1] = {H5S_UNLIMITED}, chunk[1] = {chunk_rows};
  h5::Handle space = own(H5Screate_simple(1, dims, max_dims), H5Sclose, at);
  h5::Handle dcpl = own(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, at);
  check(H5Pset_chunk(dcpl.get(), 1, chunk), at);
  h5::Handle d = own(H5Dcreate2(file, path.c_str(), file_type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
                     H5Dclose, at);
  if (count > 0) check(H5Dwrite(d.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values), at);
}

}  // namespace

std::vector<double> File::read_member_row(const std::string& dataset, const std::string& member,
                                          std::uint64_t row) const {
  Guard guard;
  std::vector<double> values;
  access_member_row(handles_->file.get(), where(path_, dataset), dataset, member, row, values, false);
  return values;
}

void File::write_member_row(const std::string& dataset, const std::string& member, std::uint64_t row,
                            const std::vector<double>& values) {
  Guard guard;
  std::vector<double> copy = values;
  access_member_row(handles_->file.get(), where(path_, dataset), dataset, member, row, copy, true);
}

std::vector<double> File::read_element_row(const std::string& dataset, const std::string& member, std::uint64_t index,
                                           const std::string& field, std::uint64_t row) const {
  Guard guard;
  std::vector<double> values;
  access_element_row(handles_->file.get(), where(path_, dataset), dataset, member, index, field, row, values, false);
  return values;
}

void File::write_element_row(const std::string& dataset, const std::string& member, std::uint64_t index,
                             const std::string& field, std::uint64_t row, const std::vector<double>& values) {
  Guard guard;
  std::vector<double> copy = values;
  access_element_row(handles_->file.get(), where(path_, dataset), dataset, member, index, field, row, copy, true);
}

void File::set_extent(const std::string& dataset, const std::vector<std::uint64_t>& dims) {
  Guard guard;
  const std::string at = where(path_, dataset);
  h5::Handle d = detail::open_dataset(handles_->file.get(), dataset, at);
  h5::Handle space = own(H5Dget_space(d.get()), H5Sclose, at);
  if (H5Sget_simple_extent_ndims(space.get()) != static_cast<int>(dims.size()))
    throw InspectError(at + ": an extent of " + std::to_string(dims.size()) + " dimensions for a dataset of another rank");
  const std::vector<hsize_t> extent(dims.begin(), dims.end());
  check(H5Dset_extent(d.get(), extent.data()), at + ": cannot set its extent");
}

namespace {

// `type` (a compound) without member `name`, packed: nullopt-like (invalid) if it has no such member.
h5::Handle without(hid_t type, const std::string& name, const std::string& at) {
  const int n = H5Tget_nmembers(type);
  check(n, at);
  std::vector<std::pair<std::string, h5::Handle>> kept;
  std::size_t size = 0;
  for (unsigned k = 0; k < static_cast<unsigned>(n); ++k) {
    char* member = H5Tget_member_name(type, k);
    const std::string text = member != nullptr ? member : "";
    H5free_memory(member);
    if (text == name) continue;
    h5::Handle t = own(H5Tget_member_type(type, k), H5Tclose, at);
    size += H5Tget_size(t.get());
    kept.emplace_back(text, std::move(t));
  }
  if (static_cast<int>(kept.size()) != n - 1) return h5::Handle();
  h5::Handle fewer = own(H5Tcreate(H5T_COMPOUND, size), H5Tclose, at);
  std::size_t offset = 0;
  for (const auto& [text, t] : kept) {
    check(H5Tinsert(fewer.get(), text.c_str(), offset, t.get()), at);
    offset += H5Tget_size(t.get());
  }
  return fewer;
}

// The row type without `member`: a member of the row, or "<m>/<field>", a field of the compound
// elements of array member <m>.
h5::Handle row_without(hid_t row_type, const std::string& member, const std::string& at) {
  h5::Handle fewer = without(row_type, member, at);
  const std::size_t slash = member.find('/');
  if (fewer.valid() || slash == std::string::npos) return fewer;
  const std::string outer = member.substr(0, slash), field = member.substr(slash + 1);
  const int k = H5Tget_member_index(row_type, outer.c_str());
  if (k < 0) return fewer;
  h5::Handle array = own(H5Tget_member_type(row_type, static_cast<unsigned>(k)), H5Tclose, at);
  if (H5Tget_class(array.get()) != H5T_ARRAY || H5Tget_array_ndims(array.get()) != 1) return fewer;
  h5::Handle element = own(H5Tget_super(array.get()), H5Tclose, at);
  if (H5Tget_class(element.get()) != H5T_COMPOUND) return fewer;
  h5::Handle smaller = without(element.get(), field, at);
  if (!smaller.valid()) return fewer;
  hsize_t dims[1] = {0};
  check(H5Tget_array_dims2(array.get(), dims), at);
  h5::Handle narrower = own(H5Tarray_create2(smaller.get(), 1, dims), H5Tclose, at);
  // The row again with the narrower member in place of the old one.
  h5::Handle rest = without(row_type, outer, at);
  h5::Handle out = own(H5Tcreate(H5T_COMPOUND, H5Tget_size(rest.get()) + H5Tget_size(narrower.get())), H5Tclose, at);
  std::size_t offset = 0;
  const int n = H5Tget_nmembers(row_type);
  for (unsigned j = 0; j < static_cast<unsigned>(n); ++j) {
    char* name = H5Tget_member_name(row_type, j);
    const std::string text = name != nullptr ? name : "";
    H5free_memory(name);
    h5::Handle t = text == outer ? own(H5Tcopy(narrower.get()), H5Tclose, at) : own(H5Tget_member_type(row_type, j), H5Tclose, at);
    check(H5Tinsert(out.get(), text.c_str(), offset, t.get()), at);
    offset += H5Tget_size(t.get());
  }
  return out;
}

// Copies every attribute of `from` to `to`, with its own type and shape.
void copy_attributes(hid_t from, hid_t to, const std::string& at) {
  std::vector<std::string> names;
  const auto collect = [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->push_back(name);
    return 0;
  };
  hsize_t index = 0;
  check(H5Aiterate2(from, H5_INDEX_NAME, H5_ITER_INC, &index, collect, &names), at + ": cannot list its attributes");
  for (const std::string& name : names) {
    const std::string here = at + ": attribute '" + name + "'";
    h5::Handle attribute = own(H5Aopen(from, name.c_str(), H5P_DEFAULT), H5Aclose, here);
    h5::Handle type = own(H5Aget_type(attribute.get()), H5Tclose, here);
    h5::Handle space = own(H5Aget_space(attribute.get()), H5Sclose, here);
    const hssize_t points = H5Sget_simple_extent_npoints(space.get());
    std::vector<unsigned char> buffer(H5Tget_size(type.get()) * static_cast<std::size_t>(std::max<hssize_t>(points, 1)));
    check(H5Aread(attribute.get(), type.get(), buffer.data()), here);
    h5::Handle copy = own(H5Acreate2(to, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, here);
    const herr_t written = H5Awrite(copy.get(), type.get(), buffer.data());
    if (H5Tdetect_class(type.get(), H5T_VLEN) > 0 || H5Tis_variable_str(type.get()) > 0)
      H5Dvlen_reclaim(type.get(), space.get(), H5P_DEFAULT, buffer.data());
    check(written, here);
  }
}

}  // namespace

void File::drop_member(const std::string& dataset, const std::string& member) {
  Guard guard;
  const std::string at = where(path_, dataset) + ": cannot drop member '" + member + "'";
  const hid_t file = handles_->file.get();
  h5::Handle d = detail::open_dataset(file, dataset, at);
  h5::Handle row_type = own(H5Dget_type(d.get()), H5Tclose, at);
  if (H5Tget_class(row_type.get()) != H5T_COMPOUND) throw InspectError(at + ": not a compound dataset");
  // The same members but one, packed: H5Dread converts each row to it by member name.
  h5::Handle fewer = row_without(row_type.get(), member, at);
  if (!fewer.valid()) throw InspectError(at + ": no such member");
  const std::size_t size = H5Tget_size(fewer.get());
  h5::Handle space = own(H5Dget_space(d.get()), H5Sclose, at);
  const hssize_t rows = H5Sget_simple_extent_npoints(space.get());
  check(rows < 0 ? -1 : 0, at);
  std::vector<unsigned char> data(size * static_cast<std::size_t>(rows));
  check(H5Dread(d.get(), fewer.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), at);
  // Written beside it, its attributes copied, then put in its place.
  const std::string temporary = dataset + ".dropping";
  const hsize_t dims[1] = {static_cast<hsize_t>(rows)};
  h5::Handle fixed = own(H5Screate_simple(1, dims, nullptr), H5Sclose, at);   // contiguous: no unlimited rows
  h5::Handle copy = own(H5Dcreate2(file, temporary.c_str(), fewer.get(), fixed.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                        H5Dclose, at);
  check(H5Dwrite(copy.get(), fewer.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), at);
  copy_attributes(d.get(), copy.get(), at);
  copy.reset();
  d.reset();
  space.reset();
  check(H5Ldelete(file, dataset.c_str(), H5P_DEFAULT), at);
  check(H5Lmove(file, temporary.c_str(), file, dataset.c_str(), H5P_DEFAULT, H5P_DEFAULT), at);
}

void File::create_group(const std::string& path) {
  Guard guard;
  own(H5Gcreate2(handles_->file.get(), path.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
      where(path_, path) + ": cannot create the group");
}

void File::create_dataset(const std::string& path, const std::vector<std::int64_t>& values, std::uint64_t chunk_rows) {
  Guard guard;
  create_1d(handles_->file.get(), where(path_, path) + ": cannot create the dataset", path, H5T_STD_I64LE,
            H5T_NATIVE_INT64, values.data(), values.size(), chunk_rows);
}

void File::create_dataset(const std::string& path, const std::vector<double>& values, std::uint64_t chunk_rows) {
  Guard guard;
  create_1d(handles_->file.get(), where(path_, path) + ": cannot create the dataset", path, H5T_IEEE_F64LE,
            H5T_NATIVE_DOUBLE, values.data(), values.size(), chunk_rows);
}

}  // namespace graspsim::recordings::inspect
