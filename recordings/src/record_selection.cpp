// RecordSelection: the --record argument parsed, and the root attribute `record` written and read.
#include "graspsim/recordings/record_selection.hpp"

#include <numeric>
#include <stdexcept>

namespace graspsim::recordings {
namespace {

std::string known_loops() {
  std::string out;
  for (const std::string_view n : kRecordedLoopNames) {
    if (!out.empty()) out += ", ";
    out += n;
  }
  return out;
}

// EVERY: decimal digits only, 1 to kMaxEvery: a row every 10^9 ticks is one every 3.9 days of
// servo ticks at 3 kHz, and the bound keeps every product with a loop's period (at most the
// servo rate) or a golden's stride inside int64.
constexpr std::int64_t kMaxEvery = 1000000000;
bool parse_every(std::string_view text, std::int64_t& out) {
  if (text.empty() || text.size() > 10 || text.find_first_not_of("0123456789") != std::string_view::npos) return false;
  out = 0;
  for (const char c : text) out = out * 10 + (c - '0');
  return out >= 1 && out <= kMaxEvery;
}

}  // namespace

std::string RecordSelection::text() const {
  std::string out;
  for (std::size_t k = 0; k < every.size(); ++k)
    if (every[k] > 0) {
      if (!out.empty()) out += ',';
      out += kRecordedLoopNames[k];
      out += ':';
      out += std::to_string(every[k]);
    }
  return out;
}

RecordSelection RecordSelection::parse(std::string_view spec) {
  RecordSelection s;
  s.every.fill(0);
  if (spec.empty()) throw std::invalid_argument("names no loop (loops: " + known_loops() + ")");
  std::size_t start = 0;
  while (start <= spec.size()) {
    const std::size_t comma = std::min(spec.find(',', start), spec.size());
    const std::string_view item = spec.substr(start, comma - start);
    const std::size_t colon = item.find(':');
    const std::string_view name = item.substr(0, colon);
    if (item.empty()) throw std::invalid_argument("has an empty item in '" + std::string(spec) + "'");
    std::size_t k = 0;
    while (k < kRecordedLoopNames.size() && kRecordedLoopNames[k] != name) ++k;
    if (k == kRecordedLoopNames.size())
      throw std::invalid_argument("names an unknown loop '" + std::string(name) + "' (loops: " + known_loops() + ")");
    if (s.every[k] != 0) throw std::invalid_argument("names loop '" + std::string(name) + "' twice");
    std::int64_t every = 1;
    if (colon != std::string_view::npos && !parse_every(item.substr(colon + 1), every))
      throw std::invalid_argument("item '" + std::string(item) + "': EVERY must be a whole number from 1 to " + std::to_string(kMaxEvery));
    s.every[k] = every;
    start = comma + 1;
  }
  return s;
}

RecordSelection RecordSelection::from_attribute(const std::optional<std::string>& value) {
  if (!value) return {};
  if (value->empty()) {   // a run that recorded no loop cannot have written a trace, but say so
    RecordSelection none;
    none.every.fill(0);
    return none;
  }
  return parse(*value);
}

RecordSelection RecordSelection::thinned(std::int64_t stride, const std::array<std::int64_t, 3>& period) const {
  RecordSelection out = *this;
  for (std::size_t l = 0; l < period.size(); ++l) {
    if (every[l] <= 0) continue;
    // Loop tick k sits at servo tick k period: a multiple of the stride every stride / gcd ticks.
    out.every[l] = std::lcm(every[l], stride / std::gcd(stride, period[l]));
  }
  return out;
}

}  // namespace graspsim::recordings
