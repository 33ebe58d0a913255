// Textures: device-independent functions of position.
//
// `Texture` is the prepared, immutable form every renderer, encoder and player
// consumes: amplitude in [0, 1] at positions along the swipe axis, measured
// from the texture's own origin (0 mm = left edge of its region). Positions
// outside [0, length) are at rest (0).
//
// `TexelSpec` is the configuration of a multi-scale Texel texture
// (docs/algorithm.md §3–§7): the fine texture is defined by (pitch distribution,
// texel length, seed) alone; the coarse profile and strengths shape its
// envelope. `TexelTexture` is its prepared form: per-texel frequency, start
// phase and envelope, computed once (texel k's draw depends only on k, so this
// is O(texels), not O(samples)); rendering any window is then a pure function
// of the sample's position.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "texel/coarse.hpp"
#include "texel/distribution.hpp"
#include "texel/grid.hpp"
#include "texel/option_spec.hpp"
#include "texel/units.hpp"

namespace texel {

/// A prepared texture. Implementations are immutable and safe to share
/// between threads.
class Texture {
 public:
  virtual ~Texture() = default;
  /// Length of the textured span (mm); positions beyond it are at rest.
  [[nodiscard]] virtual Millimetres length() const = 0;
  /// Amplitudes at grid positions first, first+1, ... (grid positions are in
  /// the texture's own coordinates). Same values whatever the window. Writes
  /// every element of `out` (0 at rest). Safe to call from several threads
  /// at once.
  virtual void render(const Grid& grid, std::int64_t first, std::span<double> out) const = 0;
  /// Short human-readable description, e.g. "texel P=10 dB I=-5 dB L=0.25 mm".
  [[nodiscard]] virtual std::string describe() const = 0;
  /// The amplitude at one position `x` (the texture's own coordinates):
  /// exactly the value render() gives a grid sample that sits at `x`.
  [[nodiscard]] double sample(Millimetres x) const;
};

/// What a texture is prepared for, the same for every kind of texture: the
/// grid it will be sampled on (in the texture's own coordinates, 0 mm at its
/// left edge; origin and spacing matter, not the count) and the top of the
/// renderable band (0 = the grid's Nyquist frequency). Texel textures bound
/// their pitch distribution by `band_top` when their spec leaves band_max at
/// 0; references are defined up to the grid's Nyquist frequency
/// (docs/references.md) and take their amplitude scale from the grid's samples.
struct Sampling {
  Grid grid;
  CyclesPerMm band_top{0.0};
  /// band_top, or the grid's Nyquist frequency when it is 0.
  [[nodiscard]] CyclesPerMm top() const { return band_top.value() > 0.0 ? band_top : grid.nyquist(); }
};

enum class PhaseMode { continuous, reset };
enum class Fill { whole_texels, partial_final_texel };

std::string_view to_string(PhaseMode m);
std::string_view to_string(Fill f);
PhaseMode parse_phase_mode(std::string_view text, std::string_view field = "phase");
Fill parse_fill(std::string_view text, std::string_view field = "fill");

/// Everything that defines a Texel texture. Defaults are the studies' values.
struct TexelSpec {
  Decibels central_pitch{10.0};    ///< dB re 1 cpm
  Decibels irregularity{-5.0};     ///< dB (see Parameterization)
  Millimetres texel_length{0.25};  ///< mm, > 0; keep below ~1 mm for fine texture
  std::uint64_t seed = 1;          ///< the random draw
  Parameterization parameterization = Parameterization::moments;
  OutOfBand out_of_band = OutOfBand::redraw;
  CyclesPerMm band_min{0.01};    ///< cpm; the source's hardware floor
  CyclesPerMm band_max{0.0};     ///< cpm; 0 = the rendering grid's Nyquist frequency
  double quantization_db = 0.0;  ///< 0 = off, else > 0 dB
  PhaseMode phase = PhaseMode::continuous;
  Fill fill = Fill::whole_texels;
  double coarse_strength = 0.0;  ///< C in [0, 1]
  double fine_strength = 1.0;    ///< F in [0, 1]
  CoarseProfile coarse = ConstantProfile{};
};

/// Texel lengths a document may give (mm; validate() needs > 0 and at most
/// the maximum). The studio's hello sends them.
inline constexpr double texel_length_mm_min = 1e-6;
inline constexpr double texel_length_mm_max = 1000.0;

inline constexpr OptionChoice phase_modes[] = {{"continuous", static_cast<int>(PhaseMode::continuous)},
                                               {"reset", static_cast<int>(PhaseMode::reset)}};
inline constexpr OptionChoice fills[] = {{"whole", static_cast<int>(Fill::whole_texels)},
                                         {"partial", static_cast<int>(Fill::partial_final_texel)}};

/// The fine texture's options as every front door offers them (`texel
/// render`/`swipe`/`play` flags, Python's render()/document() keywords, C's
/// texel_params), described once (texel/option_spec.hpp); the defaults are
/// TexelSpec{}'s, the studies'. The coarse profile is a value of its own
/// kind (constant, sinusoid, points, …), not a scalar option: each front
/// door builds it its own way (docs/format.md).
template <class Spec, class Visit>
requires std::is_same_v<std::remove_const_t<Spec>, TexelSpec>
void visit_options(Spec& s, Visit&& visit) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  visit(s.central_pitch, OptionSpec{"central_pitch_db", "central-pitch", "Central Pitch, dB re 1 cycle/mm (10 = 10 cpm)"});
  visit(s.irregularity, OptionSpec{"irregularity_db", "irregularity", "Irregularity, dB re 1 cycle/mm"});
  visit(s.texel_length, OptionSpec{"texel_length_mm", "texel-length", "Texel length, mm", 0, texel_length_mm_max, true});
  visit(s.seed, OptionSpec{"seed", "seed", "Random seed, 0 … 2^64-1", 0});
  visit(s.quantization_db,
        OptionSpec{"quantization_db", "quantization", "Frequency quantization step, dB (0 = off)", 0, quantization_db_max});
  visit(s.phase, OptionSpec{"phase", "phase", "Texel phase: continuous | reset", -inf, inf, false, false, phase_modes});
  visit(s.parameterization,
        OptionSpec{"parameterization", "parameterization", "moments (mean/SD in cpm) | log (median, SD of 10·log10 f)", -inf, inf,
                   false, false, parameterizations});
  visit(s.out_of_band, OptionSpec{"out_of_band", "out-of-band", "redraw | clamp draws outside the band", -inf, inf, false, false,
                                  out_of_band_rules});
  visit(s.fill, OptionSpec{"fill", "fill", "whole (whole texels only) | partial (render a final partial texel)", -inf, inf, false,
                           false, fills});
  visit(s.band_min, OptionSpec{"band_min_cpm", "band-min", "Lowest texel frequency, cpm", band_cpm_min, band_cpm_max});
  visit(s.band_max,
        OptionSpec{"band_max_cpm", "band-max", "Highest texel frequency, cpm (0 = the grid's Nyquist)", 0, band_cpm_max});
  visit(s.coarse_strength, OptionSpec{"coarse_strength", "coarse-strength", "Coarse strength C, 0 … 1", 0, 1});
  visit(s.fine_strength, OptionSpec{"fine_strength", "fine-strength", "Fine strength F, 0 … 1", 0, 1});
}

