// Reference textures (docs/references.md): every texture the Texel
// method was validated against, generated on the same device grid and
// amplitude scale as Texel renderings, deterministic from a seed.
//
// Families (a registry of named generators, `reference_catalogue()`):
//  - Friesen band-pass noise: `bandpass` and the nine named f_c × ζ pairs of
//    the first study (`bandpass-f1-z0.05` … `bandpass-f20-z5`);
//  - sums of sinusoids `2sin`, `3sin`, `4sin`;
//  - colours of noise `white`, `pink`, `blue`;
//  - band-limited waveforms `square`, `tri`, `saw`;
//  - patch textures `patch-2.5`, `patch-4.6`, `patch-13.5` (and shuffles);
//  - the mirrored coarse pulse pair `pulse-a`, `pulse-b`.
// Every parameter is adjustable (ReferenceSpec::params); the spec's values
// are the defaults.
//
// Method and trade-off. Every signal-defined reference (noise, sinusoids,
// waveforms) is a finite sum of sinusoids
//     y(x) = Σ_k a_k · sin(2π(f_k·x + φ_k))
// mapped to amplitude by a = 0.5 + 0.5·y / max|y| (docs/references.md §1 [choice];
// max over the prepared grid's samples). Noise is Gaussian noise specified in
// the frequency domain: components sit at the harmonics k/P of the texture's
// length P (the bins of a DFT over the whole texture), with Rayleigh
// magnitudes × the target |H(f)| and uniform phases drawn from
// CounterRng(seed, Stream::reference) at counters 2k (magnitude) and 2k+1
// (phase). That is exactly what "white noise filtered in the frequency
// domain" produces, and it is free of aliasing (no component at or above the
// grid's Nyquist frequency is ever synthesised).
//
// How the sum is evaluated on the prepared grid is the `ReferenceSynthesis`
// of the spec, fixed by the document's format version so that a document
// renders the same bytes forever (docs/format.md):
//  - `chirp_z` (version 3, the default): noise and waveforms, whose
//    components are harmonics of one fundamental, go through Bluestein's
//    chirp-z transform on Texel's own deterministic FFT (detfft), in
//    O((samples + harmonics)·log) time and bounded memory (ReferenceMemory:
//    FFTs and prepared samples beyond it go to a scratch file, with the same
//    bits; SIMD lanes and two worker threads, neither of which changes a
//    bit): 4 m of full-band white noise at 5 µm in about 0.07 s.
//    Sums of sinusoids (at most 256 arbitrary frequencies) stay direct.
//  - `direct` (version 2): every component summed at every sample with
//    detmath::sin_cycles, O(samples × components): about 2 s for 400 mm of
//    white noise at 5 µm on one core (half that on two), minutes for 4 m.
// Both are bit-identical on every build and agree to about 1e-12 (the
// chirp-z one is within 1e-15 of a long-double sum, the direct one ~2e-12).
// Positions off the prepared grid (another grid, sample(x) between samples)
// are always summed directly: a pure function of x, whatever the window.
//
// Patch and pulse textures are defined directly in amplitude (patches a = 1,
// gaps a = 0; pulses 0.5 − 0.5·cos over one 5 mm period) and are not rescaled.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "texel/coarse.hpp"
#include "texel/grid.hpp"
#include "texel/texture.hpp"
#include "texel/units.hpp"

