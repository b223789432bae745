// Golden traces: run, decimate, compare (see golden.hpp and README.md, "Golden traces").
#include "golden/golden.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include "graspsim/scripting/scenario.hpp"

namespace graspsim::golden {
namespace {

using recordings::TraceError;

// Turns HDF5's error printing off while alive (failures become TraceError).
class Quiet {
 public:
  Quiet() { H5Eget_auto2(H5E_DEFAULT, &func_, &data_); H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }
  ~Quiet() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  Quiet(const Quiet&) = delete;
  Quiet& operator=(const Quiet&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// Owns one HDF5 id.
class Id {
 public:
  using Close = herr_t (*)(hid_t);
  Id(hid_t id, Close close, const std::string& context) : id_(id), close_(close) {
    if (id_ < 0) throw TraceError(context);
  }
  ~Id() { if (id_ >= 0) close_(id_); }
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  Id(Id&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)), close_(o.close_) {}
  hid_t get() const { return id_; }

 private:
  hid_t id_;
  Close close_;
};

void check(herr_t status, const std::string& context) {
  if (status < 0) throw TraceError(context);
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
    Id attr(H5Aopen(from, name.c_str(), H5P_DEFAULT), H5Aclose, context);
    Id type(H5Aget_type(attr.get()), H5Tclose, context);
    Id space(H5Aget_space(attr.get()), H5Sclose, context);
    const hssize_t points = H5Sget_simple_extent_npoints(space.get());
    std::vector<unsigned char> buffer(H5Tget_size(type.get()) * static_cast<std::size_t>(std::max<hssize_t>(points, 1)));
    check(H5Aread(attr.get(), type.get(), buffer.data()), context);
    Id copy(H5Acreate2(to, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
            H5Aclose, context);
    const herr_t written = H5Awrite(copy.get(), type.get(), buffer.data());
    if (H5Tdetect_class(type.get(), H5T_VLEN) > 0 || H5Tis_variable_str(type.get()) > 0)
      H5Dvlen_reclaim(type.get(), space.get(), H5P_DEFAULT, buffer.data());
    check(written, context);
  }
}

void write_string_attribute(hid_t object, const std::string& name, const std::string& value,
                            const std::string& where) {
  const std::string context = "cannot write attribute '" + name + "' of " + where;
  Id type(H5Tcopy(H5T_C_S1), H5Tclose, context);
  check(H5Tset_size(type.get(), H5T_VARIABLE), context);
  check(H5Tset_cset(type.get(), H5T_CSET_UTF8), context);
  Id space(H5Screate(H5S_SCALAR), H5Sclose, context);
  if (H5Aexists(object, name.c_str()) > 0) check(H5Adelete(object, name.c_str()), context);
  Id attr(H5Acreate2(object, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
          H5Aclose, context);
  const char* text = value.c_str();
  check(H5Awrite(attr.get(), type.get(), &text), context);
}

std::int64_t read_int_attribute(hid_t object, const std::string& name, const std::string& where) {
  const std::string context = "cannot read attribute '" + name + "' of " + where;
  Id attr(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose, context);
  std::int64_t value = 0;
  check(H5Aread(attr.get(), H5T_NATIVE_INT64, &value), context);
  return value;
}

struct Copier {
  std::string file;   // input, for messages
  int compression;

  // Copies dataset `name` of `from` into `to`, keeping the rows listed in `rows` (all when null).
  void dataset(hid_t from, hid_t to, const std::string& name, const std::string& path,
               const std::vector<hsize_t>* rows) const {
    const std::string where = "dataset " + path + " of '" + file + "'";
    const std::string context = "cannot copy " + where;
    Id in(H5Dopen2(from, name.c_str(), H5P_DEFAULT), H5Dclose, context);
    Id file_type(H5Dget_type(in.get()), H5Tclose, context);
    Id memory_type(H5Tget_native_type(file_type.get(), H5T_DIR_ASCEND), H5Tclose, context);
    Id in_space(H5Dget_space(in.get()), H5Sclose, context);
    const int rank = H5Sget_simple_extent_ndims(in_space.get());
    if (rank < 1 || rank > 2) throw TraceError(context + ": rank " + std::to_string(rank));
    hsize_t dims[2] = {0, 1};
    H5Sget_simple_extent_dims(in_space.get(), dims, nullptr);
    const std::size_t row_bytes = H5Tget_size(memory_type.get()) * static_cast<std::size_t>(rank == 2 ? dims[1] : 1);
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
    Id out_space(H5Screate_simple(rank, out_dims, nullptr), H5Sclose, context);
    Id dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, context);
    check(H5Pset_obj_track_times(dcpl.get(), 0), context);   // no time stamps: byte-stable files
    if (out_dims[0] > 0) {
      hsize_t chunk[2] = {std::min<hsize_t>(out_dims[0], 8192), out_dims[1]};
      check(H5Pset_chunk(dcpl.get(), rank, chunk), context);
      check(H5Pset_shuffle(dcpl.get()), context);
      check(H5Pset_deflate(dcpl.get(), static_cast<unsigned>(compression)), context);
    }
    Id out(H5Dcreate2(to, name.c_str(), file_type.get(), out_space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
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
      Id object(H5Oopen(from, name.c_str(), H5P_DEFAULT), H5Oclose, context);
      const H5I_type_t type = H5Iget_type(object.get());
      if (type == H5I_DATASET) {
        dataset(from, to, name, child, rows);
      } else if (type == H5I_GROUP) {
        Id gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose, context);
        check(H5Pset_obj_track_times(gcpl.get(), 0), context);
        Id out(H5Gcreate2(to, name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), H5Gclose, context);
        copy_attributes(object.get(), out.get(), "group " + child);
        group(object.get(), out.get(), child, rows);
      } else {
        throw TraceError(context + ": neither a group nor a dataset");
      }
    }
  }
};

std::vector<std::int64_t> read_ticks(hid_t group, const std::string& where) {
  const std::string context = "cannot read " + where;
  Id dataset(H5Dopen2(group, "tick", H5P_DEFAULT), H5Dclose, context);
  Id space(H5Dget_space(dataset.get()), H5Sclose, context);
  std::vector<std::int64_t> ticks(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.get())));
  if (!ticks.empty())
    check(H5Dread(dataset.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, ticks.data()), context);
  return ticks;
}

// The "tick" member of a compound table (schema 3), or an empty optional-like flag if it has none.
bool read_table_ticks(hid_t dataset, const std::string& where, std::vector<std::int64_t>& ticks) {
  const std::string context = "cannot read " + where;
  Id type(H5Dget_type(dataset), H5Tclose, context);
  if (H5Tget_class(type.get()) != H5T_COMPOUND || H5Tget_member_index(type.get(), "tick") < 0) return false;
  Id space(H5Dget_space(dataset), H5Sclose, context);
  ticks.assign(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.get())), 0);
  Id tick_type(H5Tcreate(H5T_COMPOUND, sizeof(std::int64_t)), H5Tclose, context);
  check(H5Tinsert(tick_type.get(), "tick", 0, H5T_NATIVE_INT64), context);
  if (!ticks.empty())
    check(H5Dread(dataset, tick_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, ticks.data()), context);
  return true;
}

