// decimate_trace: a smaller copy of a trace, holding the rows of its loops (/servo, /haptic,
// /physics) at every `stride`-th servo tick and everything else whole (README.md, "Golden
// traces", uses it to make goldens).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace graspsim::recordings {

struct DecimateOptions {
  std::int64_t stride = 1;   // servo ticks: a loop's row is kept when its tick % stride == 0
  int compression = 9;       // deflate level (1..9) of every copied dataset, after byte shuffle
  // Root string attributes written after the copied ones, in this order (replacing a copied
  // one of the same name): what the copy is, for its readers.
  std::vector<std::pair<std::string, std::string>> root_strings;
};

// Writes the decimated copy of trace `in` to `out`, through `out`.part renamed at the end (an
// existing `out` is replaced only by a whole copy). Every root, group, table and column
// attribute is copied with its own type; a loop table of either schema (3: one compound
// dataset, 2: a group of datasets with a `tick` dataset) keeps the rows whose tick is a multiple
// of the stride; any other dataset is copied whole. Datasets are chunked (up to 8192 rows),
// without time stamps and in the 1.10 file format, so the copy's bytes depend on its content
// only. Throws TraceError naming the file and the dataset on failure, or for a stride < 1.
void decimate_trace(const std::string& in, const std::string& out, const DecimateOptions& options);

}  // namespace graspsim::recordings
