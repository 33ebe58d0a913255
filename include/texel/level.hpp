// A level in dB — a ratio of amplitudes or powers: a peak below the highest,
// an attenuation, a plot's dynamic range — as its own unit type, beside the
// ones in units.hpp. It is not a frequency: a `Decibels` is dB re 1 cycle/mm
// and converts to cycles/mm (to_cpm); a `DecibelsLevel` never does, and the
// two do not mix (docs/algorithm.md §2).
#pragma once

#include "texel/units.hpp"

namespace texel {

struct LevelDecibelTag {};
using DecibelsLevel = Quantity<LevelDecibelTag>;  ///< a level (amplitude or power ratio) in dB

namespace literals {
constexpr DecibelsLevel operator""_level_dB(long double v) { return DecibelsLevel(static_cast<double>(v)); }
constexpr DecibelsLevel operator""_level_dB(unsigned long long v) { return DecibelsLevel(static_cast<double>(v)); }
}  // namespace literals

}  // namespace texel