std::string format(const char* fmt, auto... args) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, fmt, args...);
  return buffer;
}

}  // namespace

std::string golden_path(const std::string& golden_dir, const std::string& scenario_file) {
  return golden_dir + "/" + std::filesystem::path(scenario_file).stem().string() + ".h5";
}

std::string bless_command(const std::string& scenario_file) {
  return "tools/bless scenarios/" + std::filesystem::path(scenario_file).filename().string();
}

app::RunResult run_for_golden(const std::string& scenario_file, const std::string& trace) {
  // Goldens hold the paper's scheme: they prove it stays bit for bit (README, "Golden traces").
  scripting::LoadOptions load;
  load.sets = {"integrator=paper"};
  const auto scenario = scripting::Scenario::load(scenario_file, load);
  app::RunOptions options;
  options.out = trace;
  options.overrides = load.sets;   // recorded, so that a replay of the trace runs the same step
  return app::run_scenario(scenario, options);
}

void decimate_trace(const std::string& in, const std::string& out, const DecimateOptions& options) {
  const Quiet quiet;
  const std::string where = "trace '" + in + "'";
  Id src(H5Fopen(in.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "cannot open " + where);
  const std::int64_t rate_servo = read_int_attribute(src.get(), "rate_servo", where);
  const std::int64_t rate_physics = read_int_attribute(src.get(), "rate_physics", where);
  const std::int64_t stride =
      options.stride > 0 ? options.stride
                         : std::max<std::int64_t>(1, rate_servo / std::min(rate_physics, kGoldenRowsPerSecond));

  const std::string temporary = out + ".part";
  {
    Id fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "cannot create '" + temporary + "'");
    // No time stamp on the root group either: a golden's bytes depend on its content only.
    check(H5Pset_obj_track_times(fcpl.get(), 0), "cannot create '" + temporary + "'");
    // The 1.10 format, as the traces: a dataset of one chunk has a "single chunk" index of a
    // few bytes instead of a 1.8 B-tree of ~1 kB, which would be 60% of a small golden.
    Id fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "cannot create '" + temporary + "'");
    check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST), "cannot create '" + temporary + "'");
    Id dst(H5Fcreate(temporary.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()), H5Fclose,
           "cannot create '" + temporary + "'");
    copy_attributes(src.get(), dst.get(), where);
    write_string_attribute(dst.get(), "golden",
                           format("golden format 1 (HDF5 1.10 file format), decimated: the /servo, /haptic and /physics rows at ticks that are "
                                  "multiples of %" PRId64 " (servo ticks; every physics tick up to 500 per simulated s); shuffle + deflate %d",
                                  stride, options.compression),
                           "'" + temporary + "'");
    write_string_attribute(dst.get(), "golden_cpu", cpu_model(), "'" + temporary + "'");
    if (!options.blessed_changes.empty())
      write_string_attribute(dst.get(), "blessed_changes", options.blessed_changes, "'" + temporary + "'");
    const Copier copier{in, options.compression};
    for (const std::string& name : link_names(src.get(), where)) {
      const std::string path = "/" + name;
      const std::string context = "cannot copy " + path + " of " + where;
      Id object(H5Oopen(src.get(), name.c_str(), H5P_DEFAULT), H5Oclose, context);
      std::vector<hsize_t> rows;
      const bool loop = name == "servo" || name == "haptic" || name == "physics";
      if (H5Iget_type(object.get()) == H5I_DATASET) {
        // Schema 3: the loop is one compound dataset; its rows are decimated by its tick member.
        std::vector<std::int64_t> ticks;
        const bool decimated = loop && read_table_ticks(object.get(), path + " of " + where, ticks);
        for (std::size_t r = 0; r < ticks.size() && decimated; ++r)
          if (ticks[r] % stride == 0) rows.push_back(r);
        copier.dataset(src.get(), dst.get(), name, path, decimated ? &rows : nullptr);
        continue;
      }
      Id group(H5Gopen2(src.get(), name.c_str(), H5P_DEFAULT), H5Gclose, context);
      const bool decimated = loop && H5Lexists(group.get(), "tick", H5P_DEFAULT) > 0;
      if (decimated) {
        const std::vector<std::int64_t> ticks = read_ticks(group.get(), path + "/tick of " + where);
        for (std::size_t r = 0; r < ticks.size(); ++r)
          if (ticks[r] % stride == 0) rows.push_back(r);
      }
      Id gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose, context);
      check(H5Pset_obj_track_times(gcpl.get(), 0), context);
      Id copy(H5Gcreate2(dst.get(), name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), H5Gclose, context);
      copy_attributes(group.get(), copy.get(), "group " + path + " of " + where);
      copier.group(group.get(), copy.get(), path, decimated ? &rows : nullptr);
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, out, ec);
  if (ec) throw TraceError("cannot move '" + temporary + "' to '" + out + "': " + ec.message());
}