namespace texel {

namespace detail {
class ScratchFile;
struct NoiseBand;
}  // namespace detail

/// A parameter value: a number, a list of numbers, or a word from a choice.
using ReferenceValue = std::variant<double, std::vector<double>, std::string>;

enum class ReferenceParamKind {
  number,   ///< a finite number in [min, max]
  integer,  ///< a whole number in [min, max]
  list,     ///< min_count … max_count numbers, each in [min, max]
  choice,   ///< one of `choices`
};

/// One adjustable parameter of a generator: what `texel reference --list` prints.
struct ReferenceParam {
  std::string key;  ///< e.g. "frequencies_cpm" (units in the key, as in documents)
  ReferenceParamKind kind = ReferenceParamKind::number;
  std::string unit;  ///< "cpm", "mm", "deg" or "" (dimensionless)
  ReferenceValue default_value;
  double min = 0.0;  ///< number / integer / each list element
  double max = 0.0;
  std::size_t min_count = 0;         ///< list only
  std::size_t max_count = 0;         ///< list only
  std::vector<std::string> choices;  ///< choice only
  std::string description;
};

/// A named generator with its parameters and their defaults.
struct ReferenceInfo {
  std::string name;         ///< e.g. "4sin"
  std::string family;       ///< "band-pass noise", "sum of sinusoids", ...
  std::string description;  ///< one line
  bool uses_seed = false;   ///< false: the seed changes nothing
  std::vector<ReferenceParam> params;
};

/// How a signal-defined reference is summed on its prepared grid (see the
/// banner). The bytes differ in the last bits, so a document's format version
/// picks it: version 2 documents `direct`, version 3 `chirp_z`.
enum class ReferenceSynthesis {
  direct,   ///< version 2: every component at every sample, O(samples × components)
  chirp_z,  ///< version 3: harmonic series by chirp-z transform, O((samples + harmonics)·log)
};

/// Everything that defines a reference texture: generator, overrides, seed,
/// and the synthesis whose bytes it renders.
struct ReferenceSpec {
  std::string name = "4sin";
  /// Overrides of the generator's defaults, by key. Absent keys take defaults.
  std::map<std::string, ReferenceValue> params;
  std::uint64_t seed = 1;
  /// New references take the current synthesis; documents read as version 2
  /// keep `direct` (parse_document sets it from the version).
  ReferenceSynthesis synthesis = ReferenceSynthesis::chirp_z;
};

/// Every named generator, in listing order (families together).
const std::vector<ReferenceInfo>& reference_catalogue();
/// The generator called `name`; throws InvalidArgument listing the names.
const ReferenceInfo& reference_info(std::string_view name);
/// The nine references of the second study, three families in three rows:
/// 2sin 3sin 4sin / white pink blue / square tri saw.
std::vector<std::string> second_study_names();

/// Validates name, keys, kinds, ranges and cross-parameter rules; throws
/// InvalidArgument naming the parameter, the value and what is allowed.
void validate(const ReferenceSpec& spec);
/// Parses a value written on a command line ("2.5,6,8.5", "random", "4")
/// for `key` of generator `info`; throws InvalidArgument.
ReferenceValue parse_reference_value(const ReferenceInfo& info, std::string_view key, std::string_view text);
/// Applies "KEY=VALUE" (the CLI's --param) to `spec`; throws InvalidArgument.
void set_reference_param(ReferenceSpec& spec, std::string_view assignment);
/// The value in force for `key` (override or default).
ReferenceValue reference_value(const ReferenceSpec& spec, std::string_view key);
/// A value written back as text ("2.5,6", "zero", "4").
std::string format_reference_value(const ReferenceValue& value);

/// One sinusoidal component of a signal-defined reference (before scaling).
struct ReferenceComponent {
  CyclesPerMm frequency;  ///< > 0, below the grid's Nyquist frequency
  double amplitude;       ///< >= 0
  double phase_cycles;    ///< in [0, 1)
};

/// One interval of an amplitude-defined reference (a patch or a pulse).
struct ReferenceFeature {
  Millimetres start;
  Millimetres length;
};

/// How much memory preparing a reference may use. Where the data lives
/// never changes a bit of the result; these bound the process's memory
/// whatever the texture's length (docs/algorithm.md "Reference textures").
struct ReferenceMemory {
  /// Chirp-z FFTs of up to this many points run in memory (48 bytes per
  /// point); larger ones run out of core on a scratch file in $TMPDIR (32
  /// bytes per point on disk, about 32 bytes × fft_points in memory). A
  /// power of two >= 4.
  std::size_t fft_points = std::size_t{1} << 17;
  /// Up to this many prepared samples are kept in memory (8 bytes each);
  /// more go to a scratch file and are read back as they are rendered.
  std::size_t cached_samples = std::size_t{1} << 19;
  /// Worker threads of the synthesis, each with buffers of its own (an
  /// out-of-core FFT's worker about 24 bytes × fft_points): 0 = the
  /// TEXEL_THREADS environment variable, else the processors the process
  /// may run on, at most 2. Never changes a bit.
  int threads = 0;
};

/// A reference prepared for a grid: an immutable Texture.
class ReferenceTexture final : public Texture {
 public:
  /// Prepares `spec` over [0, length) for sampling on `grid` (positions in
  /// the texture's own coordinates; only origin and spacing matter): the
  /// grid's Nyquist frequency bounds the band, the samples inside [0, length)
  /// are synthesised once (spec.synthesis) and the amplitude scale is fixed
  /// from them. Rendering on another grid takes those samples where a
  /// position coincides with one and evaluates the same function of x
  /// directly elsewhere, with the same scale (values clamped to [0, 1]).
  /// `memory` bounds the memory used (not the bytes rendered).
  /// Validates; throws InvalidArgument (IoError if a scratch file is needed
  /// and cannot be written). Allocates.
  ReferenceTexture(const ReferenceSpec& spec, Millimetres length, const Sampling& sampling, const ReferenceMemory& memory = {});

