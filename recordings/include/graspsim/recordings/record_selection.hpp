// Which loops a trace holds, and how often: `graspsim run --record LOOP[:EVERY],...` and the
// trace's root attribute `record` (recordings/README.md "Attributes"), read back by compare and
// replay so that they know what a trace holds.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace graspsim::recordings {

// The tables a run can record: the three loops, /devices/<finger> (one row per servo tick) and
// /contacts (one row per contact point of the bodies per physics tick; its EVERY counts physics
// ticks).
enum class RecordedLoop : std::size_t { kServo = 0, kHaptic = 1, kPhysics = 2, kDevices = 3, kContacts = 4 };
inline constexpr std::array<std::string_view, 5> kRecordedLoopNames = {"servo", "haptic", "physics", "devices",
                                                                       "contacts"};

struct RecordSelection {
  // Per RecordedLoop: a row is kept at every `every`-th tick of that loop, counted from its
  // first tick (tick index k of the loop is kept when k % every == 0); 0: the loop is not
  // recorded. Default: every loop at every tick, and no /contacts (its rows, a few per body per
  // physics tick, would make a trace of resting bodies several times larger: recordings/README.md).
  std::array<std::int64_t, 5> every{1, 1, 1, 1, 0};

  std::int64_t of(RecordedLoop loop) const { return every[static_cast<std::size_t>(loop)]; }
  bool records(RecordedLoop loop) const { return of(loop) > 0; }
  // The default selection (what a run records without --record).
  bool everything() const { return every == std::array<std::int64_t, 5>{1, 1, 1, 1, 0}; }

  // "servo:1,haptic:1,physics:1,devices:1": every recorded loop with its EVERY, in
  // kRecordedLoopNames order; the root attribute's value, and a valid --record argument.
  std::string text() const;

  // A --record argument: LOOP[:EVERY] items separated by commas, LOOP one of
  // kRecordedLoopNames, EVERY a whole number from 1 to 10^9 (default 1); loops not named are not
  // recorded. Throws std::invalid_argument naming the item that is wrong (an unknown loop, an
  // EVERY that is not a whole number from 1 to 10^9, a loop named twice, an empty item).
  static RecordSelection parse(std::string_view spec);
  // The root attribute `record` as read from a trace; nullopt (a trace written before the
  // attribute) means every loop at every tick, and no /contacts.
  static RecordSelection from_attribute(const std::optional<std::string>& value);

  // What is left when only the rows at servo ticks that are multiples of `stride` are kept (a
  // golden's decimation), `period[l]` servo ticks being one tick of loop l: a loop kept every
  // e-th of its ticks keeps every lcm(e, stride / gcd(stride, period))-th. /devices and
  // /contacts are copied whole, so they keep their EVERY.
  RecordSelection thinned(std::int64_t stride, const std::array<std::int64_t, 3>& period) const;
};

}  // namespace graspsim::recordings
