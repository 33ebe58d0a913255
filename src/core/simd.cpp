#include <cstdlib>
#include <string_view>

#include "texel/detail/lanes.hpp"

namespace texel::detail {

int simd_lanes() {
  static const int lanes = [] {
    const char* cap_env = std::getenv("TEXEL_SIMD");
    const std::string_view cap = cap_env ? cap_env : "auto";
    const bool allow512 = cap == "auto" || cap == "avx512";
    const bool allow256 = allow512 || cap == "avx2";
#if defined(__x86_64__) || defined(__i386__)
    if (allow512 && __builtin_cpu_supports("avx512f")) return 8;
    if (allow256 && __builtin_cpu_supports("avx2")) return 4;
#else
    (void)allow512;
    (void)allow256;
#endif
    return 2;
  }();
  return lanes;
}

}  // namespace texel::detail
