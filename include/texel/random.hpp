// Texel's own random numbers, specified so that a texture file re-creates the
// same draw on every platform and compiler (docs/algorithm.md §9).
//
// Counter-based: a draw is a pure function of (seed, stream, counter), so the
// frequency of texel k is computed without drawing texels 0..k-1. That gives
// random access (any window of a texture), streaming and regions for free.
//
//   key(seed, stream)  = mix64(seed ^ mix64(stream + 0x9E3779B97F4A7C15))
//   bits(counter)      = mix64(key + (counter + 1)·0x9E3779B97F4A7C15)
//   mix64              = the SplitMix64 / MurmurHash3 fmix64 finalizer
//                        (z ^= z>>30; z *= 0xBF58476D1CE4E5B9; z ^= z>>27;
//                         z *= 0x94D049BB133111EB; z ^= z>>31)
//   uniform(counter)   = ((bits >> 11) + 0.5) · 2^-53       in (0, 1), never 0 or 1
//   normal(counter)    = Φ^-1(uniform(counter))             (AS241)
//
// This is SplitMix64 indexed directly by its counter, which passes BigCrush
// as a sequence; keys of different streams are decorrelated by a second mix.
#pragma once

#include <cstdint>

#include "texel/detmath.hpp"

namespace texel {

/// The SplitMix64 output function (a bijection on 64-bit words), generic
/// over the word type: std::uint64_t, or a GCC/clang vector of them whose
/// every lane does the scalar operations (modular, so exactly the same).
template <class U>
[[gnu::always_inline]] constexpr U mix64_generic(U z) {
  z ^= z >> 30;
  z *= 0xBF58476D1CE4E5B9ULL;
  z ^= z >> 27;
  z *= 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return z;
}

/// The SplitMix64 output function (a bijection on 64-bit words).
constexpr std::uint64_t mix64(std::uint64_t z) { return mix64_generic(z); }

/// High 64 bits of the 128-bit product a·b, portably.
constexpr std::uint64_t mul_high(std::uint64_t a, std::uint64_t b) {
  const std::uint64_t a_lo = a & 0xFFFFFFFFu, a_hi = a >> 32;
  const std::uint64_t b_lo = b & 0xFFFFFFFFu, b_hi = b >> 32;
  const std::uint64_t lo_lo = a_lo * b_lo;
  const std::uint64_t hi_lo = a_hi * b_lo;
  const std::uint64_t lo_hi = a_lo * b_hi;
  const std::uint64_t cross = (lo_lo >> 32) + (hi_lo & 0xFFFFFFFFu) + lo_hi;
  return a_hi * b_hi + (hi_lo >> 32) + (cross >> 32);
}

/// Named streams so that the draws for different purposes never collide.
enum class Stream : std::uint64_t {
  frequency = 1,  ///< texel frequencies (counter = texel index · 2^20 + attempt)
  phase = 2,      ///< initial phase (continuous) or per-texel phases (reset)
  reference = 3,  ///< reference-texture noise and shuffles
  channel = 4,    ///< per-channel seeds of a simultaneous texture (counter = channel index; texel/multichannel.hpp)
  user = 16,      ///< first stream free for other modules
};

/// A counter-based generator: value type, no state beyond its key.
class CounterRng {
 public:
  constexpr CounterRng(std::uint64_t seed, std::uint64_t stream) : key_(mix64(seed ^ mix64(stream + 0x9E3779B97F4A7C15ULL))) {}
  constexpr CounterRng(std::uint64_t seed, Stream stream) : CounterRng(seed, static_cast<std::uint64_t>(stream)) {}

  /// 64 random bits for this counter.
  [[nodiscard]] constexpr std::uint64_t bits(std::uint64_t counter) const { return bits_generic(counter); }
  /// bits(), generic over the counter type like mix64_generic: a vector of
  /// counters gives each lane's bits.
  template <class U>
  [[nodiscard]] [[gnu::always_inline]] constexpr U bits_generic(U counter) const {
    return mix64_generic(key_ + (counter + 1) * 0x9E3779B97F4A7C15ULL);
  }
  /// Uniform in the open interval (0, 1), 53-bit resolution.
  [[nodiscard]] constexpr double uniform(std::uint64_t counter) const {
    // k + 0.5 is exact only for k < 2^52; above that it rounds to even, and
    // k = 2^53 − 1 would round up to 2^53, i.e. u = 1 (Φ⁻¹(1) = +inf). Map that
    // one word to the largest double below 1; every other value is unchanged.
    const double u = (static_cast<double>(bits(counter) >> 11) + 0.5) * 0x1.0p-53;
    return u < 1.0 ? u : 0x1.fffffffffffffp-1;
  }
  /// Standard normal by inversion of the CDF (one uniform per normal).
  [[nodiscard]] double normal(std::uint64_t counter) const { return detmath::normal_quantile(uniform(counter)); }
  /// Uniform integer in [0, n), n > 0 (Lemire's multiply-shift; the bias is < n/2^64).
  [[nodiscard]] constexpr std::uint64_t below(std::uint64_t counter, std::uint64_t n) const { return mul_high(bits(counter), n); }

 private:
  std::uint64_t key_;
};

/// A sequential generator over a CounterRng, for code that draws many values
/// in order (reference noise, shuffles). Same numbers as CounterRng at
/// counters 0, 1, 2, ...
class SequentialRng {
 public:
  SequentialRng(std::uint64_t seed, std::uint64_t stream) : rng_(seed, stream) {}
  SequentialRng(std::uint64_t seed, Stream stream) : rng_(seed, stream) {}
  std::uint64_t bits() { return rng_.bits(counter_++); }
  double uniform() { return rng_.uniform(counter_++); }
  double normal() { return rng_.normal(counter_++); }
  std::uint64_t below(std::uint64_t n) { return rng_.below(counter_++, n); }
  [[nodiscard]] std::uint64_t position() const { return counter_; }

 private:
  CounterRng rng_;
  std::uint64_t counter_ = 0;
};

}  // namespace texel
