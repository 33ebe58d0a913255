#include "texel/detail/parallel.hpp"

#include <cstdlib>

namespace texel::detail {

int worker_threads() {
  static const int threads = [] {
    if (const char* env = std::getenv("TEXEL_THREADS"); env != nullptr && *env != '\0') {
      char* end = nullptr;
      const long v = std::strtol(env, &end, 10);
      if (end != env && *end == '\0' && v >= 1) return static_cast<int>(v < 64 ? v : 64);
    }
    return std::thread::hardware_concurrency() >= 2 ? 2 : 1;
  }();
  return threads;
}

}  // namespace texel::detail
