// Explicit SIMD lanes for the bit-exact kernels (texel render, reference
// synthesis). A kernel is written once as a template over the lane count W,
// instantiated inside functions compiled for AVX-512 (W = 8), AVX2 (W = 4)
// and the baseline (W = 2), and picked at run time by simd_lanes(). Every
// lane performs the scalar operations in the same order in IEEE double
// (-ffp-contract=off), so the width changes speed, never bits.
#pragma once

namespace texel::detail {

// W doubles in one vector register. Spelled out per width: GCC drops
// vector_size on a type that depends on a template parameter.
template <int W>
struct Lanes;
template <>
struct Lanes<2> {
  using type = double __attribute__((vector_size(16)));
};
template <>
struct Lanes<4> {
  using type = double __attribute__((vector_size(32)));
};
template <>
struct Lanes<8> {
  using type = double __attribute__((vector_size(64)));
};

/// The widest lane count (8, 4 or 2) this CPU runs, chosen once. The
/// environment variable TEXEL_SIMD=avx512|avx2|sse2 caps it (the determinism
/// check compares every width on one machine); results never depend on it.
int simd_lanes();

}  // namespace texel::detail
