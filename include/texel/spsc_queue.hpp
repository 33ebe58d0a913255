// A fixed-capacity, lock-free, single-producer / single-consumer ring.
//
// The only way control data reaches the real-time thread (style.md, "Real-time
// code"): one thread pushes, one other thread pops, neither ever blocks,
// allocates or frees. Storage is inline (std::array), so the queue is built
// once (in prepare) and never touches the heap again.
//
// Method: Lamport's ring with two monotonically increasing indices. `tail_` is
// written only by the producer and `head_` only by the consumer; each side
// reads the other's index with acquire and publishes its own with release, so
// a slot's contents are visible before the index that hands it over. Indices
// are free-running size_t and masked on access (capacity is a power of two),
// so "full" and "empty" need no wasted slot. Each index sits on its own cache
// line so the two threads do not false-share; each side also caches the other
// side's index and re-reads the atomic only when the cached value says
// "full"/"empty" (fewer cross-core cache misses per operation).
//
// Trade-off: T must be trivially copyable (a slot is overwritten in place,
// never destroyed), and exactly one producer and one consumer thread may use
// a queue — a second producer needs a second queue.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <type_traits>

namespace texel {

template <class T, std::size_t Capacity>
class SpscQueue {
  static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "SpscQueue capacity must be a power of two");
  static_assert(std::is_trivially_copyable_v<T>, "SpscQueue holds trivially copyable values only");

 public:
  static constexpr std::size_t capacity = Capacity;

  /// Producer: appends `v`; false (and nothing changes) if the queue is full.
  bool try_push(const T& v) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail - head_cache_ == Capacity) {
      head_cache_ = head_.load(std::memory_order_acquire);
      if (tail - head_cache_ == Capacity) return false;
    }
    slots_[tail & (Capacity - 1)] = v;
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Consumer: the oldest value without removing it, or nullptr if empty.
  /// The pointer stays valid until pop().
  const T* front() noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_cache_) {
      tail_cache_ = tail_.load(std::memory_order_acquire);
      if (head == tail_cache_) return nullptr;
    }
    return &slots_[head & (Capacity - 1)];
  }

  /// Consumer: removes the oldest value (call only after front() != nullptr).
  void pop() noexcept { head_.store(head_.load(std::memory_order_relaxed) + 1, std::memory_order_release); }

  /// Consumer: removes the oldest value into `out`; false if empty.
  bool try_pop(T& out) noexcept {
    const T* f = front();
    if (!f) return false;
    out = *f;
    pop();
    return true;
  }

  /// Approximate number of queued values (exact when called by either side
  /// while the other is idle).
  [[nodiscard]] std::size_t size() const noexcept {
    return tail_.load(std::memory_order_acquire) - head_.load(std::memory_order_acquire);
  }

 private:
  alignas(64) std::atomic<std::size_t> head_{0};  // written by the consumer
  std::size_t tail_cache_ = 0;                    // consumer's copy of tail_
  alignas(64) std::atomic<std::size_t> tail_{0};  // written by the producer
  std::size_t head_cache_ = 0;                    // producer's copy of head_
  alignas(64) std::array<T, Capacity> slots_{};
};

}  // namespace texel