std::string divergence_summary(const recordings::CompareResult& result, std::size_t max_datasets,
                               bool only_b) {
  std::ostringstream out;
  std::size_t listed = 0;
  for (const auto& d : result.datasets) {
    if (!d.differs()) continue;
    const std::string component = d.first && d.first->component < d.components.size() && !d.components[d.first->component].empty()
                                      ? " " + d.components[d.first->component] : "";
    if (listed == 0 && d.first) {
      out << format("  first divergence at tick %" PRId64 " (t = %.6f s): %s%s: golden %.17g, run %.17g\n",
                    d.first->tick, d.first->time, d.path.c_str(), component.c_str(), d.first->b, d.first->a);
    }
    if (listed == max_datasets) {
      out << "  ... and more datasets differ (" << result.differing_datasets() << " in all)\n";
      break;
    }
    out << format("  %-48s first at tick %" PRId64 ", max abs error %.3g %s, max rel error %.3g, %" PRId64
                  " of %" PRId64 " elements differ\n",
                  d.path.c_str(), d.first ? d.first->tick : std::int64_t{-1}, d.max_abs_error, d.units.c_str(),
                  d.max_rel_error, d.exceeded, d.elements);
    ++listed;
  }
  for (const auto& loop : result.loops) {
    if (loop.only_b == 0 && (only_b || loop.only_a == 0)) continue;
    out << format("  /%s: %" PRId64 " rows matched by tick, %" PRId64 " only in the run, %" PRId64
                  " only in the golden",
                  loop.loop.c_str(), loop.matched, loop.only_a, loop.only_b);
    if (loop.first_only_b) out << format(" (first %" PRId64 ")", *loop.first_only_b);
    out << "\n";
  }
  return out.str();
}