/// Validates every field; throws InvalidArgument naming field, value and range.
void validate(const TexelSpec& spec);

/// The pitch distribution's configuration of `spec` on a band topped at
/// `band_top` when spec.band_max is 0 (TexelTexture's, and the 2-D fields').
PitchDistributionConfig distribution_config(const TexelSpec& spec, CyclesPerMm band_top);

/// The coarse/fine mixing rule (docs/algorithm.md §7), the one definition
/// the 1-D texels and the 2-D fields (texel/surface2d.hpp) share: with the
/// coarse profile reading c, coarse strength C and fine strength F, the
/// envelope is e = 1 − C·(1 − c) and the amplitude a = offset + gain·s for a
/// fine oscillation s in [−1, 1].
struct TexelMix {
  double envelope = 1.0;  ///< e
  double offset = 0.5;    ///< e − e·F/2
  double gain = 0.5;      ///< e·F/2
};
constexpr TexelMix texel_mix(double c, double coarse_strength, double fine_strength) {
  const double e = 1.0 - coarse_strength * (1.0 - c);
  return {e, e - e * fine_strength * 0.5, e * fine_strength * 0.5};
}

/// One texel of a prepared texture.
struct Texel {
  Millimetres start;      ///< left edge, k·L
  CyclesPerMm frequency;  ///< f_k after truncation and quantization
  double phase_cycles;    ///< oscillation phase at `start`, in cycles [0, 1)
  double envelope;        ///< e_k = 1 − C·(1 − c_k)
};

namespace detail {
struct TexelListOnce;
}  // namespace detail

