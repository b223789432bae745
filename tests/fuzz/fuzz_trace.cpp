// libFuzzer harness: the trace reader (recordings/src/trace_reader.cpp) and trace comparison
// (trace_compare.cpp), an HDF5 file in: what `graspsim compare` and `graspsim replay` read from a
// file they are given.
// Property: any bytes are read or refused with a TraceError naming the file (CompareInputError is
// one); a dataset read has as many values as its shape says; a file compared with itself is the
// same; no HDF5 file, group, dataset or attribute is left open afterwards. Anything else (a
// crash, in our code or inside libhdf5, a sanitizer finding, another exception, memory past
// -rss_limit_mb) is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "graspsim/recordings/h5_inspect.hpp"
#include "graspsim/recordings/trace_compare.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "tests/fuzz/fuzz_file.hpp"

using namespace graspsim;

namespace {

void require(bool holds) {
  if (!holds) std::abort();
}

template <typename F>
void refused_or_done(F&& read) {
  try {
    read();
  } catch (const recordings::TraceError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& file = fuzz::write_scratch(data, size, ".h5");
  refused_or_done([&] {
    for (const std::string& path : recordings::list_datasets(file)) {
      refused_or_done([&] {
        const recordings::Dataset d = recordings::read_dataset(file, path);
        std::size_t n = 1;
        for (std::size_t extent : d.shape) n *= extent;
        require(!d.shape.empty() && d.values.size() == n);
        require(d.bits.empty() || d.bits.size() == n);
      });
    }
  });
  // The root attributes replay and compare read first.
  for (const char* name : {"scenario_source", "scenario_path", "overrides", "status", "integrator"})
    refused_or_done([&] { (void)recordings::read_string_attribute(file, "/", name); });
  for (const char* name : {"schema_version", "rate_servo", "seed"})
    refused_or_done([&] { (void)recordings::read_int_attribute(file, "/", name); });
  refused_or_done([&] { (void)recordings::read_double_attribute(file, "/", "duration"); });
  refused_or_done([&] { (void)recordings::has_object(file, "/servo/fingers"); });
  // Compared with itself, as `graspsim compare --bitwise --attributes --all-ticks F F` would.
  refused_or_done([&] {
    recordings::CompareOptions options;
    options.bitwise = true;
    options.attributes = true;
    options.all_ticks = true;
    options.block_rows = 64;   // several blocks even for a small file
    require(recordings::compare_traces(file, file, options).same());
  });
  // Every file, group, dataset and attribute the reader and compare opened is closed, refused or
  // not (a datatype may be one the reader keeps for the process).
  require(recordings::inspect::open_object_count() == 0);
  return 0;
}
