// The sweep's summary table as one HDF5 compound dataset (sweep_table.hpp).
#include "graspsim/recordings/sweep_table.hpp"

#include <cstdio>
#include <cstring>
#include <set>

#include "graspsim/recordings/trace_writer.hpp"
#include "h5.hpp"

namespace graspsim::recordings {

std::size_t SweepColumn::rows() const {
  switch (kind) {
    case Kind::text: return text.size();
    case Kind::integer: return integers.size();
    case Kind::real: return reals.size();
  }
  return 0;
}

namespace {

// Every member is 8 bytes in memory (a char*, an int64 or a double), so member i of a row sits
// at byte 8 i and a row is 8 n bytes.
constexpr std::size_t kCell = 8;
static_assert(sizeof(const char*) == kCell && sizeof(std::int64_t) == kCell && sizeof(double) == kCell);

h5::Handle string_type(const std::string& context) {
  h5::Handle type = h5::checked(H5Tcopy(H5T_C_S1), H5Tclose, context);
  h5::check(H5Tset_size(type.get(), H5T_VARIABLE), context);
  h5::check(H5Tset_cset(type.get(), H5T_CSET_UTF8), context);
  return type;
}

void write_file(const std::string& path, const std::vector<SweepColumn>& columns,
                const std::vector<std::pair<std::string, std::string>>& attributes) {
  const std::string context = "sweep table " + path;
  const std::size_t n = columns.empty() ? 0 : columns.front().rows();
  std::set<std::string> names;
  for (const auto& c : columns) {
    if (c.rows() != n) throw TraceError(context + ": column '" + c.name + "' has another number of rows");
    if (c.name.empty() || !names.insert(c.name).second)
      throw TraceError(context + ": column name '" + c.name + "' is empty or repeated");
  }
  // Memory and file row types: the same members, the file's packed in order.
  h5::Handle text = string_type(context);
  h5::Handle memory = h5::checked(H5Tcreate(H5T_COMPOUND, kCell * std::max<std::size_t>(columns.size(), 1)),
                                  H5Tclose, context);
  for (std::size_t i = 0; i < columns.size(); ++i) {
    const hid_t type = columns[i].kind == SweepColumn::Kind::text      ? text.get()
                       : columns[i].kind == SweepColumn::Kind::integer ? H5T_NATIVE_INT64
                                                                       : H5T_NATIVE_DOUBLE;
    h5::check(H5Tinsert(memory.get(), columns[i].name.c_str(), kCell * i, type), context);
  }
  h5::Handle file_type = h5::checked(H5Tcopy(memory.get()), H5Tclose, context);
  h5::check(H5Tpack(file_type.get()), context);
  std::vector<unsigned char> buffer(kCell * columns.size() * n);
  for (std::size_t r = 0; r < n; ++r) {
    for (std::size_t i = 0; i < columns.size(); ++i) {
      unsigned char* cell = buffer.data() + kCell * (r * columns.size() + i);
      const auto& c = columns[i];
      if (c.kind == SweepColumn::Kind::text) {
        const char* s = c.text[r].c_str();
        std::memcpy(cell, &s, kCell);
      } else if (c.kind == SweepColumn::Kind::integer) {
        std::memcpy(cell, &c.integers[r], kCell);
      } else {
        std::memcpy(cell, &c.reals[r], kCell);
      }
    }
  }
  h5::Handle file = h5::checked(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose,
                                "cannot create " + context);
  const hsize_t dims[1] = {static_cast<hsize_t>(n)};
  h5::Handle space = h5::checked(H5Screate_simple(1, dims, nullptr), H5Sclose, context);
  h5::Handle dataset = h5::checked(H5Dcreate2(file.get(), "runs", file_type.get(), space.get(), H5P_DEFAULT,
                                              H5P_DEFAULT, H5P_DEFAULT), H5Dclose, context);
  if (n > 0 && !columns.empty())
    h5::check(H5Dwrite(dataset.get(), memory.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer.data()), context);
  std::string units;
  for (const auto& c : columns)
    if (!c.unit.empty()) units += c.name + "=" + c.unit + "\n";
  h5::create_string_attribute(file.get(), "units", units, context);
  for (const auto& [name, value] : attributes) h5::write_string_attribute(file.get(), name, value, context);
  dataset.reset();
  space.reset();
  if (file.close() < 0) throw TraceError("cannot finish " + context + ": " + h5::last_error());
}

}  // namespace

void write_sweep_table(const std::string& path, const std::vector<SweepColumn>& columns,
                       const std::vector<std::pair<std::string, std::string>>& attributes) {
  h5::Lock lock;
  h5::Quiet quiet;
  const std::string partial = path + ".partial";
  try {
    write_file(partial, columns, attributes);
  } catch (...) {
    std::remove(partial.c_str());
    throw;
  }
  if (std::rename(partial.c_str(), path.c_str()) != 0) {
    std::remove(partial.c_str());
    throw TraceError("cannot rename " + partial + " to " + path);
  }
}

}  // namespace graspsim::recordings