GoldenCheck check_against_golden(const std::string& fresh, const std::string& golden,
                                 const std::string& scenario_file) {
  recordings::CompareOptions options;
  options.bitwise = true;
  GoldenCheck check;
  check.result = recordings::compare_traces(fresh, golden, options);
  bool every_golden_row = true;
  for (const auto& loop : check.result.loops)
    if (loop.only_b > 0 || loop.matched != loop.rows_b) every_golden_row = false;
  check.same = check.result.same() && every_golden_row;
  if (check.same) return check;
  std::ostringstream msg;
  msg << "golden trace " << golden << " differs from a fresh run of " << scenario_file << " (bitwise):\n"
      << divergence_summary(check.result, 12, true);
  for (const auto& a : check.result.attributes) {
    if ((a.name == "compiler" || a.name == "build_flags") && a.a != a.b) {
      msg << "  note: the golden's " << a.name << " was '" << a.b.value_or("(none)") << "', this run's is '"
          << a.a.value_or("(none)") << "'\n";
    }
    if (a.name == "golden_cpu" && a.b && *a.b != cpu_model())
      msg << "  note: the golden was blessed on CPU '" << *a.b << "', this is '" << cpu_model() << "'\n";
  }
  msg << "  (bit-identity is promised for the same compiler, flags, libraries and CPU: README.md, "
         "Determinism)\n"
      << "If the change is intended, re-bless the golden (it prints what changed): "
      << bless_command(scenario_file);
  check.message = msg.str();
  return check;
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) {
        std::string model = line.substr(colon + 1);
        model.erase(0, model.find_first_not_of(' '));
        return model;
      }
    }
  }
  return "unknown";
}

}  // namespace graspsim::golden
