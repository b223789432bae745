// The schema-free view: opening and creating a file, its objects, a dataset's shape, type,
// chunks and filters, an object's time stamps, and the process's open-object count.
#include <array>
#include <utility>

#include "inspect_detail.hpp"

namespace graspsim::recordings::inspect {

static_assert(kUnlimited == H5S_UNLIMITED, "kUnlimited is HDF5's unlimited extent");
static_assert(kFilterDeflate == H5Z_FILTER_DEFLATE && kFilterShuffle == H5Z_FILTER_SHUFFLE,
              "the filter ids are HDF5's");

namespace detail {

h5::Handle own(hid_t id, h5::CloseFn close, const std::string& what) {
  if (id < 0) throw InspectError(what + ": " + h5::last_error());
  return h5::Handle(id, close);
}

void check(herr_t status, const std::string& what) {
  if (status < 0) throw InspectError(what + ": " + h5::last_error());
}

h5::Handle open_object(hid_t file, const std::string& path, const std::string& what) {
  return own(H5Oopen(file, path.c_str(), H5P_DEFAULT), H5Oclose, what + ": cannot open the object");
}

h5::Handle open_dataset(hid_t file, const std::string& path, const std::string& what) {
  return own(H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose, what + ": cannot open the dataset");
}

std::string where(const std::string& file, const std::string& path) { return file + ": " + path; }

Type type_of(hid_t type) {
  Type out;
  out.bytes = H5Tget_size(type);
  switch (H5Tget_class(type)) {
    case H5T_INTEGER:
      out.type_class = TypeClass::kInteger;
      out.is_signed = H5Tget_sign(type) != H5T_SGN_NONE;
      break;
    case H5T_FLOAT: out.type_class = TypeClass::kFloat; break;
    case H5T_STRING: out.type_class = TypeClass::kString; break;
    case H5T_COMPOUND: out.type_class = TypeClass::kCompound; break;
    case H5T_ARRAY: out.type_class = TypeClass::kArray; break;
    default: out.type_class = TypeClass::kOther; break;
  }
  return out;
}

}  // namespace detail

using detail::check;
using detail::Guard;
using detail::own;
using detail::where;

File::File(std::string path, std::unique_ptr<Handles> handles) : path_(std::move(path)), handles_(std::move(handles)) {}
File::File(File&&) noexcept = default;
File& File::operator=(File&& other) noexcept {
  if (this != &other) {
    Guard guard;
    handles_ = std::move(other.handles_);
    path_ = std::move(other.path_);
  }
  return *this;
}
File::~File() {
  Guard guard;
  handles_.reset();
}

File File::open(const std::string& path, Mode mode) {
  Guard guard;
  auto handles = std::make_unique<Handles>();
  handles->file = own(H5Fopen(path.c_str(), mode == Mode::kReadWrite ? H5F_ACC_RDWR : H5F_ACC_RDONLY, H5P_DEFAULT),
                      H5Fclose, path + ": cannot open it" + (mode == Mode::kReadWrite ? " to write" : ""));
  return File(path, std::move(handles));
}

File File::create(const std::string& path, Format format) {
  Guard guard;
  h5::Handle fapl = own(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, path + ": cannot create it");
  if (format == Format::kLatest)
    check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST), path + ": cannot create it");
  auto handles = std::make_unique<Handles>();
  handles->file = own(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose,
                      path + ": cannot create it");
  return File(path, std::move(handles));
}

namespace {

herr_t collect_object(hid_t, const char* name, const H5O_info_t* info, void* out) {
  const std::string n = name;
  const ObjectKind kind = info->type == H5O_TYPE_GROUP     ? ObjectKind::kGroup
                          : info->type == H5O_TYPE_DATASET ? ObjectKind::kDataset
                                                           : ObjectKind::kOther;
  static_cast<std::vector<Object>*>(out)->push_back({n == "." ? "/" : "/" + n, kind});
  return 0;
}

std::vector<std::uint64_t> to_u64(const std::vector<hsize_t>& v) { return {v.begin(), v.end()}; }

}  // namespace

std::vector<Object> File::objects() const {
  Guard guard;
  std::vector<Object> out;
  check(H5Ovisit2(handles_->file.get(), H5_INDEX_NAME, H5_ITER_INC, collect_object, &out, H5O_INFO_BASIC),
        path_ + ": cannot list its objects");
  return out;
}

