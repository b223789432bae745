// Counts heap allocations in a test executable, for the real-time rule that a servo tick
// allocates nothing after warm-up (Drake's rule: an allocation can take microseconds and its
// timing is unbounded, which a 3 kHz device loop cannot afford). Replaces the global operator
// new and delete: include this header in exactly one source file of an executable of its own,
// so the replacement touches no other test. Read graspsim::test::allocations() before and after.
#pragma once

#include <atomic>
#include <cstdlib>
#include <new>

namespace graspsim::test {
inline std::atomic<long> g_allocations{0};   // operator new calls so far
inline long allocations() { return g_allocations.load(); }
}  // namespace graspsim::test

void* operator new(std::size_t n) {
  ++graspsim::test::g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
