// Real-time scheduling of Texel's own threads (detail/realtime.hpp).
#include "texel/detail/realtime.hpp"

#include <cstring>

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>

namespace texel::detail {

namespace {
ThreadScheduling pack(int policy, int priority, int error) {
  return {static_cast<std::uint64_t>(policy & 0xff) | static_cast<std::uint64_t>(priority & 0xff) << 8 |
          static_cast<std::uint64_t>(error & 0xffff) << 16 | std::uint64_t{1} << 48};
}
}  // namespace

ThreadScheduling current_scheduling() noexcept {
  int policy = SCHED_OTHER;
  sched_param p{};
  if (pthread_getschedparam(pthread_self(), &policy, &p) != 0) return {};
  return pack(policy, p.sched_priority, 0);
}

ThreadScheduling make_thread_realtime() noexcept {
  ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);  // wake-ups on time, not coalesced (default 50 µs)
  sched_param p{};
  p.sched_priority = realtime_priority;
  const int error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
  ThreadScheduling now = current_scheduling();
  if (error != 0) now.packed |= static_cast<std::uint64_t>(error & 0xffff) << 16;
  return now;
}

std::string describe(ThreadScheduling s) {
  if (!(s.packed >> 48)) return "not started";
  const int policy = static_cast<int>(s.packed & 0xff);
  const int priority = static_cast<int>((s.packed >> 8) & 0xff);
  const int error = static_cast<int>((s.packed >> 16) & 0xffff);
  const char* name = policy == SCHED_FIFO ? "SCHED_FIFO" : policy == SCHED_RR ? "SCHED_RR" : "SCHED_OTHER";
  std::string out = name;
  if (policy == SCHED_FIFO || policy == SCHED_RR) return out + " priority " + std::to_string(priority) + " (real-time)";
  if (error != 0) out += std::string(" (real-time refused: ") + std::strerror(error) + ")";
  return out;
}

}  // namespace texel::detail
