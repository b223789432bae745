// decimate_trace: copies a trace, keeping the loops' rows at every stride-th tick.
#include "graspsim/recordings/trace_decimate.hpp"

#include <algorithm>
#include <array>
#include <optional>
#include <filesystem>
#include <system_error>

#include "graspsim/recordings/record_selection.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "h5.hpp"
#include "h5_checks.hpp"
#include "table_layout.hpp"

namespace graspsim::recordings {
namespace {

using h5::check;
using h5::checked;
using h5::Handle;

// The tables a run appends a row to per tick of its loop (TraceRecorder): the ones decimated.
bool is_loop(const std::string& name) {
  return name == "servo" || name == "haptic" || name == "physics";
}

std::vector<std::string> link_names(hid_t group, const std::string& where) {
  std::vector<std::string> names;
  const auto collect = [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->push_back(name);
    return 0;
  };
  hsize_t index = 0;
  check(H5Literate(group, H5_INDEX_NAME, H5_ITER_INC, &index, collect, &names),
        "cannot list " + where);
  return names;
}

// Copies every attribute of `from` to `to`, in name order, with its own type and shape.
void copy_attributes(hid_t from, hid_t to, const std::string& where) {
  std::vector<std::string> names;
  const auto collect = [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->push_back(name);
    return 0;
  };
  hsize_t index = 0;
  check(H5Aiterate2(from, H5_INDEX_NAME, H5_ITER_INC, &index, collect, &names),
        "cannot list the attributes of " + where);
  for (const std::string& name : names) {
    const std::string context = "cannot copy attribute '" + name + "' of " + where;
    Handle attr = checked(H5Aopen(from, name.c_str(), H5P_DEFAULT), H5Aclose, context);
    Handle type = checked(H5Aget_type(attr.get()), H5Tclose, context);
    Handle space = checked(H5Aget_space(attr.get()), H5Sclose, context);
    const hssize_t points = H5Sget_simple_extent_npoints(space.get());
    std::vector<unsigned char> buffer(H5Tget_size(type.get()) *
                                      static_cast<std::size_t>(std::max<hssize_t>(points, 1)));
    check(H5Aread(attr.get(), type.get(), buffer.data()), context);
    Handle copy = checked(
        H5Acreate2(to, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
        H5Aclose, context);
    const herr_t written = H5Awrite(copy.get(), type.get(), buffer.data());
    if (H5Tdetect_class(type.get(), H5T_VLEN) > 0 || H5Tis_variable_str(type.get()) > 0)
      H5Dvlen_reclaim(type.get(), space.get(), H5P_DEFAULT, buffer.data());
    check(written, context);
  }
}

// No modification time on a new object: the copy's bytes depend on its content only.
Handle untimed(hid_t property_class, const std::string& context) {
  Handle list = checked(H5Pcreate(property_class), H5Pclose, context);
  check(H5Pset_obj_track_times(list.get(), 0), context);
  return list;
}

// The row indices of `ticks` that are multiples of `stride`.
std::vector<hsize_t> kept_rows(const std::vector<std::int64_t>& ticks, std::int64_t stride) {
  std::vector<hsize_t> rows;
  for (std::size_t r = 0; r < ticks.size(); ++r)
    if (ticks[r] % stride == 0) rows.push_back(r);
  return rows;
}

// The whole `tick` dataset of a schema 2 loop group.
std::vector<std::int64_t> read_tick_dataset(hid_t group, const std::string& where) {
  const std::string context = "cannot read " + where;
  Handle dataset = checked(H5Dopen2(group, "tick", H5P_DEFAULT), H5Dclose, context);
  Handle space = checked(H5Dget_space(dataset.get()), H5Sclose, context);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  h5::check_rows(dataset.get(), static_cast<std::uint64_t>(std::max<hssize_t>(n, 0)), context);
  std::vector<std::int64_t> ticks(static_cast<std::size_t>(std::max<hssize_t>(n, 0)));
  if (!ticks.empty())
    check(H5Dread(dataset.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, ticks.data()), context);
  return ticks;
}

// The `tick` member of a compound table (schema 3 and 4); false if it has none.
bool read_tick_member(hid_t dataset, const std::string& where, std::vector<std::int64_t>& ticks) {
  const std::string context = "cannot read " + where;
  Handle type = checked(H5Dget_type(dataset), H5Tclose, context);
  if (H5Tget_class(type.get()) != H5T_COMPOUND || H5Tget_member_index(type.get(), "tick") < 0) return false;
  Handle space = checked(H5Dget_space(dataset), H5Sclose, context);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  h5::check_rows(dataset, static_cast<std::uint64_t>(std::max<hssize_t>(n, 0)), context);
  ticks.assign(static_cast<std::size_t>(std::max<hssize_t>(n, 0)), 0);
  Handle tick_type = checked(H5Tcreate(H5T_COMPOUND, sizeof(std::int64_t)), H5Tclose, context);
  check(H5Tinsert(tick_type.get(), "tick", 0, H5T_NATIVE_INT64), context);
  if (!ticks.empty())
    check(H5Dread(dataset, tick_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, ticks.data()), context);
  return true;
}

struct Copier {
  std::string file;   // input, for messages
  int compression;

  // Copies dataset `name` of `from` into `to`, keeping the rows listed in `rows` (all when null).
  void dataset(hid_t from, hid_t to, const std::string& name, const std::string& path,
               const std::vector<hsize_t>* rows) const {
    const std::string where = "dataset " + path + " of '" + file + "'";
    const std::string context = "cannot copy " + where;
    Handle in = checked(H5Dopen2(from, name.c_str(), H5P_DEFAULT), H5Dclose, context);
    Handle file_type = checked(H5Dget_type(in.get()), H5Tclose, context);
    Handle memory_type = h5::packed_native(file_type.get(), context);   // no conversion of a trace's rows
    Handle in_space = checked(H5Dget_space(in.get()), H5Sclose, context);
    const int rank = H5Sget_simple_extent_ndims(in_space.get());
    if (rank < 1 || rank > 2) throw TraceError(context + ": rank " + std::to_string(rank));
    hsize_t dims[2] = {0, 1};
    H5Sget_simple_extent_dims(in_space.get(), dims, nullptr);
    h5::check_rows(in.get(), dims[0], context);
    const std::size_t row_bytes =
        H5Tget_size(memory_type.get()) * static_cast<std::size_t>(rank == 2 ? dims[1] : 1);
    std::vector<unsigned char> all(row_bytes * static_cast<std::size_t>(dims[0]));
    if (dims[0] > 0)
      check(H5Dread(in.get(), memory_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, all.data()), context);
    std::vector<unsigned char> kept;
    if (rows) {
      kept.reserve(row_bytes * rows->size());
      for (const hsize_t r : *rows) {
        if (r >= dims[0]) throw TraceError(context + ": it has fewer rows than its table's tick column");
        kept.insert(kept.end(), all.begin() + static_cast<std::ptrdiff_t>(r * row_bytes),
                    all.begin() + static_cast<std::ptrdiff_t>((r + 1) * row_bytes));
      }
    } else {
      kept = std::move(all);
    }
    hsize_t out_dims[2] = {rows ? static_cast<hsize_t>(rows->size()) : dims[0], dims[1]};
    Handle out_space = checked(H5Screate_simple(rank, out_dims, nullptr), H5Sclose, context);
    Handle dcpl = untimed(H5P_DATASET_CREATE, context);
    if (out_dims[0] > 0) {
      // At most 8192 rows and 4 MiB a chunk (a wide table's rows: 1000 objects are 184 kB a row).
      const hsize_t rows_per_chunk = std::max<hsize_t>(1, std::min<hsize_t>(8192, (4u << 20) / std::max<std::size_t>(row_bytes, 1)));
      hsize_t chunk[2] = {std::min<hsize_t>(out_dims[0], rows_per_chunk), out_dims[1]};
      check(H5Pset_chunk(dcpl.get(), rank, chunk), context);
      check(H5Pset_shuffle(dcpl.get()), context);
      check(H5Pset_deflate(dcpl.get(), static_cast<unsigned>(compression)), context);
    }
    Handle out = checked(H5Dcreate2(to, name.c_str(), file_type.get(), out_space.get(), H5P_DEFAULT,
                                    dcpl.get(), H5P_DEFAULT),
                         H5Dclose, context);
    if (out_dims[0] > 0)
      check(H5Dwrite(out.get(), memory_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, kept.data()), context);
    copy_attributes(in.get(), out.get(), where);
  }

  // Copies group `from` into `to` recursively; `rows` as above, for every dataset below.
  void group(hid_t from, hid_t to, const std::string& path, const std::vector<hsize_t>* rows) const {
    for (const std::string& name : link_names(from, "group " + path + " of '" + file + "'")) {
      const std::string child = path == "/" ? "/" + name : path + "/" + name;
      const std::string context = "cannot copy " + child + " of '" + file + "'";
      Handle object = checked(H5Oopen(from, name.c_str(), H5P_DEFAULT), H5Oclose, context);
      const H5I_type_t type = H5Iget_type(object.get());
      if (type == H5I_DATASET) {
        dataset(from, to, name, child, rows);
      } else if (type == H5I_GROUP) {
        Handle gcpl = untimed(H5P_GROUP_CREATE, context);
        Handle out = checked(H5Gcreate2(to, name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT),
                             H5Gclose, context);
        copy_attributes(object.get(), out.get(), "group " + child);
        group(object.get(), out.get(), child, rows);
      } else {
        throw TraceError(context + ": neither a group nor a dataset");
      }
    }
  }

  // Copies top-level object `name`: a loop keeps its rows at ticks that are multiples of
  // `stride` (schema 3 or 4 table, or schema 2 group), anything else is copied whole.
  void top_level(hid_t src, hid_t dst, const std::string& name, std::int64_t stride) const {
    const std::string where = "trace '" + file + "'";
    const std::string path = "/" + name;
    const std::string context = "cannot copy " + path + " of " + where;
    Handle object = checked(H5Oopen(src, name.c_str(), H5P_DEFAULT), H5Oclose, context);
    std::vector<std::int64_t> ticks;
    if (H5Iget_type(object.get()) == H5I_DATASET) {
      const bool decimated = is_loop(name) && read_tick_member(object.get(), path + " of " + where, ticks);
      const std::vector<hsize_t> rows = kept_rows(ticks, stride);
      dataset(src, dst, name, path, decimated ? &rows : nullptr);
      return;
    }
    Handle from = checked(H5Gopen2(src, name.c_str(), H5P_DEFAULT), H5Gclose, context);
    const bool decimated = is_loop(name) && H5Lexists(from.get(), "tick", H5P_DEFAULT) > 0;
    if (decimated) ticks = read_tick_dataset(from.get(), path + "/tick of " + where);
    const std::vector<hsize_t> rows = kept_rows(ticks, stride);
    Handle gcpl = untimed(H5P_GROUP_CREATE, context);
    Handle to = checked(H5Gcreate2(dst, name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), H5Gclose, context);
    copy_attributes(from.get(), to.get(), "group " + path + " of " + where);
    group(from.get(), to.get(), path, decimated ? &rows : nullptr);
  }
};

// Creates `path` (truncating it) in the 1.10 file format, with no time stamp on the root: a
// dataset of one chunk then has a "single chunk" index of a few bytes instead of a 1.8 B-tree
// of ~1 kB, which would be 60% of a small golden.
Handle create_copy(const std::string& path) {
  const std::string context = "cannot create '" + path + "'";
  Handle fcpl = untimed(H5P_FILE_CREATE, context);
  Handle fapl = checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, context);
  check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST), context);
  return checked(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()), H5Fclose, context);
}

}  // namespace

