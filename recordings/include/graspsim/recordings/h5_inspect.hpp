// A schema-free view of any HDF5 file, by HDF5 names only: its objects, a dataset's shape, type,
// chunking and filters, attributes, one row of a compound member, and the few edits that fault
// tests make (a value changed, a member dropped, an extent grown, a file left open by a killed
// SWMR writer).
//
// It is the independent reader of what recordings/ writes: it knows nothing of a trace's layout
// (no trace_reader, no trace_schema, no table or column names) and opens files with libhdf5's
// defaults, without the module's checks on untrusted files. A test that reads a trace through
// this view and through trace_reader.hpp checks the writer against HDF5 itself, not against a
// second use of the writer's own ideas. Tests and tools outside recordings/ use it instead of the
// C API, so HDF5 stays private to this module.
//
// Every call holds the module's HDF5 lock and prints nothing; a failure throws InspectError
// naming the file, the object and HDF5's reason.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace graspsim::recordings::inspect {

class InspectError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A maximum extent without limit (HDF5's H5S_UNLIMITED).
inline constexpr std::uint64_t kUnlimited = ~std::uint64_t{0};
// HDF5's registered filter ids.
inline constexpr int kFilterDeflate = 1;
inline constexpr int kFilterShuffle = 2;

enum class TypeClass { kInteger, kFloat, kString, kCompound, kArray, kOther };

// A stored datatype: its class and size.
struct Type {
  TypeClass type_class = TypeClass::kOther;
  std::size_t bytes = 0;   // bytes of one element as stored
  bool is_signed = false;  // integers only
};

// One member of a compound type. An array member's `element` is its base type and `width` its
// element count (the product of its dimensions); a scalar member's `element` is `type` and
// `width` is 1. An element that is itself a compound (a trace's group of entities: an array of
// one compound per body or finger) has its members in `fields`.
struct Member {
  std::string name;
  Type type;
  Type element;
  std::uint64_t width = 1;
  std::vector<Member> fields;
};

// One filter of a dataset's pipeline, in order: its id (kFilterDeflate, ...), its name as
// stored, and its client values (deflate: the level).
struct Filter {
  int id = -1;
  std::string name;
  std::vector<unsigned> values;
};

struct DatasetInfo {
  std::vector<std::uint64_t> dims;       // current extent, one per rank (rows first)
  std::vector<std::uint64_t> max_dims;   // maximum extent (kUnlimited for none)
  Type type;                             // the element type (kCompound for a table of rows)
  std::vector<Member> members;           // a compound type's members, in stored order
  bool chunked = false;
  std::vector<std::uint64_t> chunk;      // chunk extent, one per rank; empty when not chunked
  std::vector<Filter> filters;
  std::uint64_t storage_bytes = 0;       // bytes allocated in the file (H5Dget_storage_size)
};

// Where one allocated chunk of a dataset lies in the file.
struct Chunk {
  std::uint64_t address = 0;   // byte offset in the file
  std::uint64_t bytes = 0;     // stored (filtered) size
};

enum class ObjectKind { kGroup, kDataset, kOther };

struct Object {
  std::string path;   // "/" for the root, "/a/b" below it
  ObjectKind kind = ObjectKind::kOther;
};

struct Attribute {
  std::string name;
  Type type;
};

// The time stamps in an object's header, s since the epoch; 0 where none is stored.
struct ObjectTimes {
  std::int64_t access = 0, modification = 0, change = 0, birth = 0;
};

class File {
 public:
  enum class Mode { kReadOnly, kReadWrite };
  // kLatest: the newest file format (superblock v3), which SWMR writing needs.
  enum class Format { kDefault, kLatest };

  // Opens with libhdf5's default access (no SWMR); throws InspectError naming the file.
  static File open(const std::string& path, Mode mode = Mode::kReadOnly);
  // Creates (truncates) an empty file.
  static File create(const std::string& path, Format format = Format::kDefault);

  File(File&&) noexcept;
  File& operator=(File&&) noexcept;
  ~File();   // closes every object still open and the file

  const std::string& path() const { return path_; }

  // Structure. `objects()` lists the root and every group and dataset below it, each once.
  std::vector<Object> objects() const;
  DatasetInfo dataset(const std::string& path) const;
  std::vector<Chunk> chunks(const std::string& dataset) const;   // allocated chunks, in index order
  ObjectTimes times(const std::string& path) const;

  // Attributes of the object at `object` ("/" for the root), in name order.
  std::vector<Attribute> attributes(const std::string& object) const;
  bool has_attribute(const std::string& object, const std::string& name) const;
  // A one-element string attribute, variable- or fixed-length.
  std::string read_string_attribute(const std::string& object, const std::string& name) const;
  // A scalar variable-length UTF-8 string, replacing any attribute of that name.
  void write_string_attribute(const std::string& object, const std::string& name, const std::string& value);
  // An existing attribute is written in place (its stored type kept); a new one is a scalar
  // little-endian int64.
  void write_int_attribute(const std::string& object, const std::string& name, std::int64_t value);

  // Row `row` of member `member` of compound dataset `dataset`, as `width` doubles (converted by
  // HDF5 from the stored type); writing converts back and changes nothing else in the row.
  std::vector<double> read_member_row(const std::string& dataset, const std::string& member, std::uint64_t row) const;
  void write_member_row(const std::string& dataset, const std::string& member, std::uint64_t row,
                        const std::vector<double>& values);

  // The same for field `field` of element `index` of member `member`, an array of compound
  // elements: the member's row is read as stored, the field converted to doubles (H5Tconvert)
  // and, written, converted back into the row, the rest of the member as it was.
  std::vector<double> read_element_row(const std::string& dataset, const std::string& member, std::uint64_t index,
                                       const std::string& field, std::uint64_t row) const;
  void write_element_row(const std::string& dataset, const std::string& member, std::uint64_t index,
                         const std::string& field, std::uint64_t row, const std::vector<double>& values);

  // Edits.
  void set_extent(const std::string& dataset, const std::vector<std::uint64_t>& dims);
  // Rewrites compound dataset `dataset` without member `member` (or, for "<m>/<field>" where
  // <m> is an array of compound elements, without that field of every element): the other
  // members packed in order, every row kept; the copy is contiguous and keeps the attributes.
  void drop_member(const std::string& dataset, const std::string& member);
  void create_group(const std::string& path);
  // A 1-D chunked dataset of `values` (little-endian int64 or float64) with unlimited rows.
  void create_dataset(const std::string& path, const std::vector<std::int64_t>& values, std::uint64_t chunk_rows);
  void create_dataset(const std::string& path, const std::vector<double>& values, std::uint64_t chunk_rows);
  void start_swmr_write();   // the file must have been created with Format::kLatest
  void flush();

  struct Handles;

 private:
  File(std::string path, std::unique_ptr<Handles> handles);
  std::string path_;
  std::unique_ptr<Handles> handles_;
};

// Holds the module's process-wide HDF5 lock (every HDF5 call of recordings/ takes it; Debian's
// libhdf5 is not thread-safe) for its lifetime: while one is held, no other thread's trace
// writer or reader reaches the file, which is how a test makes a background writer slow.
class LibraryLock {
 public:
  LibraryLock();
  ~LibraryLock();
  LibraryLock(const LibraryLock&) = delete;
  LibraryLock& operator=(const LibraryLock&) = delete;

 private:
  struct Held;
  std::unique_ptr<Held> held_;
};

// Files, groups, datasets and attributes open in this process (H5Fget_obj_count): a reader that
// closed everything it opened leaves 0.
std::int64_t open_object_count();

}  // namespace graspsim::recordings::inspect
