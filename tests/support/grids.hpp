// The device grids the tests render on, written once.
#pragma once

#include <cmath>
#include <cstdint>

#include "texel/grid.hpp"

namespace texel::test_support {

/// The tpad's sample spacing (mm) and sample count (docs/algorithm.md §8).
inline constexpr double tpad_dx = 0.0053;
inline constexpr std::int64_t tpad_samples = 19200;

/// The tpad's grid from x = 0: 19,200 samples 0.0053 mm apart (101.76 mm).
inline constexpr Grid tpad_grid() { return Grid{Millimetres(0.0), Millimetres(tpad_dx), tpad_samples}; }

/// The tpad's spacing over another length: round(length / 0.0053) samples.
inline Grid tpad_grid(double length_mm) {
  return Grid{Millimetres(0.0), Millimetres(tpad_dx), static_cast<std::int64_t>(std::llround(length_mm / tpad_dx))};
}

}  // namespace texel::test_support
