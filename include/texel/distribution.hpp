// The texel-frequency distribution (docs/algorithm.md §4, §5).
//
// Lognormal in two parameterizations:
//  - moments (default, the source's): Central Pitch is the mean m and
//    Irregularity the standard deviation s of the frequency in cpm;
//    sigma² = ln(1 + s²/m²), mu = ln m − sigma²/2 (MATLAB lognrnd's mapping).
//  - log [choice, extension]: Central Pitch is the median exp(mu) and
//    Irregularity the standard deviation of 10·log10(f) in dB, so
//    sigma = I·ln(10)/10 and I must be >= 0.
// Draws outside [f_min, f_max] are re-drawn (truncated distribution, default)
// or clamped [choice]. Quantization rounds to a log grid q dB apart.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "texel/option_spec.hpp"
#include "texel/random.hpp"
#include "texel/units.hpp"

namespace texel {

enum class Parameterization { moments, log };
enum class OutOfBand { redraw, clamp };
/// Their spellings, for the options' descriptions (texel/option_spec.hpp).
inline constexpr OptionChoice parameterizations[] = {{"moments", static_cast<int>(Parameterization::moments)},
                                                     {"log", static_cast<int>(Parameterization::log)}};
inline constexpr OptionChoice out_of_band_rules[] = {{"redraw", static_cast<int>(OutOfBand::redraw)},
                                                     {"clamp", static_cast<int>(OutOfBand::clamp)}};

std::string_view to_string(Parameterization p);
std::string_view to_string(OutOfBand o);
/// Parse "moments" / "log"; throws InvalidArgument naming `field`.
Parameterization parse_parameterization(std::string_view text, std::string_view field = "parameterization");
OutOfBand parse_out_of_band(std::string_view text, std::string_view field = "out_of_band");

/// The ranges PitchDistribution accepts (the one place for each rule; the
/// studio's hello sends them to the designer's fields).
inline constexpr double central_pitch_db_min = -40.0;
inline constexpr double central_pitch_db_max = 40.0;
inline constexpr double irregularity_db_min = -60.0;  ///< moments; log needs >= 0 (see the constructor)
inline constexpr double irregularity_db_max = 40.0;
inline constexpr double quantization_db_max = 20.0;
/// The band edges a document or device profile may state (cycles/mm):
/// band_min in [band_cpm_min, band_cpm_max], band_max 0 (Nyquist) or up to
/// band_cpm_max; on a grid band_min must also lie below the band's top.
inline constexpr double band_cpm_min = 1e-12;
inline constexpr double band_cpm_max = 1e12;

struct PitchDistributionConfig {
  Decibels central_pitch{10.0};  ///< dB re 1 cpm; -20 … 19.7 dB on the reference device
  Decibels irregularity{-5.0};   ///< dB re 1 cpm (moments) or dB of log-spread (log, >= 0)
  Parameterization parameterization = Parameterization::moments;
  OutOfBand out_of_band = OutOfBand::redraw;
  CyclesPerMm band_min{0.01};               ///< lowest renderable frequency (cpm), > 0
  CyclesPerMm band_max{94.33962264150944};  ///< highest (cpm): the grid's Nyquist frequency
  double quantization_db = 0.0;             ///< 0 = off; else grid spacing in dB, > 0
};

/// A validated, prepared distribution. Value type; draw() is pure.
class PitchDistribution {
 public:
  /// Validates the config; throws InvalidArgument if a value is out of range
  /// or the band [band_min, band_max] holds less than `min_band_mass` of the
  /// distribution (a drawing loop would then almost never terminate).
  explicit PitchDistribution(const PitchDistributionConfig& config);

  /// Frequency (cpm) of draw `index` for `seed`: a pure function.
  [[nodiscard]] double draw(std::uint64_t seed, std::uint64_t index) const;
  /// out[i] = draw(seed, first + i), bit for bit, for a run of draws: the
  /// usual first attempts computed a vector of texels at a time, the rare
  /// ones (a tail of the normal quantile, a redraw) by draw itself.
  void draw(std::uint64_t seed, std::uint64_t first, std::span<double> out) const;

  [[nodiscard]] double mu() const { return mu_; }        ///< mean of ln f
  [[nodiscard]] double sigma() const { return sigma_; }  ///< standard deviation of ln f
  /// Fraction of the untruncated distribution inside the band.
  [[nodiscard]] double band_mass() const { return band_mass_; }
  [[nodiscard]] const PitchDistributionConfig& config() const { return config_; }

  /// Round a frequency to the q-dB grid, kept inside the band (a grid value
  /// above band_max steps down by q, below band_min steps up).
  [[nodiscard]] double quantize(double f_cpm) const;

  static constexpr double min_band_mass = 1e-3;
  /// Draw attempts per texel before the redraw gives up and clamps. With the
  /// band mass >= 1e-3 the chance of reaching it is below 1e-40.
  static constexpr std::uint64_t max_attempts = 1u << 17;

 private:
  PitchDistributionConfig config_;
  double mu_ = 0.0;
  double sigma_ = 0.0;
  double band_mass_ = 1.0;
};

}  // namespace texel
