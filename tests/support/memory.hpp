// Shared by the bounded-memory tests: the process's peak resident memory and
// a bitwise comparison of double arrays.
#pragma once

#include <sys/resource.h>

#include <cstring>
#include <vector>

namespace texel::test_support {

/// The process's peak resident set so far, in KiB (getrusage ru_maxrss).
inline long peak_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

/// True when a and b hold the same doubles bit for bit.
inline bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

}  // namespace texel::test_support
