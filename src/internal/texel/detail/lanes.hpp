// Explicit SIMD lanes for the bit-exact kernels (texel render, reference
// synthesis, device encoders). A kernel is written once as a template over
// the lane count W, instantiated inside functions compiled for AVX-512
// (W = 8), AVX2 (W = 4) and the baseline (W = 2), and picked at run time by
// simd_lanes(). Every lane performs the scalar operations in the same order
// in IEEE double (-ffp-contract=off), so the width changes speed, never bits.
#pragma once

#include <cstdint>

namespace texel::detail {

// W doubles in one vector register (`type`), the W-lane uint64 vector of
// their bits, and the W-lane int32, uint16 and float vectors the encoders
// convert through. Spelled out per width: GCC drops vector_size on a type
// that depends on a template parameter.
template <int W>
struct Lanes;
template <>
struct Lanes<2> {
  using type = double __attribute__((vector_size(16)));
  using u64 = std::uint64_t __attribute__((vector_size(16)));
  using i32 = std::int32_t __attribute__((vector_size(8)));
  using u16 = std::uint16_t __attribute__((vector_size(4)));
  using f32 = float __attribute__((vector_size(8)));
};
template <>
struct Lanes<4> {
  using type = double __attribute__((vector_size(32)));
  using u64 = std::uint64_t __attribute__((vector_size(32)));
  using i32 = std::int32_t __attribute__((vector_size(16)));
  using u16 = std::uint16_t __attribute__((vector_size(8)));
  using f32 = float __attribute__((vector_size(16)));
};
template <>
struct Lanes<8> {
  using type = double __attribute__((vector_size(64)));
  using u64 = std::uint64_t __attribute__((vector_size(64)));
  using i32 = std::int32_t __attribute__((vector_size(32)));
  using u16 = std::uint16_t __attribute__((vector_size(16)));
  using f32 = float __attribute__((vector_size(32)));
};

/// The widest lane count (8, 4 or 2) this CPU runs, chosen once. The
/// environment variable TEXEL_SIMD=avx512|avx2|sse2 caps it (the determinism
/// check compares every width on one machine); results never depend on it.
int simd_lanes();

}  // namespace texel::detail
