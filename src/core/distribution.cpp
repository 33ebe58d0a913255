#include "texel/distribution.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "texel/detail/format.hpp"
#include "texel/detail/lanes.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"

namespace texel {
namespace {

using detail::num;

constexpr double ln10_over_10 = 0.230258509299404568402;  // ln(10)/10
constexpr double ten_over_ln10 = 4.34294481903251827651;

double db_of(double cpm) { return ten_over_ln10 * detmath::log(cpm); }
double cpm_of(double db) { return detmath::exp(db * ln10_over_10); }

void require_finite(double v, std::string_view field, std::string_view unit) {
  if (!std::isfinite(v))
    throw InvalidArgument(std::string(field) + " is " + num(v) + " " + std::string(unit) + "; it must be a finite number");
}

// ------------------------------------------------------------ lane-wise draws
//
// The first attempt of W texels' draws at once, each lane doing exactly the
// scalar operations in the same order — the pattern and reasoning of the
// render kernel (texture.cpp, above render_lanes): the counter's bits
// (CounterRng::bits_generic, modular integer arithmetic), the uniform, the
// normal quantile (AS241's central branch and its first tail, through
// detmath's generic definitions, which the scalar functions share) and
// exp(mu + sigma·z), in IEEE double with -ffp-contract=off. Every lane
// computes both branches and a select keeps the one the scalar code takes.
// A lane the kernel cannot finish exactly is marked for
// PitchDistribution::draw, which starts again from attempt 0 and so returns
// the same bits: AS241's far tail (r > 5, p < 1.4e-11), an exponent k
// outside 2^k's normal range, or a frequency outside the band (a redraw, or
// a clamp). Some steps differ in form from the scalar code but not in
// value, being exact: the uniform's 53-bit integer converted to double in
// two 32-bit halves (each exact, their sum exact below 2^53); log's and
// exp's exponents moved between integers and doubles through 2^52's bits
// (exact below 2^51); ldexp as a multiplication by 2^k built from k's bits
// (detmath::scale_pow2); square roots, correctly rounded either way.
// tests/core/test_distribution.cpp compares runs with the scalar draw bit
// for bit.
struct DrawBatch {
  CounterRng rng;
  std::uint64_t first;  // index of out[0]
  double mu, sigma, lo, hi;
};

// A negative value marks a lane for the scalar draw (a frequency never is).

template <int W>
[[gnu::always_inline]] inline void draw_lanes(const DrawBatch& b, double* out, std::size_t count) {
  using V = typename detail::Lanes<W>::type;
  using U = typename detail::Lanes<W>::u64;
  constexpr std::uint64_t two52_bits = 0x4330000000000000ULL;  // 2^52: n | two52_bits is 2^52 + n for n < 2^52
  constexpr double two52 = 4503599627370496.0;
  U lane{};
  for (int l = 0; l < W; ++l) lane[l] = static_cast<std::uint64_t>(l);
  for (std::size_t i = 0; i < count; i += W) {
    // u = ((bits >> 11) + 0.5)·2^-53, never 1 (CounterRng::uniform).
    const U index = lane + (b.first + i);
    const U word = b.rng.bits_generic(index * PitchDistribution::max_attempts) >> 11;
    // (__builtin_bit_cast: never a call, see detmath::log_normal_generic.)
    const V whole = (__builtin_bit_cast(V, (word >> 32) | two52_bits) - two52) * 4294967296.0 +
                    (__builtin_bit_cast(V, (word & 0xFFFFFFFFULL) | two52_bits) - two52);
    V u = (whole + 0.5) * 0x1.0p-53;
    u = u < 1.0 ? u : V{} + 0x1.fffffffffffffp-1;
    // z = Φ⁻¹(u) (detmath::normal_quantile's branches; |q| <= 0.425 is
    // fabs(q) <= 0.425, q never NaN). Selects test the comparisons directly:
    // vector masks kept in variables and combined are built lane by lane.
    const V q = u - 0.5;
    const V abs_q = q < 0.0 ? -q : q;
    V r = q < 0.0 ? u : 1.0 - u;
    r = -detmath::log_normal_generic<V, U>(r);
    {
      // Lane by lane through memory, where the compiler vectorizes it (no
      // errno here); indexing the vector itself would split it into lanes.
      alignas(sizeof(V)) double lanes[W];
      std::memcpy(lanes, &r, sizeof r);
      for (int l = 0; l < W; ++l) lanes[l] = std::sqrt(lanes[l]);  // correctly rounded
      std::memcpy(&r, lanes, sizeof r);
    }
    V z = detmath::normal_quantile_tail_generic(r);
    z = q < 0.0 ? -z : z;
    z = abs_q <= 0.425 ? detmath::normal_quantile_central_generic(q) : z;
    const V far = abs_q <= 0.425 ? V{} : r;  // r > 5: AS241's far tail, left to the scalar draw
    // f = exp(t), t = mu + sigma·z (detmath::exp's reduction and scaling).
    const V t = b.mu + b.sigma * z;
    V k;
    const V p = detmath::exp_reduced_generic(t, k);
    const U biased = __builtin_bit_cast(U, k + (two52 + 1023.0));  // low bits: k + 1023
    V f = p * __builtin_bit_cast(V, biased << 52);
    // 2^k normal (k in [-1022, 1023] puts t inside exp's thresholds,
    // -745.13 … 709.78, and a NaN t fails it), the near tail, the band:
    // else a negative mark for the scalar draw. (Each test its own mark: GCC
    // 12 merges selects with one common value into a mask it builds lane by
    // lane.)
    f = k >= -1022.0 ? f : V{} - 1.0;
    f = k <= 1023.0 ? f : V{} - 2.0;
    f = far <= 5.0 ? f : V{} - 3.0;
    f = f >= b.lo ? f : V{} - 4.0;
    f = f <= b.hi ? f : V{} - 5.0;
    std::memcpy(out + i, &f, std::min<std::size_t>(W, count - i) * sizeof(double));
  }
}

using DrawKernel = void (*)(const DrawBatch&, double*, std::size_t);

#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx512f"))) void draw_avx512(const DrawBatch& b, double* out, std::size_t n) { draw_lanes<8>(b, out, n); }
__attribute__((target("avx2"))) void draw_avx2(const DrawBatch& b, double* out, std::size_t n) { draw_lanes<4>(b, out, n); }
#endif

/// The widest kernel this CPU runs (detail::simd_lanes), chosen once; none
/// below AVX2, where two lanes computing every branch are slower than the
/// scalar draw computing one.
DrawKernel draw_kernel() {
  static const DrawKernel kernel = []() -> DrawKernel {
#if defined(__x86_64__) || defined(__i386__)
    if (detail::simd_lanes() == 8) return &draw_avx512;
    if (detail::simd_lanes() == 4) return &draw_avx2;
#endif
    return nullptr;
  }();
  return kernel;
}

}  // namespace

std::string_view to_string(Parameterization p) { return p == Parameterization::moments ? "moments" : "log"; }
std::string_view to_string(OutOfBand o) { return o == OutOfBand::redraw ? "redraw" : "clamp"; }

Parameterization parse_parameterization(std::string_view text, std::string_view field) {
  if (text == "moments") return Parameterization::moments;
  if (text == "log") return Parameterization::log;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: moments, log");
}

OutOfBand parse_out_of_band(std::string_view text, std::string_view field) {
  if (text == "redraw") return OutOfBand::redraw;
  if (text == "clamp") return OutOfBand::clamp;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: redraw, clamp");
}

PitchDistribution::PitchDistribution(const PitchDistributionConfig& config) : config_(config) {
  const double p_db = config.central_pitch.value();
  const double i_db = config.irregularity.value();
  const double lo = config.band_min.value();
  const double hi = config.band_max.value();
  require_finite(p_db, "central_pitch_db", "dB");
  require_finite(i_db, "irregularity_db", "dB");
  if (!(std::isfinite(lo) && lo > 0.0))
    throw InvalidArgument("band_min_cpm is " + num(lo) + " cpm; it must be a finite number > 0");
  if (!(std::isfinite(hi) && hi > lo))
    throw InvalidArgument("band_max_cpm is " + num(hi) + " cpm; it must be finite and above band_min_cpm (" + num(lo) + " cpm)");
  const double q = config.quantization_db;
  if (!(std::isfinite(q) && q >= 0.0 && q <= quantization_db_max))
    throw InvalidArgument("quantization_db is " + num(q) + " dB; allowed: 0 (off) or a step in (0, " + num(quantization_db_max) +
                          "] dB");
  if (p_db < central_pitch_db_min || p_db > central_pitch_db_max)
    throw InvalidArgument("central_pitch_db is " + num(p_db) + " dB; allowed: " + num(central_pitch_db_min) + " … " +
                          num(central_pitch_db_max) + " dB (0.0001 … 10000 cpm)");
  if (i_db > irregularity_db_max || (config.parameterization == Parameterization::moments && i_db < irregularity_db_min))
    throw InvalidArgument("irregularity_db is " + num(i_db) + " dB; allowed: " + num(irregularity_db_min) + " … " +
                          num(irregularity_db_max) + " dB");

  const double lo_db = db_of(lo);
  const double hi_db = db_of(hi);
  if (p_db < lo_db - 1e-9 || p_db > hi_db + 1e-9)
    throw InvalidArgument("central_pitch_db is " + num(p_db) + " dB (" + num(cpm_of(p_db)) +
                          " cpm), outside the renderable band " + detail::fixed(lo_db, 2) + " … " + detail::fixed(hi_db, 2) +
                          " dB (" + num(lo) + " … " + num(hi) + " cpm; the top is the grid's Nyquist frequency unless set)");

  if (config.parameterization == Parameterization::moments) {
    const double m = cpm_of(p_db);
    const double s = cpm_of(i_db);
    const double ratio = s / m;
    const double sigma2 = detmath::log(1.0 + ratio * ratio);
    sigma_ = std::sqrt(sigma2);
    mu_ = detmath::log(m) - 0.5 * sigma2;
  } else {
    if (i_db < 0.0)
      throw InvalidArgument("irregularity_db is " + num(i_db) +
                            " dB; with parameterization 'log' it is the standard deviation of 10·log10(f) and must be >= 0 dB");
    mu_ = p_db * ln10_over_10;
    sigma_ = i_db * ln10_over_10;
  }

  if (sigma_ > 0.0) {
    const double a = (detmath::log(lo) - mu_) / sigma_;
    const double b = (detmath::log(hi) - mu_) / sigma_;
    band_mass_ = detmath::normal_cdf(b) - detmath::normal_cdf(a);
  } else {
    const double f = detmath::exp(mu_);
    band_mass_ = (f >= lo && f <= hi) ? 1.0 : 0.0;
  }
  if (config.out_of_band == OutOfBand::redraw && band_mass_ < min_band_mass)
    throw InvalidArgument("the pitch distribution (central_pitch_db " + num(p_db) + " dB, irregularity_db " + num(i_db) +
                          " dB) has only " + num(band_mass_) + " of its mass inside the band " + num(lo) + " … " + num(hi) +
                          " cpm; at least " + num(min_band_mass) +
                          " is needed (narrow the irregularity or use out_of_band clamp)");
}

double PitchDistribution::quantize(double f) const {
  const double q = config_.quantization_db;
  if (q <= 0.0) return f;
  const double lo = config_.band_min.value();
  const double hi = config_.band_max.value();
  double n = std::round(db_of(f) / q);
  double fq = cpm_of(q * n);
  if (fq > hi) fq = cpm_of(q * (n - 1.0));
  if (fq < lo) fq = cpm_of(q * (n + 1.0));
  // A band narrower than one step holds no grid value: keep the clamped draw.
  if (fq > hi || fq < lo) fq = f < lo ? lo : (f > hi ? hi : f);
  return fq;
}

double PitchDistribution::draw(std::uint64_t seed, std::uint64_t index) const {
  const CounterRng rng(seed, Stream::frequency);
  const double lo = config_.band_min.value();
  const double hi = config_.band_max.value();
  const std::uint64_t base = index * max_attempts;
  double f = 0.0;
  for (std::uint64_t attempt = 0; attempt < max_attempts; ++attempt) {
    f = detmath::exp(mu_ + sigma_ * rng.normal(base + attempt));
    if (config_.out_of_band == OutOfBand::clamp || (f >= lo && f <= hi)) break;
  }
  f = f < lo ? lo : (f > hi ? hi : f);
  return quantize(f);
}

void PitchDistribution::draw(std::uint64_t seed, std::uint64_t first, std::span<double> out) const {
  const DrawBatch batch{
      CounterRng(seed, Stream::frequency), first, mu_, sigma_, config_.band_min.value(), config_.band_max.value()};
  const DrawKernel kernel = draw_kernel();
  if (kernel == nullptr) {
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = draw(seed, first + i);
    return;
  }
  kernel(batch, out.data(), out.size());
  const bool quantized = config_.quantization_db > 0.0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (out[i] < 0.0)
      out[i] = draw(seed, first + i);
    else if (quantized)
      out[i] = quantize(out[i]);  // draw's clamp is the identity for an in-band value
  }
}

}  // namespace texel