  [[nodiscard]] Millimetres length() const override { return length_; }
  void render(const Grid& grid, std::int64_t first, std::span<double> out) const override;
  [[nodiscard]] std::string describe() const override;

  [[nodiscard]] const ReferenceSpec& spec() const { return spec_; }
  /// Sinusoidal components (signal-defined references), ascending in
  /// frequency; empty otherwise. A noise's components are drawn again on
  /// every call (K of them for a band holding K harmonics; not kept).
  [[nodiscard]] std::vector<ReferenceComponent> components() const;
  /// Patches or pulses (amplitude-defined references); empty otherwise.
  [[nodiscard]] const std::vector<ReferenceFeature>& features() const { return features_; }
  /// The gaps between consecutive features, in spatial order.
  [[nodiscard]] std::vector<Millimetres> gaps() const;
  /// max|y| over the prepared grid's samples (1 for amplitude-defined references).
  [[nodiscard]] double peak() const { return peak_; }
  /// True when the prepared samples live in a scratch file (more than
  /// ReferenceMemory::cached_samples of them).
  [[nodiscard]] bool samples_in_scratch_file() const { return scratch_ != nullptr; }
  /// Slow, obviously-correct single-sample evaluation (tests).
  [[nodiscard]] double amplitude_at(Millimetres x) const;

 private:
  enum class Shape { sum, patch, pulse };
  void evaluate(const Grid& grid, std::int64_t first, std::span<double> out) const;
  /// Prepared samples [i, i + out.size()) (indices from cache_first_), as
  /// amplitudes (a sum is kept as synthesised and mapped here).
  void read_samples(std::size_t i, std::span<double> out) const;

  ReferenceSpec spec_;
  Millimetres length_;
  Shape shape_ = Shape::sum;
  std::vector<ReferenceComponent> components_;      // sums of sinusoids and waveforms
  std::shared_ptr<const detail::NoiseBand> noise_;  // noise: drawn on demand instead
  std::vector<ReferenceFeature> features_;
  double peak_ = 1.0;
  double scale_ = 0.5;  // 0.5 / peak
  // Samples on the prepared grid (global indices cache_first_ …), reused when
  // the same grid renders again (the usual case: Surface::render): in
  // cache_, or in scratch_ when there are more than
  // ReferenceMemory::cached_samples.
  Grid grid_;
  std::int64_t cache_first_ = 0;
  std::size_t cache_count_ = 0;
  std::vector<double> cache_;
  std::shared_ptr<const detail::ScratchFile> scratch_;
};

/// The reference's amplitudes on samples [0, grid.count) of `grid` (origin
/// = the texture's left edge), over the grid's length.
std::vector<double> render_reference(const ReferenceSpec& spec, const Grid& grid);

/// A reference as a coarse profile (docs/references.md §7, coarse-feature study):
/// the reference prepared over `length` and sampled every `spacing`.
SampledProfile reference_profile(const ReferenceSpec& spec, Millimetres length, Millimetres spacing);

/// The one way to prepare a texture of any kind (see texel/texture.hpp).
std::shared_ptr<const Texture> prepare(const ReferenceSpec& spec, Millimetres length, const Sampling& sampling);

}  // namespace texel
