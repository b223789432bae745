// A 64-bit fingerprint of the whole engine State, for the trace's per-physics-tick state_hash
// column: a replay that reproduces every hash reproduced the run bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>

#include "graspsim/engine/state.hpp"

namespace graspsim {

inline constexpr std::uint64_t kFnv1a64Offset = 14695981039346656037ull;   // FNV-1a 64 basis
inline constexpr std::uint64_t kFnv1a64Prime = 1099511628211ull;           // FNV-1a 64 prime

// FNV-1a 64 of `size` bytes, continuing from `hash` (start: kFnv1a64Offset).
std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t hash = kFnv1a64Offset);

// A hash of every field of the State by its exact bits, in a fixed order (engine/README.md,
// "State hash"): each value is widened to a 64-bit word w (double: its IEEE bits, so -0.0 != 0.0
// and NaN payloads count; integers, enums and bools: as int64) and fed as
//   h = (h xor w) * kFnv1a64Prime;  h = h xor (h >> 32)      (from h = kFnv1a64Offset);
// every vector's length is fed before its elements. Never reads struct padding. Allocates nothing.
std::uint64_t state_hash(const State& state);

}  // namespace graspsim