namespace {

// The members of compound type `type`; a member that is an array of compound elements (a
// trace's entity group) lists the element's members as its `fields`.
std::vector<Member> members_of(hid_t type, const std::string& at) {
  std::vector<Member> out;
  const int n = H5Tget_nmembers(type);
  check(n, at);
  for (unsigned k = 0; k < static_cast<unsigned>(n); ++k) {
    Member m;
    char* name = H5Tget_member_name(type, k);
    if (name != nullptr) m.name = name;
    H5free_memory(name);
    const std::string here = at + ": member " + m.name;
    h5::Handle member = own(H5Tget_member_type(type, k), H5Tclose, here);
    m.type = detail::type_of(member.get());
    m.element = m.type;
    h5::Handle base;
    if (m.type.type_class == TypeClass::kArray) {
      const int array_rank = H5Tget_array_ndims(member.get());
      check(array_rank, here);
      std::vector<hsize_t> extent(static_cast<std::size_t>(array_rank));
      check(H5Tget_array_dims2(member.get(), extent.data()), here);
      for (hsize_t e : extent) m.width *= e;
      base = own(H5Tget_super(member.get()), H5Tclose, here);
      m.element = detail::type_of(base.get());
    }
    if (m.element.type_class == TypeClass::kCompound)
      m.fields = members_of(base.valid() ? base.get() : member.get(), here);
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace

DatasetInfo File::dataset(const std::string& path) const {
  Guard guard;
  const std::string at = where(path_, path);
  h5::Handle d = detail::open_dataset(handles_->file.get(), path, at);
  DatasetInfo out;
  h5::Handle space = own(H5Dget_space(d.get()), H5Sclose, at);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  check(rank, at);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank)), max_dims(dims.size());
  check(H5Sget_simple_extent_dims(space.get(), dims.data(), max_dims.data()), at);
  out.dims = to_u64(dims);
  out.max_dims = to_u64(max_dims);

  h5::Handle type = own(H5Dget_type(d.get()), H5Tclose, at);
  out.type = detail::type_of(type.get());
  if (out.type.type_class == TypeClass::kCompound) out.members = members_of(type.get(), at);

  h5::Handle dcpl = own(H5Dget_create_plist(d.get()), H5Pclose, at);
  out.chunked = H5Pget_layout(dcpl.get()) == H5D_CHUNKED;
  if (out.chunked) {
    std::vector<hsize_t> chunk(dims.size());
    check(H5Pget_chunk(dcpl.get(), rank, chunk.data()), at + ": cannot read its chunk");
    out.chunk = to_u64(chunk);
  }
  const int filters = H5Pget_nfilters(dcpl.get());
  check(filters, at);
  for (unsigned i = 0; i < static_cast<unsigned>(filters); ++i) {
    std::array<unsigned, 16> values{};
    std::size_t count = values.size();
    std::array<char, 256> name{};
    unsigned flags = 0, config = 0;
    const H5Z_filter_t id = H5Pget_filter2(dcpl.get(), i, &flags, &count, values.data(), name.size(), name.data(), &config);
    check(id, at + ": cannot read its filters");
    out.filters.push_back({static_cast<int>(id), name.data(),
                           std::vector<unsigned>(values.begin(), values.begin() + std::min(count, values.size()))});
  }
  out.storage_bytes = H5Dget_storage_size(d.get());
  return out;
}

std::vector<Chunk> File::chunks(const std::string& dataset) const {
  Guard guard;
  const std::string at = where(path_, dataset);
  h5::Handle d = detail::open_dataset(handles_->file.get(), dataset, at);
  h5::Handle space = own(H5Dget_space(d.get()), H5Sclose, at);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  check(rank, at);
  hsize_t count = 0;
  check(H5Dget_num_chunks(d.get(), space.get(), &count), at + ": cannot count its chunks");
  std::vector<Chunk> out;
  std::vector<hsize_t> offset(static_cast<std::size_t>(rank) + 1);
  for (hsize_t k = 0; k < count; ++k) {
    unsigned mask = 0;
    haddr_t address = 0;
    hsize_t bytes = 0;
    check(H5Dget_chunk_info(d.get(), space.get(), k, offset.data(), &mask, &address, &bytes),
          at + ": cannot read chunk " + std::to_string(k));
    out.push_back({address, bytes});
  }
  return out;
}

ObjectTimes File::times(const std::string& path) const {
  Guard guard;
  H5O_info_t info;
  check(H5Oget_info_by_name2(handles_->file.get(), path.c_str(), &info, H5O_INFO_TIME, H5P_DEFAULT),
        where(path_, path) + ": cannot read its header");
  return {static_cast<std::int64_t>(info.atime), static_cast<std::int64_t>(info.mtime),
          static_cast<std::int64_t>(info.ctime), static_cast<std::int64_t>(info.btime)};
}

void File::start_swmr_write() {
  Guard guard;
  check(H5Fstart_swmr_write(handles_->file.get()), path_ + ": cannot start SWMR writing");
}

void File::flush() {
  Guard guard;
  check(H5Fflush(handles_->file.get(), H5F_SCOPE_GLOBAL), path_ + ": cannot flush it");
}

struct LibraryLock::Held {
  h5::Lock lock;
};
LibraryLock::LibraryLock() : held_(std::make_unique<Held>()) {}
LibraryLock::~LibraryLock() = default;

std::int64_t open_object_count() {
  Guard guard;
  const ssize_t n = H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_FILE | H5F_OBJ_GROUP | H5F_OBJ_DATASET | H5F_OBJ_ATTR);
  detail::check(n < 0 ? -1 : 0, "cannot count HDF5's open objects");
  return static_cast<std::int64_t>(n);
}

}  // namespace graspsim::recordings::inspect