class TexelTexture final : public Texture {
 public:
  /// Prepares `spec` over [0, length) for `sampling` (its band top bounds the
  /// pitch distribution when spec.band_max is 0). Validates; throws
  /// InvalidArgument. Allocates.
  /// `keep`: texels kept whole up to this count (kept_texels; a longer
  /// texture is checkpointed, see below). It moves memory, never a bit.
  TexelTexture(const TexelSpec& spec, Millimetres length, const Sampling& sampling, std::size_t keep = kept_texels);

  [[nodiscard]] Millimetres length() const override { return length_; }
  void render(const Grid& grid, std::int64_t first, std::span<double> out) const override;
  [[nodiscard]] std::string describe() const override;

  [[nodiscard]] const TexelSpec& spec() const { return spec_; }
  /// Every texel. A texture of more than kept_texels texels keeps only
  /// checkpoints, so the first call draws them all (and keeps them): prefer
  /// texel_count() and for_each_texels() there.
  [[nodiscard]] const std::vector<Texel>& texels() const;
  /// The number of texels.
  [[nodiscard]] std::size_t texel_count() const { return count_; }
  /// Calls fn(first index, std::span<const Texel>) on every texel in
  /// ascending runs, in bounded memory whatever the count.
  void for_each_texels(const std::function<void(std::size_t, std::span<const Texel>)>& fn) const;
  [[nodiscard]] const PitchDistribution& distribution() const { return distribution_; }
  /// End of the textured span: texel count · L, or the length with a partial final texel.
  [[nodiscard]] Millimetres textured_end() const { return Millimetres(end_mm_); }

  /// Index of the texel containing position x, or -1 if none.
  [[nodiscard]] std::int64_t texel_at(Millimetres x) const;
  /// Slow, obviously-correct single-sample evaluation (tests); sample(x) is
  /// the renderer's own value.
  [[nodiscard]] double amplitude_at(Millimetres x) const;

  /// Positions within this distance below a texel boundary count as on it, so
  /// that k·L computed in floating point lands in texel k (1 picometre).
  static constexpr double boundary_tolerance_mm = 1e-9;

  /// Up to this many texels are kept whole (48 bytes each); a longer
  /// texture keeps the phase every checkpoint_stride texels and draws the
  /// texels a window needs as it renders (the same values, bit for bit), so
  /// its memory is bounded whatever its length.
  static constexpr std::size_t kept_texels = std::size_t{1} << 17;
  static constexpr std::size_t checkpoint_stride = 1024;

 private:
  /// Texels and their envelope terms for indices [first, first + count).
  struct TexelRun {
    std::uint64_t owner = 0;  // the texture (id_) whose texels these are
    std::size_t first = 0;
    std::vector<Texel> texels;
    std::vector<double> offset;  // e_k·(1 − F/2)
    std::vector<double> gain;    // e_k·F/2
    std::vector<double> coarse;  // work: c_k of the run
  };

  struct BlockCache;

  /// Draws texels [first, first + count) into `run`, starting from `phase`
  /// (the continuous phase entering texel `first`); returns the phase
  /// entering texel first + count.
  double draw(std::size_t first, std::size_t count, double phase, TexelRun& run) const;
  /// That phase alone: draw's frequencies and recurrence, keeping nothing.
  double advance(std::size_t first, std::size_t count, double phase) const;
  /// The run of checkpoint block `block` (lazy mode).
  void draw_block(std::size_t block, TexelRun& run) const;
  /// Texel k's run: the kept one, or this thread's block of a checkpointed
  /// texture (kept from one window to the next, and shared with the other
  /// threads through blocks_: no redrawing and no allocation per window).
  /// Valid until the thread asks for another block.
  const TexelRun& run_of(std::size_t k) const;

  TexelSpec spec_;
  Millimetres length_;
  PitchDistribution distribution_;
  std::size_t count_ = 0;
  TexelRun kept_;                               // every texel (count_ <= kept_texels)
  std::vector<double> checkpoint_phase_;        // else: the phase entering texel c·checkpoint_stride
  std::shared_ptr<detail::TexelListOnce> all_;  // texels() of a checkpointed texture, drawn once
  std::shared_ptr<BlockCache> blocks_;          // its recently drawn blocks, shared by threads
  double end_mm_ = 0.0;
  std::uint64_t id_ = 0;  // unique per prepared texture (copies share it: same texels)
};

/// Number of texels a span of `length` holds under `fill`.
std::size_t texel_count(Millimetres length, Millimetres texel_length, Fill fill);

/// The one way to prepare a texture of any kind (ReferenceSpec's overload is
/// in texel/reference.hpp): `spec` over [0, length) for `sampling`.
std::shared_ptr<const Texture> prepare(const TexelSpec& spec, Millimetres length, const Sampling& sampling);

}  // namespace texel
