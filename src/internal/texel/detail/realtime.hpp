// Real-time scheduling for the threads Texel itself runs (the paced
// backends' loop; the JACK benchmark reports what JACK gave its own thread):
// SCHED_FIFO when the system allows it, timer slack of 1 ns either way.
#pragma once

#include <cstdint>
#include <string>

namespace texel::detail {

/// Policy, priority and the error of the request, packed in one word so it
/// can live in a lock-free atomic.
struct ThreadScheduling {
  std::uint64_t packed = 0;  // policy | priority << 8 | error << 16 | set << 48
};

/// The SCHED_FIFO priority Texel asks for: a middle value of 1 … 99, above
/// ordinary real-time helpers, below the kernel's own threads on RT kernels.
inline constexpr int realtime_priority = 70;

/// On the calling thread: sets its timer slack to 1 ns (prctl) and asks for
/// SCHED_FIFO at realtime_priority. Never throws; returns what it got.
ThreadScheduling make_thread_realtime() noexcept;
/// The calling thread's current policy and priority.
ThreadScheduling current_scheduling() noexcept;
/// "SCHED_FIFO priority 70 (real-time)" or "SCHED_OTHER (real-time refused: Operation not permitted)".
std::string describe(ThreadScheduling s);

}  // namespace texel::detail
