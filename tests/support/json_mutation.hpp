// Deterministic mutations of JSON-ish text for the fuzz replay tests (the
// GCC side of each libFuzzer target): bit flips, JSON punctuation,
// truncations, deleted and duplicated spans, extreme numbers, strings swapped
// for numbers or objects. Mutation k of a text is a pure function of the
// generator and k, so a failure names a reproducible input.
#pragma once

#include <cstdint>
#include <string>

#include "texel/random.hpp"

namespace texel::test_support {

inline std::string mutate_json(const std::string& s, const texel::CounterRng& rng, std::uint64_t k) {
  std::string m = s;
  if (m.empty()) return m;
  const auto pos = static_cast<std::size_t>(rng.below(k * 8 + 1, m.size()));
  switch (rng.below(k * 8, 7)) {
    case 0: m[pos] = static_cast<char>(m[pos] ^ (1 << rng.below(k * 8 + 2, 8))); break;
    case 1: m[pos] = "{}[]\",:0-9e.tn\\ "[rng.below(k * 8 + 2, 17)]; break;
    case 2: m.resize(pos); break;
    case 3: m.erase(pos, static_cast<std::size_t>(rng.below(k * 8 + 2, 40))); break;
    case 4: m.insert(pos, m.substr(static_cast<std::size_t>(rng.below(k * 8 + 3, m.size())), 30)); break;
    case 5: {  // replace a number by an extreme one
      const auto d = m.find_first_of("0123456789", pos);
      if (d != std::string::npos) m.replace(d, 1, rng.below(k * 8 + 3, 2) ? "1e308" : "-99999999999");
      break;
    }
    default: {  // replace a string by a number or an object
      const auto q = m.find('"', pos);
      const auto e = q == std::string::npos ? q : m.find('"', q + 1);
      if (e != std::string::npos) m.replace(q, e - q + 1, rng.below(k * 8 + 3, 2) ? "7" : "{}");
      break;
    }
  }
  return m;
}

}  // namespace texel::test_support
