// The one counting allocator of the tests: the global operator new/delete
// (plain, array, nothrow, sized, over-aligned) replaced by versions that count
// what the current thread allocates and frees while its `counting` flag is on,
// and that throw std::bad_alloc while its `fail` flag is on. Used to prove
// that a real-time path allocates nothing and that running out of memory is
// reported, never crashes.
//
// It *defines* the replaceable operators: include it in exactly one
// translation unit of a test executable.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>

namespace texel::test_support::alloc {

inline thread_local bool counting = false;  ///< count this thread's allocations and frees
inline thread_local bool fail = false;      ///< make this thread's allocations throw std::bad_alloc
inline std::atomic<std::uint64_t> counted_allocations{0};
inline std::atomic<std::uint64_t> counted_frees{0};
inline std::atomic<std::uint64_t> all_allocations{0};  ///< every allocation of every thread

/// Counts this thread's allocations for its lifetime.
struct CountingScope {
  CountingScope() { counting = true; }
  ~CountingScope() { counting = false; }
  CountingScope(const CountingScope&) = delete;
  CountingScope& operator=(const CountingScope&) = delete;
};

inline void* allocate(std::size_t n, std::size_t align) {
  if (fail) throw std::bad_alloc();
  all_allocations.fetch_add(1, std::memory_order_relaxed);
  if (counting) counted_allocations.fetch_add(1, std::memory_order_relaxed);
  if (n == 0) n = 1;
  void* p = align <= alignof(std::max_align_t) ? std::malloc(n) : std::aligned_alloc(align, (n + align - 1) / align * align);
  if (!p) throw std::bad_alloc();
  return p;
}

inline void release(void* p) noexcept {
  if (p && counting) counted_frees.fetch_add(1, std::memory_order_relaxed);
  std::free(p);
}

/// Whether this program's operator new/delete are the counting ones: one
/// counted allocation and one counted free for a `new int` (the counters are
/// reset after). Each test program that includes this header checks it once.
inline bool counter_works() {
  counting = true;
  auto* volatile p = new int(3);
  delete p;
  counting = false;
  return counted_allocations.exchange(0) == 1 && counted_frees.exchange(0) == 1;
}

/// The real-time loop of the player tests: `blocks` calls of `process()`
/// (which returns the block's peak) with this thread's allocations and
/// frees counted from zero, publishing the number of blocks done to `done`
/// after each (a control thread paces its finger samples by it). Returns the
/// sum of the peaks; counted_allocations / counted_frees then hold what
/// process() allocated and freed.
template <class Process>
double count_blocks(std::uint64_t blocks, std::atomic<std::uint64_t>& done, Process&& process) {
  counted_allocations = 0;
  counted_frees = 0;
  double sum = 0;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    counting = true;
    const double peak = process();
    counting = false;
    sum += peak;
    done.store(b + 1, std::memory_order_relaxed);
  }
  return sum;
}

}  // namespace texel::test_support::alloc

// The replacements pair malloc/aligned_alloc with free on purpose.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(std::size_t n) { return texel::test_support::alloc::allocate(n, 0); }
void* operator new[](std::size_t n) { return texel::test_support::alloc::allocate(n, 0); }
void* operator new(std::size_t n, std::align_val_t a) {
  return texel::test_support::alloc::allocate(n, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t n, std::align_val_t a) {
  return texel::test_support::alloc::allocate(n, static_cast<std::size_t>(a));
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return texel::test_support::alloc::allocate(n, 0);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return operator new(n, std::nothrow); }
void operator delete(void* p) noexcept { texel::test_support::alloc::release(p); }
void operator delete[](void* p) noexcept { texel::test_support::alloc::release(p); }
void operator delete(void* p, std::size_t) noexcept { texel::test_support::alloc::release(p); }
void operator delete[](void* p, std::size_t) noexcept { texel::test_support::alloc::release(p); }
void operator delete(void* p, std::align_val_t) noexcept { texel::test_support::alloc::release(p); }
void operator delete[](void* p, std::align_val_t) noexcept { texel::test_support::alloc::release(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { texel::test_support::alloc::release(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { texel::test_support::alloc::release(p); }
