// Coarse texture profiles (docs/algorithm.md §7): one value c_k in [0, 1] per
// texel, sampled at the texel's centre from a function of position.
//
// Kinds: constant (the fine-only studies), a sinusoid of given period and
// phase, an explicit per-texel list, position/value points (linear
// interpolation, held flat beyond the ends: a CSV of position_mm,value), and a
// uniformly sampled signal (used to turn a reference texture into a profile).
#pragma once

#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "texel/units.hpp"

namespace texel {

struct ConstantProfile {
  double value = 1.0;  ///< in [0, 1]
};
/// c(x) = 0.5 + 0.5·sin(2π·(x/period + phase_deg/360)).
struct SineProfile {
  Millimetres period{5.0};  ///< > 0
  double phase_deg = 0.0;   ///< any finite value
};
/// c_k = values[k]; needs at least as many values as texels.
struct ValuesProfile {
  std::vector<double> values;
};
/// Piecewise-linear through (position_mm, value) points, strictly increasing positions.
struct PointsProfile {
  std::vector<std::pair<double, double>> points;
};
/// A signal sampled every `spacing` from position 0 (linear interpolation).
struct SampledProfile {
  Millimetres spacing{0.0};
  std::vector<double> values;
};

using CoarseProfile = std::variant<ConstantProfile, SineProfile, ValuesProfile, PointsProfile, SampledProfile>;

/// Throws InvalidArgument (naming the field) if the profile is malformed.
void validate(const CoarseProfile& profile);
/// Throws InvalidArgument when a ValuesProfile holds fewer than `count`
/// values (one per texel); other profiles cover any count.
void check_texel_values(const CoarseProfile& profile, std::size_t count);
/// c at each texel centre (k + 0.5)·L for k in [0, count). Throws
/// InvalidArgument when a ValuesProfile is shorter than `count`.
std::vector<double> sample_at_texel_centres(const CoarseProfile& profile, Millimetres texel_length, std::size_t count);
/// The same values for texels first … first + c.size() − 1, into c (bit for
/// bit the whole's). The profile must be valid and a ValuesProfile long
/// enough (the whole-count form checks both).
void sample_at_texel_centres(const CoarseProfile& profile, Millimetres texel_length, std::size_t first, std::span<double> c);
/// Human-readable kind ("constant", "sine", ...).
std::string kind_name(const CoarseProfile& profile);
/// Reads a CSV of position_mm,value rows (an optional header line is allowed).
PointsProfile read_profile_csv(const std::string& path);

}  // namespace texel
