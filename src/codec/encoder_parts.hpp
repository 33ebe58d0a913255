// What the encoder's stages share (src/codec/, one file per section of
// docs/encoder.md): spectra.cpp (analysis spectra), split.cpp (§1 the
// coarse/fine split), model.cpp (§2 the perceptual model), fit.cpp (§3 the
// analysis-by-synthesis fit), recovery.cpp (§4 parameter recovery of Texel
// renderings), coarse_fields.cpp (the coarse section of the bitstream) and
// encode.cpp (the pipeline). Internal to the codec component.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "texel/codec.hpp"

namespace texel::codec::parts {

constexpr double ten_over_ln10 = 4.34294481903251827651;
inline double db_of(double cpm) { return ten_over_ln10 * std::log(cpm); }
inline double cpm_of(double db) { return std::pow(10.0, db / 10.0); }
/// Texel lengths (mm) the encoder tries besides --texel-length when it asks
/// whether the input was drawn by the renderer (§1 step 0, §4).
constexpr std::array<double, 3> candidate_texel_lengths_mm{0.25, 0.5, 1.0};

// --- spectra.cpp ---------------------------------------------------------------

/// One-sided power spectrum (arbitrary scale) of a zero-mean signal: a Hann
/// periodogram zero-padded to a power of two, or Welch's average of
/// half-overlapping 2^15-sample segments for long signals. Bin i is at
/// i/(M·spacing) cpm; returns M through `m_out`.
std::vector<double> power_spectrum(std::span<const double> x, std::size_t& m_out);
/// The same into `p` (reused storage: an encode analyses dozens of signals).
void power_spectrum(std::span<const double> x, std::vector<double>& p, std::size_t& m_out);
/// x minus its mean.
std::vector<double> centred(std::span<const double> x);
/// x minus its mean, in place.
void centre(std::vector<double>& x);
/// centre(x) and centre(y), the two sums in one pass.
void centre(std::vector<double>& x, std::vector<double>& y);
/// How differently two signals of the same length distribute their power
/// over half-octave bands (dB; docs/encoder.md §1 step 4).
double shape_distance_db(const std::vector<double>& x, const std::vector<double>& y, double dx);
/// The log-spectral centroid of a whole signal (its mean removed), dB re
/// 1 cpm: Percept::log_centroid_db's band and weighting at swipe speed v.
/// `below`, if given, receives the share of the whole spectrum's power under f_split (cpm).
/// The band ends at `top_cpm` if lower (version 3: the felt band's top).
double log_centroid_db(std::span<const double> x, double dx, double v, double f_split = 0.0, double* below = nullptr,
                       double top_cpm = std::numeric_limits<double>::infinity());
/// Share (0 … 1) of the power of x (its mean removed) above f_cpm.
double power_share_above(std::span<const double> x, double dx, double f_cpm);
/// x without its content above the felt band (version 3's analysis signal,
/// docs/encoder.md §2 "Version 3"): zero-phase, gain 1 up to top_cpm and a
/// raised cosine to 0 at 1.2 × top_cpm, the mean kept.
void lowpass_felt(std::vector<double>& x, double dx, double top_cpm);
/// The top of the log-spectral centroid's band for `model`, cpm: the felt
/// band's top under version 3, else none (infinite).
inline double centroid_top_cpm(const PerceptualModel& model) {
  return model.version == 3 ? felt_band_top_cpm(model).value() : std::numeric_limits<double>::infinity();
}

// --- split.cpp -------------------------------------------------------------------

struct Split {
  std::vector<double> fine;  // zero-mean fine signal (envelope divided out)
  double range = 0.0;        // relative envelope range (p98 − p2) / p98 at texel centres (automatic splits)
  std::size_t window = 0;    // running-extreme window, samples
  bool coarse = false;
  double C = 0.0;
  double F = 1.0;
  std::vector<double> c;  // per-texel coarse profile (coarse only)
};

/// automatic: §1 decides; fine_only / two_scale: forced; coarse_only: the
/// input has no fine texture (F = 0), its envelope is the signal itself.
enum class SplitMode { automatic, fine_only, two_scale, coarse_only };

/// §1 steps 1–3 and 5: the envelope, flat or not, the profile and strengths.
/// `window` > 0 fixes the running-extreme window (samples) instead of
/// deriving it from the spectrum: candidates are analysed exactly like the input.
Split split(const std::vector<double>& a, double dx, const EncoderConfig& cfg, SplitMode mode = SplitMode::automatic,
            std::size_t window = 0);
/// The same into `out`, reusing its signal-sized buffer (the fit splits
/// every two-scale candidate).
void split(const std::vector<double>& a, double dx, const EncoderConfig& cfg, SplitMode mode, std::size_t window, Split& out);

/// §1 step 0: the longest of `lengths` (mm) over whose texels the input is
/// constant (a coarse profile without fine texture, as the renderer draws it
/// with F = 0), if any.
std::optional<double> stepped_texel_length(const std::vector<double>& a, double dx, std::span<const double> lengths);

double percentile(std::vector<double> v, double q);
double correlation(const std::vector<double>& a, const std::vector<double>& b);

// --- fit.cpp ---------------------------------------------------------------------

/// The fine-only TexelSpec of a candidate under the encoder's settings.
TexelSpec fine_spec(double p_db, double i_db, const EncoderConfig& cfg, CyclesPerMm band_max, std::uint64_t seed);
/// A fine-only Texel texture of the encoder's settings.
TexelTexture fine_texture(double p_db, double i_db, const EncoderConfig& cfg, CyclesPerMm band_max, Millimetres length,
                          std::uint64_t seed = 0x5EED0001);

/// The fit's residuals (Fitter::residuals).
using Residuals = std::array<double, 6>;

/// The objective: model distance between the target percept and candidate
/// renderings of (P, I) on the input's grid, analysed like the input.
struct Fitter {
  Fitter(const EncoderConfig& config, const Percept& target_percept, double spacing_mm, std::size_t candidate_samples,
         CyclesPerMm band_top, double band_bottom = 0.0, const Split* coarse_estimate = nullptr)
      : cfg(config),
        target(target_percept),
        dx(spacing_mm),
        samples(candidate_samples),
        band_max(band_top),
        f_min(band_bottom),
        two_scale(coarse_estimate) {}