void decimate_trace(const std::string& in, const std::string& out, const DecimateOptions& options) {
  const std::string where = "trace '" + in + "'";
  if (options.stride < 1) throw TraceError("cannot decimate " + where + ": stride " +
                                           std::to_string(options.stride) + " is not a positive number of ticks");
  const std::string temporary = out + ".part";
  // What the copy holds, in its root attribute `record`, from the source's and its rates (a
  // trace without rates is not a run's: its `record`, if any, is copied as it is).
  std::optional<std::string> record;
  if (has_attribute(in, "/", "rate_servo") && has_attribute(in, "/", "rate_haptic") &&
      has_attribute(in, "/", "rate_physics")) {
    const std::int64_t servo = read_int_attribute(in, "/", "rate_servo");
    const std::array<std::int64_t, 3> period{1, servo / read_int_attribute(in, "/", "rate_haptic"),
                                             servo / read_int_attribute(in, "/", "rate_physics")};
    const RecordSelection source = RecordSelection::from_attribute(
        has_attribute(in, "/", "record") ? std::optional<std::string>(read_string_attribute(in, "/", "record"))
                                         : std::nullopt);
    record = source.thinned(options.stride, period).text();
  }
  {
    h5::Lock lock;
    h5::Quiet quiet;
    h5::OpenFile src = h5::open_read_only(in, where);
    Handle dst = create_copy(temporary);
    copy_attributes(src.file.get(), dst.get(), where);
    if (record) h5::write_string_attribute(dst.get(), "record", *record, "'" + temporary + "'");
    for (const auto& [name, value] : options.root_strings)
      h5::write_string_attribute(dst.get(), name, value, "'" + temporary + "'");
    const Copier copier{in, options.compression};
    for (const std::string& name : link_names(src.file.get(), where))
      copier.top_level(src.file.get(), dst.get(), name, options.stride);
    if (dst.close() < 0) throw TraceError("cannot close '" + temporary + "': " + h5::last_error());
  }
  std::error_code ec;
  std::filesystem::rename(temporary, out, ec);
  if (ec) throw TraceError("cannot move '" + temporary + "' to '" + out + "': " + ec.message());
}

}  // namespace graspsim::recordings
