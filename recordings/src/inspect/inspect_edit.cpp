// The schema-free view: one row of a compound member read or written, and the edits fault tests
// make (an extent set, a member dropped, groups and datasets created).
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

void File::drop_member(const std::string& dataset, const std::string& member) {
  Guard guard;
  const std::string at = where(path_, dataset) + ": cannot drop member '" + member + "'";
  const hid_t file = handles_->file.get();
  h5::Handle d = detail::open_dataset(file, dataset, at);
  h5::Handle row_type = own(H5Dget_type(d.get()), H5Tclose, at);
  if (H5Tget_class(row_type.get()) != H5T_COMPOUND) throw InspectError(at + ": not a compound dataset");
  // The same members but one, packed: H5Dread converts each row to it by member name.
  const int n = H5Tget_nmembers(row_type.get());
  check(n, at);
  std::vector<std::pair<std::string, h5::Handle>> kept;
  std::size_t size = 0;
  for (unsigned k = 0; k < static_cast<unsigned>(n); ++k) {
    char* name = H5Tget_member_name(row_type.get(), k);
    const std::string text = name != nullptr ? name : "";
    H5free_memory(name);
    if (text == member) continue;
    h5::Handle t = own(H5Tget_member_type(row_type.get(), k), H5Tclose, at);
    size += H5Tget_size(t.get());
    kept.emplace_back(text, std::move(t));
  }
  if (static_cast<int>(kept.size()) != n - 1) throw InspectError(at + ": no such member");
  h5::Handle fewer = own(H5Tcreate(H5T_COMPOUND, size), H5Tclose, at);
  std::size_t offset = 0;
  for (const auto& [name, t] : kept) {
    check(H5Tinsert(fewer.get(), name.c_str(), offset, t.get()), at);
    offset += H5Tget_size(t.get());
  }
  h5::Handle space = own(H5Dget_space(d.get()), H5Sclose, at);
  const hssize_t rows = H5Sget_simple_extent_npoints(space.get());
  check(rows < 0 ? -1 : 0, at);
  std::vector<unsigned char> data(size * static_cast<std::size_t>(rows));
  check(H5Dread(d.get(), fewer.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), at);
  d.reset();
  space.reset();
  check(H5Ldelete(file, dataset.c_str(), H5P_DEFAULT), at);
  const hsize_t dims[1] = {static_cast<hsize_t>(rows)};
  h5::Handle fixed = own(H5Screate_simple(1, dims, nullptr), H5Sclose, at);   // contiguous: no unlimited rows
  h5::Handle copy = own(H5Dcreate2(file, dataset.c_str(), fewer.get(), fixed.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                        H5Dclose, at);
  check(H5Dwrite(copy.get(), fewer.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), at);
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