  const EncoderConfig& cfg;
  const Percept& target;
  double dx;
  std::size_t samples;
  CyclesPerMm band_max;
  double f_min = 0.0;                // analysis band bottom (the boundary, for the fine part of a two-scale texture)
  const Split* two_scale = nullptr;  // the input's coarse estimate: candidates carry it and are split alike
  int evaluations = 0;

  struct Evaluated {
    double p_db, i_db;
    int draws;
    std::optional<Percept> percept;
  };
  std::vector<Evaluated> memo;  // every point evaluated (a fit evaluates a few dozen)
  struct Drawn {
    double p_db, i_db;
    std::uint64_t seed;
    Percept percept;
  };
  std::vector<Drawn> drawn;  // every candidate rendered: the grid's one-draw points are not drawn again with two
  int draws = 2;             // candidate draws per evaluation (1 or 2)

  /// Candidate (P, I) drawn with `seed`, rendered on the input's grid into `a`.
  void render(double p_db, double i_db, std::uint64_t seed, std::vector<double>& a) const;
  /// The percept of that candidate, analysed like the input.
  [[nodiscard]] Percept render_percept(double p_db, double i_db, std::uint64_t seed) const;
  /// render_percept of two draws of a fine-only candidate (the same
  /// percepts, their means taken in one pass).
  [[nodiscard]] std::array<Percept, 2> render_percepts(double p_db, double i_db, std::array<std::uint64_t, 2> seeds) const;
  std::optional<Percept> evaluate(double p_db, double i_db);
  /// Mean percept over `draws` candidate draws (common random numbers); none if
  /// (P, I) cannot be rendered. Counts one evaluation unless (P, I) was
  /// evaluated before.
  std::optional<Percept> percept(double p_db, double i_db);
  /// The fit's objective, fit_distance to the target (1e6 if not renderable).
  double operator()(double p_db, double i_db);
  /// The felt distance to the target, distance() (1e6 if not renderable).
  double felt(double p_db, double i_db);
  /// The objective's terms (pitch and noisiness in JND, the tie-break terms
  /// weighted, the drawn texture's pitch and noisiness weighted): their norm
  /// is operator()'s value.
  std::optional<Residuals> residuals(double p_db, double i_db);
};

struct Box {
  double p_lo, p_hi, i_lo, i_hi;
  [[nodiscard]] bool inside(double p, double i) const { return p >= p_lo && p <= p_hi && i >= i_lo && i <= i_hi; }
};
Box fit_box(const EncoderConfig& cfg, CyclesPerMm band_max);

struct FineFit {
  double p_db = 10.0, i_db = -5.0, distance = 0.0;
  Percept input;
  bool identifiable = true;
  double bound_db = 0.0;
  int evaluations = 0;
};

/// §3 step 4: does a much narrower distribution feel different?
void identifiability(Fitter& fit, const Box& box, FineFit& out);
/// How far fit_fine goes.
struct FitOptions {
  bool identifiability = true;  // §3 step 4 (else P and I only)
  int iterations = 8;           // least-squares iterations at most
  /// Start here instead of the grid around the spectrum's moments (a
  /// refinement of an earlier, shorter fit).
  std::optional<std::array<double, 2>> start;
};
/// §3: the fine texture whose percept is closest to that of `fine`.
FineFit fit_fine(const std::vector<double>& fine, double dx, std::size_t cand, CyclesPerMm band_max, const EncoderConfig& cfg,
                 double f_min = 0.0, const Split* two_scale = nullptr, const FitOptions& options = {});

// --- recovery.cpp ----------------------------------------------------------------

/// Recovered parameters of an input that is itself a fine-only Texel
/// rendering (docs/encoder.md §4), if it is one.
struct TexelRecovery {
  double L = 0.0, p_db = 0.0, i_db = 0.0, rms = 0.0;
  std::size_t texels = 0;
};
std::optional<TexelRecovery> recover_texel(const std::vector<double>& a, double dx, const EncoderConfig& cfg,
                                           CyclesPerMm band_max);

// --- coarse_fields.cpp ------------------------------------------------------------

/// The coarse section for profile c at `bits` per level, every `stride`-th texel.
CoarseFields coarse_fields(const std::vector<double>& c, double C, double F, unsigned bits, std::uint32_t stride,
                           std::uint8_t predictor);
/// RMS difference between c and the profile the fields decode to.
double coarse_error(const std::vector<double>& c, const CoarseFields& f);
/// The per-texel profile the fields decode to.
std::vector<double> decoded_profile(const CoarseFields& f, std::size_t count);

}  // namespace texel::codec::parts
