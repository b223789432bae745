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

// Every replaceable form is replaced, so that every allocation is counted and each block is freed
// by the library that allocated it: a sanitizer runtime supplies the forms left out (Catch2 calls
// the nothrow form), and AddressSanitizer rightly reports its block freed by our delete's free().
namespace graspsim::test::detail {
inline void* counted_malloc(std::size_t n) noexcept {
  ++g_allocations;
  return std::malloc(n ? n : 1);
}
// aligned_alloc wants a size that is a multiple of the alignment.
inline void* counted_aligned(std::size_t n, std::align_val_t alignment) noexcept {
  ++g_allocations;
  const auto a = static_cast<std::size_t>(alignment);
  return std::aligned_alloc(a, n == 0 ? a : (n + a - 1) / a * a);
}
inline void* or_throw(void* p) {
  if (p == nullptr) throw std::bad_alloc();
  return p;
}
}  // namespace graspsim::test::detail

namespace graspsim_alloc = graspsim::test::detail;
void* operator new(std::size_t n) { return graspsim_alloc::or_throw(graspsim_alloc::counted_malloc(n)); }
void* operator new[](std::size_t n) { return graspsim_alloc::or_throw(graspsim_alloc::counted_malloc(n)); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return graspsim_alloc::counted_malloc(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return graspsim_alloc::counted_malloc(n); }
void* operator new(std::size_t n, std::align_val_t a) { return graspsim_alloc::or_throw(graspsim_alloc::counted_aligned(n, a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return graspsim_alloc::or_throw(graspsim_alloc::counted_aligned(n, a)); }
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return graspsim_alloc::counted_aligned(n, a);
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return graspsim_alloc::counted_aligned(n, a);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
