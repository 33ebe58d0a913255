#include "texel/texture.hpp"

#include <algorithm>
#include <cmath>

#include "texel/detail/format.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"
#include "texel/random.hpp"

namespace texel {
namespace {

using detail::num;

void check_fraction(double v, std::string_view field) {
  if (!(v >= 0.0 && v <= 1.0)) throw InvalidArgument(std::string(field) + " is " + num(v) + "; allowed: 0 … 1");
}

// The fused fine-texture kernel for one texel's run of samples:
//   x = origin + i·Δx, u = φ_k + f_k·(x − start_k), a = offset_k + gain_k·sin(2πu).
// `base` is the global index of out[0] as a double; base + m is exact for any
// index below 2^53, so x is bit-identical to Grid::position(i) — which is what
// makes every window, SIMD width and -O level produce the same bytes.
void render_run(double base, double origin, double spacing, const Texel& t, double offset, double gain, double* out,
                std::int32_t count) {
  const double start = t.start_mm;
  const double f = t.frequency_cpm;
  const double phase = t.phase_cycles;
  for (std::int32_t m = 0; m < count; ++m) {
    const double x = origin + (base + static_cast<double>(m)) * spacing;
    const double u = phase + f * (x - start);
    out[m] = offset + gain * detmath::sin_cycles(u);
  }
}

}  // namespace

std::string_view to_string(PhaseMode m) { return m == PhaseMode::continuous ? "continuous" : "reset"; }
std::string_view to_string(Fill f) { return f == Fill::whole_texels ? "whole" : "partial"; }

PhaseMode parse_phase_mode(std::string_view text, std::string_view field) {
  if (text == "continuous") return PhaseMode::continuous;
  if (text == "reset") return PhaseMode::reset;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: continuous, reset");
}

Fill parse_fill(std::string_view text, std::string_view field) {
  if (text == "whole") return Fill::whole_texels;
  if (text == "partial") return Fill::partial_final_texel;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: whole, partial");
}

void validate(const TexelSpec& spec) {
  const double L = spec.texel_length.value();
  if (!(std::isfinite(L) && L > 0.0))
    throw InvalidArgument("texel_length_mm is " + num(L) + " mm; it must be a finite number > 0");
  if (L > 1000.0) throw InvalidArgument("texel_length_mm is " + num(L) + " mm; allowed: up to 1000 mm");
  check_fraction(spec.coarse_strength, "coarse_strength");
  check_fraction(spec.fine_strength, "fine_strength");
  if (!std::isfinite(spec.band_max.value()) || spec.band_max.value() < 0.0)
    throw InvalidArgument("band_max_cpm is " + num(spec.band_max.value()) + " cpm; allowed: 0 (the grid's Nyquist) or > band_min_cpm");
  validate(spec.coarse);
}

std::size_t texel_count(Millimetres length, Millimetres texel_length, Fill fill) {
  const double ratio = length.value() / texel_length.value();
  if (!(ratio >= 0.0)) return 0;
  if (ratio > 1e12) throw InvalidArgument("texture length / texel length is " + num(ratio) + "; at most 1e12 texels");
  // The boundary tolerance keeps 0.3 / 0.1 = 2.9999999999999996 at 3 texels.
  const double tol = TexelTexture::boundary_tolerance_mm / texel_length.value();
  const double n = fill == Fill::whole_texels ? std::floor(ratio + tol) : std::ceil(ratio - tol);
  return static_cast<std::size_t>(std::max(n, 0.0));
}

TexelTexture::TexelTexture(const TexelSpec& spec, Millimetres length, CyclesPerMm nyquist)
    : spec_(spec),
      length_(length),
      distribution_([&] {
        validate(spec);
        if (!(std::isfinite(length.value()) && length.value() > 0.0))
          throw InvalidArgument("texture length is " + num(length.value()) + " mm; it must be a finite number > 0");
        PitchDistributionConfig c;
        c.central_pitch = spec.central_pitch;
        c.irregularity = spec.irregularity;
        c.parameterization = spec.parameterization;
        c.out_of_band = spec.out_of_band;
        c.band_min = spec.band_min;
        c.band_max = spec.band_max.value() > 0.0 ? spec.band_max : nyquist;
        c.quantization_db = spec.quantization_db;
        return PitchDistribution(c);
      }()) {
  const double L = spec.texel_length.value();
  const std::size_t n = texel_count(length, spec.texel_length, spec.fill);
  end_mm_ = spec.fill == Fill::whole_texels ? static_cast<double>(n) * L : length.value();
  const std::vector<double> coarse = sample_at_texel_centres(spec.coarse, spec.texel_length, n);

  texels_.resize(n);
  offset_.resize(n);
  gain_.resize(n);
  const CounterRng phase_rng(spec.seed, Stream::phase);
  double phase = phase_rng.uniform(0);
  const double C = spec.coarse_strength;
  const double F = spec.fine_strength;
  for (std::size_t k = 0; k < n; ++k) {
    Texel& t = texels_[k];
    t.start_mm = static_cast<double>(k) * L;
    t.frequency_cpm = distribution_.draw(spec.seed, k);
    if (spec.phase == PhaseMode::reset) phase = phase_rng.uniform(k + 1);
    t.phase_cycles = phase;
    t.envelope = 1.0 - C * (1.0 - coarse[k]);
    offset_[k] = t.envelope - t.envelope * F * 0.5;
    gain_[k] = t.envelope * F * 0.5;
    // Continuous phase: the next texel starts where this one ends. Keep the
    // phase in [0, 1) cycles so precision does not decay along the surface.
    const double next = phase + t.frequency_cpm * L;
    phase = next - detmath::floor_exact(next);
  }
}

std::int64_t TexelTexture::texel_at(double x) const {
  const double shifted = x + boundary_tolerance_mm;
  if (!(shifted >= 0.0) || !(x < end_mm_ - boundary_tolerance_mm) || texels_.empty()) return -1;
  const double k = std::floor(shifted / spec_.texel_length.value());
  const auto n = static_cast<double>(texels_.size());
  if (k >= n) return -1;
  return static_cast<std::int64_t>(k);
}

double TexelTexture::amplitude_at(double x) const {
  const std::int64_t k = texel_at(x);
  if (k < 0) return 0.0;
  const auto i = static_cast<std::size_t>(k);
  const Texel& t = texels_[i];
  const double u = t.phase_cycles + t.frequency_cpm * (x - t.start_mm);
  return offset_[i] + gain_[i] * detmath::sin_cycles(u);
}

void TexelTexture::render(const Grid& grid, std::int64_t first, std::span<double> out) const {
  const auto n = static_cast<std::int64_t>(out.size());
  const double L = spec_.texel_length.value();
  auto pos = [&](std::int64_t j) { return grid.position(first + j); };
  std::int64_t j = 0;
  while (j < n) {
    const std::int64_t k = texel_at(pos(j));
    if (k < 0) {
      out[static_cast<std::size_t>(j)] = 0.0;
      ++j;
      continue;
    }
    // The run of samples in texel k ends at the first sample whose texel
    // differs. Estimate it from the boundary, then settle it with texel_at
    // itself so the rule is the one amplitude_at uses.
    const double boundary = std::min(static_cast<double>(k + 1) * L, end_mm_) - boundary_tolerance_mm;
    const double estimate = std::ceil((boundary - grid.origin_mm) / grid.spacing_mm) - static_cast<double>(first);
    std::int64_t end = estimate >= static_cast<double>(n) ? n : std::max(j + 1, static_cast<std::int64_t>(estimate));
    while (end > j + 1 && texel_at(pos(end - 1)) != k) --end;
    while (end < n && texel_at(pos(end)) == k) ++end;
    // Long runs go in pieces so the kernel's index stays a 32-bit int (the
    // int32 -> double conversion vectorizes everywhere; int64 does not).
    const auto ik = static_cast<std::size_t>(k);
    for (std::int64_t a = j; a < end;) {
      const std::int64_t len = std::min<std::int64_t>(end - a, 1 << 30);
      render_run(static_cast<double>(first + a), grid.origin_mm, grid.spacing_mm, texels_[ik], offset_[ik], gain_[ik],
                 out.data() + a, static_cast<std::int32_t>(len));
      a += len;
    }
    j = end;
  }
}

std::string TexelTexture::describe() const {
  return "texel P=" + num(spec_.central_pitch.value()) + " dB I=" + num(spec_.irregularity.value()) +
         " dB L=" + num(spec_.texel_length.value()) + " mm seed=" + std::to_string(spec_.seed) + " (" +
         std::string(to_string(spec_.parameterization)) + ")";
}

}  // namespace texel
