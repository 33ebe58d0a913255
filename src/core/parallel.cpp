#include "texel/detail/parallel.hpp"

#include <algorithm>
#include <cstdlib>
#include <optional>

#if defined(__linux__)
#include <sched.h>
#endif

namespace texel::detail {
namespace {

/// TEXEL_THREADS as a count (1 … 64), if set to one.
std::optional<int> threads_from_environment() {
  static const std::optional<int> threads = []() -> std::optional<int> {
    if (const char* env = std::getenv("TEXEL_THREADS"); env != nullptr && *env != '\0') {
      char* end = nullptr;
      const long v = std::strtol(env, &end, 10);
      if (end != env && *end == '\0' && v >= 1) return static_cast<int>(std::min(v, 64L));
    }
    return std::nullopt;
  }();
  return threads;
}

}  // namespace

int available_processors() {
  unsigned cores = std::thread::hardware_concurrency();
#if defined(__linux__)
  // The processors this process may run on (taskset, a container's cpuset),
  // which can be fewer than the machine's.
  cpu_set_t set;
  if (::sched_getaffinity(0, sizeof set, &set) == 0) cores = static_cast<unsigned>(CPU_COUNT(&set));
#endif
  return static_cast<int>(std::max(cores, 1u));
}

int worker_threads(int cap) {
  if (const std::optional<int> env = threads_from_environment()) return *env;
  return std::clamp(available_processors(), 1, std::max(cap, 1));
}

}  // namespace texel::detail
