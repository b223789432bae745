// Checks on what a trace file says about itself, made before HDF5 or this module acts on it: a
// trace may come from anywhere (a damaged disk, a mail attachment, a fuzzer), and neither a
// claimed extent nor a claimed string length may decide how much memory is taken or where
// HDF5 reads (recordings/README.md, "Reading untrusted traces").
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <string>

#include "h5.hpp"

namespace graspsim::recordings::h5 {

// Metadata read attempts of a SWMR reader. HDF5 retries a metadata block whose checksum fails
// (a writer may be half way through it) with a doubling sleep, and its default of 100 attempts
// makes one damaged byte wait for ever (measured: 30 attempts 3 ms, 40 attempts 1.1 s). 20
// tries a torn read again for about a millisecond, then fails.
inline constexpr unsigned kSwmrReadAttempts = 20;

// Deflate's largest compression ratio (RFC 1951: a 258-byte match in at least 2 bits, about
// 1032 : 1). A filtered dataset cannot hold more bytes than this times the bytes of its file.
inline constexpr std::uint64_t kMaxFilterRatio = 1032;

// The most a last chunk may add to that: our largest chunks are one flush interval (0.25 s of
// rows, 25 MB for a 10-finger /servo at 100 kHz); a damaged chunk size cannot raise it further.
inline constexpr std::uint64_t kMaxChunkSlack = 64ull << 20;   // bytes

// Values per row of one column: our widest holds 4 (a quaternion); more is a damaged type.
inline constexpr std::uint64_t kMaxColumnWidth = 1024;

struct OpenFile {
  Handle file;
  bool swmr = false;   // opened in SWMR read mode (the file was not closed cleanly)
};

// Opens an existing trace read-only. Refused at once, with `where` and the reason, before HDF5
// reads a byte: a missing path, a directory, anything that is not a regular file (a FIFO, a
// device such as /dev/zero, a socket: a read from one may never end). Then as HDF5: a plain
// open, else a SWMR read open (a file still marked open for writing) with kSwmrReadAttempts.
OpenFile open_read_only(const std::string& path, const std::string& where);

// The size of the file holding `object` in bytes (HDF5's view: its end of file).
std::uint64_t file_size(hid_t object, const std::string& context);

// Throws TraceError(context + ...) unless `rows` rows of `dataset` can be read into memory: the
// rows' bytes (rows x the stored size of one row) must fit in the file, times kMaxFilterRatio
// if the dataset is filtered (compressed), plus one chunk up to kMaxChunkSlack (a last chunk
// whose extent was written before its data). Checked with integer arithmetic that cannot overflow.
void check_rows(hid_t dataset, std::uint64_t rows, const std::string& context);

// Throws TraceError(context + ...) unless HDF5 can read the variable-length string value of the
// one-element `attribute` without reading outside the file's bytes: its reference (length,
// global heap collection, index) is read raw, the collection is read from the file and walked
// as HDF5 will walk it, and the object must lie inside it with exactly the claimed length.
// libhdf5 1.10 trusts both and copies past its buffers otherwise (a signal, not an error).
void check_variable_string(hid_t attribute, const std::string& name, const std::string& context);

}  // namespace graspsim::recordings::h5
