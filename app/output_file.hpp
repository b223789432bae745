// Where a run's trace goes, and how it gets there without losing what was there before
// (README.md "What can go wrong"): a default name kept inside the working directory; an output
// that is one of the run's inputs refused; and a claim on the output path: the trace is written
// to `<out>.partial`, locked while a run writes it, and renamed to `<out>` only once it is
// complete or marked with its error.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace graspsim::app {

// The output cannot be used: it is an input, a directory, locked by another run, or a partial
// trace of a run that did not finish is in the way. The message names the file and why; the CLI
// exits 2, having written nothing.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "<name>.h5" for a scenario `name`, a plain file name in the working directory: every byte
// outside [A-Za-z0-9_.-] (a '/', a '\', a space, a control character, any non-ASCII byte)
// becomes '_', and so does a '.' that starts or ends the name or follows another '.' (no "..",
// no hidden file). An empty name gives "trace"; a name is cut to kMaxStem bytes first.
std::string default_trace_name(const std::string& scenario_name);
constexpr std::size_t kMaxStem = 200;   // bytes: with ".h5.partial" well under NAME_MAX (255)

// How a command names its output in messages: the option that gave it, and how to write none.
struct OutputNaming {
  std::string option = "--out";                              // "--out", "--summary", "trace="
  std::string write_none = "--no-trace writes no trace";     // what to do instead
};

// What is at `path`, symbolic links followed, when it is not a file an output may replace: "a
// character device", "a block device", "a FIFO", "a socket", "a directory" (with "a symbolic
// link to " before it when a link leads there); "" when nothing is there or a regular file is.
// Every output is written beside its path and renamed over it, which would put a regular file in
// place of a device (/dev/null as root: for every program on the machine), a FIFO or a socket.
std::string not_replaceable(const std::string& path);

// Throws OutputError when not_replaceable(path) is not "": names the path as `naming.option` gave
// it, what it is, and what to do instead (`naming.write_none`).
void refuse_unreplaceable(const std::string& path, const OutputNaming& naming);

// A file the run reads, and what it is for messages: "the scenario", "mesh file", "finger
// 'thumb''s replay recording".
struct InputFile {
  std::string path;
  std::string what;
};

// The name the trace is written under until the run ends: "<out>.partial".
std::string partial_name(const std::string& out);

// Throws OutputError if `out`, or the partial name it is written under, is one of `inputs`:
// the same name, or the same file (device and inode, symbolic links followed, so a link or a
// hard link to an input is refused too). The message names `out` as the option `flag` gave it.
void refuse_input_as_output(const std::string& out, const std::vector<InputFile>& inputs,
                            const std::string& flag = "--out");

// True when a run holds the lock of an OutputClaim on `path` (its partial trace is being
// written): such a file must not be repaired or written by anyone else.
bool locked_by_a_run(const std::string& path);

// A run's claim on its output path. The constructor creates `<out>.partial` and takes an
// exclusive open-file-description lock (fcntl F_OFD_SETLK, which HDF5's own flock() locks
// do not interfere with) on it, held until the claim ends. Throws OutputError, having changed
// nothing, when `out` is not a file to replace (refuse_unreplaceable: a directory, a device, a
// FIFO, a socket), when the partial's name is taken by anything but a regular file, when
// another run holds the lock ("another graspsim run is writing ..."), when a non-empty partial
// is there unlocked (a run that was killed: its trace is kept, never overwritten), or when the
// partial cannot be created.
class OutputClaim {
 public:
  explicit OutputClaim(const std::string& out, const OutputNaming& naming = {});
  // Releases the lock. A partial neither committed nor abandoned is left where it is if it holds
  // anything (a trace this run could not finish), and removed if it is empty.
  ~OutputClaim();
  OutputClaim(const OutputClaim&) = delete;
  OutputClaim& operator=(const OutputClaim&) = delete;

  const std::string& out() const { return out_; }
  const std::string& partial() const { return partial_; }
  // Renames the partial to `out`, replacing what was there (a symbolic link at `out` is replaced
  // by the trace; its target is left alone). Throws OutputError naming both on failure, or when
  // something other than a regular file has taken `out` since the claim, leaving the partial in
  // place.
  void commit();
  // Removes the partial: this run leaves nothing, and `out` is as it was.
  void abandon();

 private:
  bool still_ours() const;   // the partial's name still leads to the file this claim locked
  std::string out_, partial_;
  OutputNaming naming_;
  int fd_ = -1;              // the partial, open and locked
  bool done_ = false;        // committed or abandoned
};

}  // namespace graspsim::app
