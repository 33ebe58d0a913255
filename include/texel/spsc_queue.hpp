// A fixed-capacity, lock-free, single-producer / single-consumer ring.
//
// The only way control data reaches the real-time thread (docs/contributing.md §2, "Real-time
// code"): one thread pushes, one other thread pops, neither ever blocks,
// allocates or frees. The ring is allocated once, by the constructor (in
// prepare), with a capacity chosen then; push and pop never touch the heap.
// Keeping the ring off the object keeps its owner small (a Player with a
// 4096-event queue is under 1 KiB, not 160 KiB) so it can live on any stack.
//
// Method: Lamport's ring with two monotonically increasing indices. `tail_` is
// written only by the producer and `head_` only by the consumer; each side
// reads the other's index with acquire and publishes its own with release, so
// a slot's contents are visible before the index that hands it over. Indices
// are free-running size_t and masked on access (capacity is a power of two),
// so "full" and "empty" need no wasted slot. Each index sits on its own cache
// line so the two threads do not false-share, and the ring pointer and mask,
// read by both and written by neither after construction, sit on a third;
// each side also caches the other side's index and re-reads the atomic only
// when the cached value says "full"/"empty" (fewer cross-core cache misses per
// operation).
//
// Trade-off: T must be trivially copyable (a slot is overwritten in place,
// never destroyed), and exactly one producer and one consumer thread may use
// a queue — a second producer needs a second queue.
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <string>
#include <type_traits>

#include "texel/error.hpp"

namespace texel {

template <class T>
class SpscQueue {
  static_assert(std::is_trivially_copyable_v<T>, "SpscQueue holds trivially copyable values only");

 public:
  static constexpr std::size_t max_capacity = std::size_t{1} << 24;

  /// prepare: allocates the ring of `capacity` slots (a power of two,
  /// 2 … max_capacity) once. Throws InvalidArgument naming the value.
  explicit SpscQueue(std::size_t capacity) {
    if (capacity < 2 || capacity > max_capacity || (capacity & (capacity - 1)) != 0)
      throw InvalidArgument("queue capacity is " + std::to_string(capacity) + "; allowed: a power of two, 2 … " +
                            std::to_string(max_capacity));
    slots_ = std::make_unique<T[]>(capacity);
    mask_ = capacity - 1;
  }
  SpscQueue(const SpscQueue&) = delete;
  SpscQueue& operator=(const SpscQueue&) = delete;

  [[nodiscard]] std::size_t capacity() const noexcept { return mask_ + 1; }

  /// Producer: appends `v`; false (and nothing changes) if the queue is full.
  bool try_push(const T& v) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail - head_cache_ > mask_) {
      head_cache_ = head_.load(std::memory_order_acquire);
      if (tail - head_cache_ > mask_) return false;
    }
    slots_[tail & mask_] = v;
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
    return &slots_[head & mask_];
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
  std::unique_ptr<T[]> slots_;                    // the ring; fixed after construction
  std::size_t mask_ = 0;                          // capacity − 1
  alignas(64) std::atomic<std::size_t> head_{0};  // written by the consumer
  std::size_t tail_cache_ = 0;                    // consumer's copy of tail_
  alignas(64) std::atomic<std::size_t> tail_{0};  // written by the producer
  std::size_t head_cache_ = 0;                    // producer's copy of head_
};

}  // namespace texel
