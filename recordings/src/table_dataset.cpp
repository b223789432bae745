// A table's dataset, on the writer side: created at the first job, then appended a block at a
// time (packed into compound rows, integer columns checked).
#include <algorithm>
#include <cstring>
#include <sstream>

#include "trace_writer_impl.hpp"

namespace graspsim::recordings {

using namespace writer;

void TraceTable::Impl::create_dataset(hid_t file_id) {
  const std::string where = context() + ": cannot create table " + quoted("/" + name);
  if (columns.empty()) throw TraceError(where + ": it has no columns");
  h5::Handle file_type = row_type(columns, groups, packed_width, false, where);
  memory_type = row_type(columns, groups, packed_width, true, where);
  // A whole chunk is written straight to the file, past the chunk cache (a copy and its
  // bookkeeping saved), when the packed rows are the file's bytes: no filter, no conversion.
  const htri_t same = H5Tequal(file_type.get(), memory_type.get());
  h5::check(same, where);
  direct = same > 0 && file->options.compression == 0;
  runs.clear();
  integers.clear();
  for (const Column& c : columns) {
    if (c.dtype == DType::kFloat64 || c.dtype == DType::kUInt64) {
      const std::size_t w = static_cast<std::size_t>(c.width);
      if (!runs.empty() && runs.back().offset + runs.back().count == c.offset &&
          runs.back().bytes + 8 * runs.back().count == c.bytes) {
        runs.back().count += w;
      } else {
        runs.push_back(CopyRun{c.offset, c.bytes, w});
      }
    } else {
      integers.push_back(&c);
    }
  }
  // Shape (0,), unlimited rows, one chunk per block.
  const hsize_t dims[1] = {0};
  const hsize_t max_dims[1] = {H5S_UNLIMITED};
  const hsize_t chunk[1] = {static_cast<hsize_t>(block_rows)};
  h5::Handle space = h5::checked(H5Screate_simple(1, dims, max_dims), H5Sclose, where);
  h5::Handle dcpl = untimed(H5P_DATASET_CREATE, where);
  // The column attributes (a hundred or so) stay in the object header: compact storage is several
  // times cheaper to create than the dense storage (fractal heap + B-tree) that the newest file
  // format switches to after 8.
  const unsigned compact = static_cast<unsigned>(std::min<std::size_t>(attributes.size() + 8, 1000));
  h5::check(H5Pset_attr_phase_change(dcpl.get(), compact, compact > 8 ? compact - 8 : 0), where);
  h5::check(H5Pset_chunk(dcpl.get(), 1, chunk), where);
  // Every row is written before it is read: no fill values (they cost a memset of each new chunk).
  h5::check(H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER), where);
  if (file->options.compression > 0) {
    // Byte shuffle first: with a compound element it groups the k-th byte of every row, so
    // each column's slowly changing high bytes sit together for deflate.
    h5::check(H5Pset_shuffle(dcpl.get()), where);
    h5::check(H5Pset_deflate(dcpl.get(), static_cast<unsigned>(file->options.compression)), where);
  }
  h5::Handle lcpl = h5::checked(H5Pcreate(H5P_LINK_CREATE), H5Pclose, where);
  h5::check(H5Pset_create_intermediate_group(lcpl.get(), 1), where);
  dataset = h5::checked(H5Dcreate2(file_id, ("/" + name).c_str(), file_type.get(), space.get(),
                                   lcpl.get(), dcpl.get(), H5P_DEFAULT),
                        H5Dclose, where);
  // Sorted by name, so the file does not depend on the order attributes were set in.
  std::vector<std::pair<std::string, std::string>> sorted = attributes;
  std::sort(sorted.begin(), sorted.end());
  for (const auto& [key, value] : sorted) {
    h5::create_string_attribute(dataset.get(), key, value, context() + ", table " + quoted("/" + name));
  }
  packed.assign(block_rows * packed_width, 0);
}

// Packs the block's rows into compound rows (checking integer columns) and appends them.
// Allocates nothing on success (messages are built only on failure); HDF5 mallocs its own.
void TraceTable::Impl::write_block(Block& block) {
  const std::size_t n = block.count;
  for (std::size_t r = 0; r < n; ++r) {
    const double* src = block.rows.data() + r * row_width;
    unsigned char* dst = packed.data() + r * packed_width;
    for (const CopyRun& run : runs) std::memcpy(dst + run.bytes, src + run.offset, 8 * run.count);
    for (const Column* column : integers) {
      const Column& c = *column;
      const double* in = src + c.offset;
      unsigned char* out = dst + c.bytes;
      for (std::size_t k = 0; k < static_cast<std::size_t>(c.width); ++k) {
        const double value = in[k];
        if (!fits(value, c.dtype)) {
          std::ostringstream message;
          message.precision(17);
          message << column_context(c.name) << ": row " << (written + static_cast<std::int64_t>(r))
                  << " holds " << value << ", which is not an " << name_of(c.dtype);
          throw TraceError(message.str());
        }
        if (c.dtype == DType::kInt64) {
          const std::int64_t v = static_cast<std::int64_t>(value);
          std::memcpy(out + 8 * k, &v, 8);
        } else if (c.dtype == DType::kInt32) {
          const std::int32_t v = static_cast<std::int32_t>(value);
          std::memcpy(out + 4 * k, &v, 4);
        } else {
          const std::int8_t v = static_cast<std::int8_t>(value);
          std::memcpy(out + k, &v, 1);
        }
      }
    }
  }
  auto fail = [&]() {
    throw TraceError(context() + ", table " + quoted("/" + name) + ": cannot append rows: " +
                     h5::last_error());
  };
  const hsize_t new_dims[1] = {static_cast<hsize_t>(written) + n};
  const hsize_t start[1] = {static_cast<hsize_t>(written)};
  const hsize_t count[1] = {n};
  if (H5Dset_extent(dataset.get(), new_dims) < 0) fail();
  if (direct && n == block_rows && static_cast<std::size_t>(written) % block_rows == 0) {
    // Exactly one whole chunk (the runner's blocks are its chunks): its bytes as they are.
    if (H5Dwrite_chunk(dataset.get(), H5P_DEFAULT, 0, start, n * packed_width, packed.data()) < 0) fail();
    written += static_cast<std::int64_t>(n);
    return;
  }
  h5::Handle file_space(H5Dget_space(dataset.get()), H5Sclose);
  if (!file_space.valid()) fail();
  if (H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr) < 0) {
    fail();
  }
  h5::Handle memory_space(H5Screate_simple(1, count, nullptr), H5Sclose);
  if (!memory_space.valid()) fail();
  if (H5Dwrite(dataset.get(), memory_type.get(), memory_space.get(), file_space.get(),
               H5P_DEFAULT, packed.data()) < 0) {
    fail();
  }
  written += static_cast<std::int64_t>(n);
}

}  // namespace graspsim::recordings
