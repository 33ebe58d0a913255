// §2 of docs/encoder.md: the perceptual model (threshold, percept, distance).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "encoder_parts.hpp"
#include "texel/detail/format.hpp"
#include "texel/detail/lanes.hpp"
#include "texel/error.hpp"

namespace texel::codec {

using namespace parts;
using texel::detail::num;
namespace {

/// Masking floor of the model, dB below the strongest spectral component.
constexpr double masked_db = 50.0;

/// x^e for x ≥ 0 over every bin of every candidate's spectrum: libm's pow
/// was an eighth of an encode. An exponent with at most four binary digits
/// after the point (the default 1.75 / 2 = 0.875 = ½ + ¼ + ⅛) is a product
/// of integer powers and repeated square roots, exact to a few ulp; any
/// other exponent falls back to pow.
class DyadicPower {
 public:
  DyadicPower() = default;
  explicit DyadicPower(double e) : e_(e) {
    const double scaled = e * 16.0;
    if (e >= 0.0 && e <= 8.0 && scaled == std::floor(scaled)) {
      const auto bits = static_cast<unsigned>(scaled);
      whole_ = bits >> 4;
      fraction_ = bits & 15u;  // bit 3: x^½, bit 2: x^¼, bit 1: x^⅛, bit 0: x^1/16
      dyadic_ = true;
    }
  }
  double operator()(double x) const {
    if (!dyadic_) return std::pow(x, e_);
    double r = 1.0;
    for (unsigned k = 0; k < whole_; ++k) r *= x;
    double root = x;
    for (unsigned bit = 8; bit != 0 && (fraction_ & ((bit << 1) - 1)) != 0; bit >>= 1) {
      root = std::sqrt(root);
      if (fraction_ & bit) r *= root;
    }
    return r;
  }

 private:
  double e_ = 1.0;
  unsigned whole_ = 1, fraction_ = 0;
  bool dyadic_ = true;
};

}  // namespace

std::string_view to_string(PerceptualModel::Display d) { return d == PerceptualModel::Display::flat ? "flat" : "device"; }

PerceptualModel::Display parse_display_response(std::string_view text, std::string_view field) {
  if (text == "device") return PerceptualModel::Display::device;
  if (text == "flat") return PerceptualModel::Display::flat;
  throw FieldError(std::string(field), "is '" + std::string(text) + "'; allowed: device, flat");
}

double display_gain(const PerceptualModel& model, CyclesPerMm f) {
  if (model.display_response == PerceptualModel::Display::flat) return 1.0;
  return model.display.gain(Hertz(f.value() * model.swipe_speed.value()));
}

bool display_in_loop(const PerceptualModel& model) {
  return model.display_response == PerceptualModel::Display::device && !model.display.flat();
}

double threshold_db(Hertz f) {
  const double hz = std::max(f.value(), 1e-6);
  const double pacinian = 12.0 * std::fabs(std::log2(hz / 250.0));
  return std::min({pacinian, 30.0, 60.0});
}

double felt_threshold_db(Hertz f, Hertz top) {
  const double hz = std::max(f.value(), 1e-6);
  if (hz > top.value()) return std::numeric_limits<double>::infinity();
  // Below 250 Hz the non-Pacinian floor holds (version 2's curve); above it
  // the Pacinian branch keeps rising: no floor where nothing else is felt.
  if (hz < 250.0) return std::min(12.0 * std::log2(250.0 / hz), 30.0);
  return 12.0 * std::log2(hz / 250.0);
}

CyclesPerMm felt_band_top_cpm(const PerceptualModel& model) {
  return CyclesPerMm(model.felt_band_top.value() / model.swipe_speed.value());
}

namespace {

/// Version 3's threshold at one speed: the hard top, or the soft roll-off.
double felt_threshold_one_db(double hz, const PerceptualModel& m) {
  if (!(m.felt_rolloff_db_per_octave > 0.0)) return felt_threshold_db(Hertz(hz), m.felt_band_top);
  if (hz < 250.0) return std::min(12.0 * std::log2(250.0 / std::max(hz, 1e-6)), 30.0);
  return 12.0 * std::log2(hz / 250.0) + m.felt_rolloff_db_per_octave * std::max(0.0, std::log2(hz / m.felt_rolloff_knee.value()));
}

/// Speed ratios (to the median) and their weights: a lognormal with
/// standard deviation `sigma` of ln(speed), 41 nodes over ±3 SD.
constexpr int speed_nodes = 41;
double speed_ratio(int j, double sigma) { return std::exp(sigma * (-3.0 + 6.0 * j / (speed_nodes - 1))); }
double speed_weight(int j) {
  const double z = -3.0 + 6.0 * j / (speed_nodes - 1);
  double sum = 0.0;
  for (int i = 0; i < speed_nodes; ++i) {
    const double u = -3.0 + 6.0 * i / (speed_nodes - 1);
    sum += std::exp(-0.5 * u * u);
  }
  return std::exp(-0.5 * z * z) / sum;
}

}  // namespace

double felt_weight_threshold_db(Hertz f, const PerceptualModel& m) {
  if (!(m.speed_spread > 0.0)) return felt_threshold_one_db(f.value(), m);
  double sens = 0.0;
  for (int j = 0; j < speed_nodes; ++j) {
    const double t = felt_threshold_one_db(f.value() * speed_ratio(j, m.speed_spread), m);
    if (std::isfinite(t)) sens += speed_weight(j) * std::pow(10.0, -t / 10.0);
  }
  return sens > 0.0 ? -10.0 * std::log10(sens) : std::numeric_limits<double>::infinity();
}

CyclesPerMm felt_band_reach_cpm(const PerceptualModel& m) {
  const double slowest = m.speed_spread > 0.0 ? speed_ratio(0, m.speed_spread) : 1.0;
  double top_hz = m.felt_band_top.value();
  if (m.felt_rolloff_db_per_octave > 0.0) {
    // Where the single-speed threshold reaches 80 dB: beyond it nothing is felt.
    const double knee = m.felt_rolloff_knee.value();
    const double octaves = (80.0 - 12.0 * std::log2(knee / 250.0)) / (12.0 + m.felt_rolloff_db_per_octave);
    top_hz = knee * std::exp2(std::max(0.0, octaves));
  }
  return CyclesPerMm(top_hz / slowest / m.swipe_speed.value());
}

namespace {

/// Percept::log_centroid_db of a power spectrum `p` whose bins are at
/// frequencies `f` (cpm) and levels `d` (dB), on a grid of spacing dx, at
/// most up to `top` cpm (version 3: the felt band's top).
double log_centroid(const std::vector<double>& p, const std::vector<double>& f, const std::vector<double>& d, double dx, double v,
                    double f_lo, double top = std::numeric_limits<double>::infinity()) {
  const double lo = std::max(f_lo, centroid_low_hz / v), hi = std::min(centroid_top_nyquist * 0.5 / dx, top);
  double sp = 0.0, spd = 0.0;
  for (std::size_t i = 1; i < p.size(); ++i)
    if (f[i] >= lo && f[i] <= hi) sp += p[i], spd += p[i] * d[i];
  return sp > 0.0 ? spd / sp : 0.0;
}

/// Version 1 (the model before): every bin weighted by its own
/// suprathreshold sensitivity and amplitude.
Percept perceive_v1(std::span<const double> fine, double spacing_mm, const PerceptualModel& model, double f_min_cpm) {
  std::size_t m = 0;
  thread_local std::vector<double> p;  // reused: the fit perceives hundreds of candidates
  power_spectrum(fine, p, m);
  const double v = model.swipe_speed.value();
  // Per-bin frequency, dB, display gain and weight depend only on (M, Δx, v),
  // the model's weighting and the display: cached, a few settings at once (an
  // encode alternates between the whole band and the band above the boundary).
  struct Bins {
    std::size_t m = 0;
    double dx = 0, v = 0, f_min = 0, exponent = 0, scale = 0;
    double corner = 0;  // display response in force (0: flat or off)
    int order = 0;
    std::vector<double> f, d, gain, h2;
    std::vector<double> gain_drawn;  // the weights without the display (empty: no display)
    std::size_t first = 1;           // the first bin at or above f_min (gain > 0 from there)
    DyadicPower half_exponent;       // √P to the weight exponent: P to half of it
  };
  thread_local std::array<Bins, 4> cache;
  thread_local std::size_t replace = 0;
  const double f_lo = std::max(0.01, f_min_cpm);
  const bool display = display_in_loop(model);
  const double corner = display ? model.display.corner.value() : 0.0;
  const int order = display ? model.display.order : 0;
  auto same = [&](const Bins& b) {
    return b.m == m && b.dx == spacing_mm && b.v == v && b.f_min == f_lo && b.exponent == model.weight_exponent &&
           b.scale == model.sensitivity_scale && b.corner == corner && b.order == order;
  };
  auto hit = std::find_if(cache.begin(), cache.end(), same);
  if (hit == cache.end()) {
    if (display) validate(model.display, "display");
    Bins& bins = cache[replace];
    replace = (replace + 1) % cache.size();
    bins.m = m, bins.dx = spacing_mm, bins.v = v, bins.f_min = f_lo;
    bins.exponent = model.weight_exponent, bins.scale = model.sensitivity_scale;
    bins.corner = corner, bins.order = order;
    bins.half_exponent = DyadicPower(0.5 * model.weight_exponent);
    const double df = 1.0 / (static_cast<double>(m) * spacing_mm);
    bins.f.assign(p.size(), 0.0);
    bins.d.assign(p.size(), 0.0);
    bins.gain.assign(p.size(), 0.0);
    bins.h2.assign(p.size(), 1.0);
    bins.gain_drawn.assign(display ? p.size() : 0, 0.0);
    bins.first = p.size();
    for (std::size_t i = 1; i < p.size(); ++i) {
      const double f = static_cast<double>(i) * df;
      bins.f[i] = f;
      bins.d[i] = db_of(f);
      // The display passes |H(f·v)| of the component's amplitude: the felt
      // component is the displayed one (flat: exactly 1, the model before).
      const double h = display ? model.display.gain(Hertz(f * v)) : 1.0;
      bins.h2[i] = h * h;
      // Suprathreshold sensitivity at f·v over sqrt(f): amplitude per unit
      // log-frequency, raised to the weight exponent (applied to √P below).
      const double sensitivity = std::pow(10.0, -model.sensitivity_scale * threshold_db(Hertz(f * v)) / 20.0);
      bins.gain[i] = f < f_lo ? 0.0 : std::pow(h * sensitivity / std::sqrt(f), model.weight_exponent);
      if (display) bins.gain_drawn[i] = f < f_lo ? 0.0 : std::pow(sensitivity / std::sqrt(f), model.weight_exponent);
      if (bins.gain[i] > 0.0) bins.first = std::min(bins.first, i);
    }
    hit = cache.begin() + static_cast<std::ptrdiff_t>(&bins - cache.data());
  }
  const Bins& bins = *hit;
  // Components more than `masked_db` below the strongest are not felt
  // (and leakage and quantization noise stay out of the spread). Felt: on
  // the displayed spectrum P·|H|²; physical: on the texture's own spectrum P
  // (the tie-break keeps the fit anchored to the texture where the display
  // hides it). With a flat display the two masks are one, as before.
  double peak = 0.0, peak_felt = 0.0;
  for (std::size_t i = bins.first; i < p.size(); ++i)
    if (bins.gain[i] > 0.0) peak = std::max(peak, p[i]), peak_felt = std::max(peak_felt, p[i] * bins.h2[i]);
  const double floor = peak * std::pow(10.0, -masked_db / 10.0);
  const double floor_felt = peak_felt * std::pow(10.0, -masked_db / 10.0);
  double sw = 0, swf = 0, swd = 0, swdd = 0;      // perceptual weights
  double sp = 0, spf = 0, spd = 0, spdd = 0;      // physical (power) weights
  double sw0 = 0, swf0 = 0, swd0 = 0, swdd0 = 0;  // perceptual weights of the texture as drawn (display in the loop)
  const bool drawn = !bins.gain_drawn.empty();
  for (std::size_t i = bins.first; i < p.size(); ++i) {
    if (bins.gain[i] == 0.0) continue;
    const double f = bins.f[i], d = bins.d[i];
    const double amplitude = bins.half_exponent(p[i]);  // √P to the weight exponent
    if (p[i] > floor && p[i] * bins.h2[i] > floor_felt) {
      const double w = amplitude * bins.gain[i];
      sw += w, swf += w * f, swd += w * d, swdd += w * d * d;
    }
    if (p[i] > floor) {
      sp += p[i], spf += p[i] * f, spd += p[i] * d, spdd += p[i] * d * d;
      if (drawn) {  // felt as drawn: masked on the texture's own spectrum
        const double w = amplitude * bins.gain_drawn[i];
        sw0 += w, swf0 += w * f, swd0 += w * d, swdd0 += w * d * d;
      }
    }
  }
  if (!(sw > 0.0)) throw InvalidArgument("the fine texture is empty: no spectral content above " + num(f_lo) + " cycles/mm");
  Percept q;
  q.pitch_db = db_of(swf / sw);
  const double md = swd / sw;
  q.noisiness_db = std::sqrt(std::max(0.0, swdd / sw - md * md));
  q.mean_db = db_of(spf / sp);
  const double pd = spd / sp;
  q.spread_db = std::sqrt(std::max(0.0, spdd / sp - pd * pd));
  if (model.centroid) q.log_centroid_db = log_centroid(p, bins.f, bins.d, spacing_mm, v, f_lo);
  q.drawn_pitch_db = q.pitch_db;
  q.drawn_noisiness_db = q.noisiness_db;
  if (drawn && sw0 > 0.0) {
    q.drawn_pitch_db = db_of(swf0 / sw0);
    const double md0 = swd0 / sw0;
    q.drawn_noisiness_db = std::sqrt(std::max(0.0, swdd0 / sw0 - md0 * md0));
  }
  return q;
}

/// Version 2's per-band sums of the spectrum (perceive_v2): in, the power
/// p, each bin's frequency f, level d and display gain h2, the bands' ends;
/// out, per band the felt (through the display, masked at floor_felt)
/// energy and its sums of f, d, d², the same of the texture as drawn (when
/// `drawn_e` is given), and over all bands the physical sums.
struct BandSums {
  const double *p, *f, *d, *h2;
  const std::size_t* end;
  std::size_t first, bands;
  double floor, floor_felt;
  double *felt_e, *felt_f, *felt_d, *felt_dd;
  double *drawn_e, *drawn_f, *drawn_d, *drawn_dd;
  double* physical;
};

/// Band by band (each a run of bins), bin by bin in order: the four sums of
/// a kind (energy, f, d, d²) as the four lanes of one vector. Lane by lane
/// the same terms are added in the same order as four scalar sums: the
/// term vector is p·(1, f, d, d)·(1, 1, 1, d) = (p, p·f, p·d, (p·d)·d).
[[gnu::always_inline]] inline void band_sums_lanes(const BandSums& in) {
  using V = double __attribute__((vector_size(32)));
  V phys = {0.0, 0.0, 0.0, 0.0};
  const bool drawn = in.drawn_e != nullptr;
  for (std::size_t k = 0, i = in.first; k < in.bands; ++k) {
    V felt = {0.0, 0.0, 0.0, 0.0}, own = {0.0, 0.0, 0.0, 0.0};
    for (const std::size_t e = in.end[k]; i < e; ++i) {
      const double pi = in.p[i];
      if (!(pi > in.floor)) continue;
      const double f = in.f[i], d = in.d[i];
      const V a = {1.0, f, d, d}, b = {1.0, 1.0, 1.0, d};
      const V term = (pi * a) * b;
      phys += term;
      const double w = pi * in.h2[i];
      if (w > in.floor_felt) felt += (w * a) * b;
      own += term;
    }
    in.felt_e[k] = felt[0], in.felt_f[k] = felt[1], in.felt_d[k] = felt[2], in.felt_dd[k] = felt[3];
    if (drawn) in.drawn_e[k] = own[0], in.drawn_f[k] = own[1], in.drawn_d[k] = own[2], in.drawn_dd[k] = own[3];
  }
  for (int l = 0; l < 4; ++l) in.physical[l] = phys[l];
}

/// The largest p[i] and p[i]·h2[i] over [first, n), from 0: running maxima
/// in four lanes (a maximum is the same whatever order it is taken in).
[[gnu::always_inline]] inline void band_peaks_lanes(const double* p, const double* h2, std::size_t first, std::size_t n,
                                                    double& peak, double& peak_felt) {
  using V = double __attribute__((vector_size(32)));
  V pk = {0.0, 0.0, 0.0, 0.0}, pkf = pk;
  std::size_t i = first;
  for (; i + 4 <= n; i += 4) {
    V v, h;
    std::memcpy(&v, p + i, sizeof v);
    std::memcpy(&h, h2 + i, sizeof h);
    const V f = v * h;
    pk = pk < v ? v : pk;
    pkf = pkf < f ? f : pkf;
  }
  double a = 0.0, b = 0.0;
  for (int l = 0; l < 4; ++l) a = std::max(a, pk[l]), b = std::max(b, pkf[l]);
  for (; i < n; ++i) a = std::max(a, p[i]), b = std::max(b, p[i] * h2[i]);
  peak = a, peak_felt = b;
}

void band_sums_baseline(const BandSums& in) { band_sums_lanes(in); }
__attribute__((target("avx2"))) void band_sums_avx2(const BandSums& in) { band_sums_lanes(in); }
using PeaksFn = void (*)(const double*, const double*, std::size_t, std::size_t, double&, double&);
void band_peaks_baseline(const double* p, const double* h2, std::size_t first, std::size_t n, double& peak, double& peak_felt) {
  band_peaks_lanes(p, h2, first, n, peak, peak_felt);
}
__attribute__((target("avx2"))) void band_peaks_avx2(const double* p, const double* h2, std::size_t first, std::size_t n,
                                                     double& peak, double& peak_felt) {
  band_peaks_lanes(p, h2, first, n, peak, peak_felt);
}
PeaksFn band_peaks() {
  static const PeaksFn fn = texel::detail::simd_lanes() >= 4 ? &band_peaks_avx2 : &band_peaks_baseline;
  return fn;
}

/// The widest the CPU has (and TEXEL_SIMD allows); every width adds the same bits.
auto band_sums() -> void (*)(const BandSums&) {
  static void (*const fn)(const BandSums&) = texel::detail::simd_lanes() >= 4 ? &band_sums_avx2 : &band_sums_baseline;
  return fn;
}

/// Version 2 threshold of the non-Pacinian channel (dB above the Pacinian
/// best, 250 Hz): flat 30 dB up to 100 Hz, rising 6 dB/octave above.
double non_pacinian_db(double hz) { return 30.0 + 6.0 * std::max(0.0, std::log2(std::max(hz, 1e-6) / 100.0)); }
/// Version 2 threshold of the Pacinian channel: the U of threshold_db without its floor.
double pacinian_db(double hz) { return std::min(12.0 * std::fabs(std::log2(std::max(hz, 1e-6) / 250.0)), 60.0); }

/// Version 2 (docs/encoder.md §2, "Version 2"): the spectrum pooled into
/// constant-Q bands (energy per band, so a line and a continuous spectrum
/// count alike), each band's sensation level its level above the
/// (suprathreshold-scaled) threshold at its centre, the band's felt weight a
/// function of that level (PerceptualModel::weighting), and felt pitch the
/// weighted mean of the bands' log-frequency centroids.
/// Version 3 (`felt_band`): the same within the felt band only (bins up to
/// PerceptualModel::felt_band_top at the model's speed; felt_threshold_db):
/// felt, drawn and physical sums, the masking peak and the centroid. An
/// input with next to nothing in the felt band (under 10⁻⁶ of its power)
/// cannot be felt at this speed; its whole spectrum is then weighed by the
/// Pacinian branch without the band's edge, so the fit stays defined.
Percept perceive_v2(std::span<const double> fine, double spacing_mm, const PerceptualModel& model, double f_min_cpm,
                    bool felt_band = false) {
  std::size_t m = 0;
  thread_local std::vector<double> p;
  power_spectrum(fine, p, m);
  const double v = model.swipe_speed.value();
  // Version 3: the felt band's top, cpm (infinite: every bin, version 2).
  double top_cpm = felt_band ? felt_band_reach_cpm(model).value() : std::numeric_limits<double>::infinity();
  if (felt_band) {
    // Nothing in the felt band (less than 10⁻⁶ of the power above f_min):
    // the whole spectrum, weighed by the Pacinian branch without the edge.
    const double df = 1.0 / (static_cast<double>(m) * spacing_mm);
    const double lo = std::max(0.01, f_min_cpm);
    double in = 0.0, all = 0.0;
    for (std::size_t i = 1; i < p.size(); ++i) {
      const double f = static_cast<double>(i) * df;
      if (f < lo) continue;
      all += p[i];
      if (f <= top_cpm) in += p[i];
    }
    if (!(in > 1e-6 * all)) top_cpm = std::numeric_limits<double>::infinity();
  }
  // Version 3 with nothing in its band: the Pacinian branch without the edge.
  auto threshold = [&](double hz) {
    if (!felt_band) return threshold_db(Hertz(hz));
    return std::isinf(top_cpm) ? felt_threshold_db(Hertz(hz), Hertz(std::numeric_limits<double>::infinity()))
                               : felt_weight_threshold_db(Hertz(hz), model);
  };
  const double f_lo = std::max(0.01, f_min_cpm);
  const bool display = display_in_loop(model);
  const double corner = display ? model.display.corner.value() : 0.0;
  const int order = display ? model.display.order : 0;
  const double b = model.band_octaves;
  struct Bins {
    std::size_t m = 0;
    double dx = 0, v = 0, f_min = 0, b = 0, corner = 0, top = 0;
    int order = 0;
    std::size_t n = 0;  // bins [first, n) are analysed: up to the felt band's top (version 3), else all
    std::vector<double> f, d, h2;
    std::vector<int> band;  // band of each bin (−1: below f_min)
    std::vector<double> centre_hz;
    std::vector<std::size_t> end;  // band k's bins are [end[k−1] (first for k = 0), end[k])
    std::size_t first = 1;
  };
  thread_local std::array<Bins, 4> cache;
  thread_local std::size_t replace = 0;
  auto same = [&](const Bins& x) {
    return x.m == m && x.dx == spacing_mm && x.v == v && x.f_min == f_lo && x.b == b && x.corner == corner && x.order == order &&
           x.top == top_cpm;
  };
  auto hit = std::find_if(cache.begin(), cache.end(), same);
  if (hit == cache.end()) {
    if (display) validate(model.display, "display");
    Bins& x = cache[replace];
    replace = (replace + 1) % cache.size();
    x.m = m, x.dx = spacing_mm, x.v = v, x.f_min = f_lo, x.b = b, x.corner = corner, x.order = order, x.top = top_cpm;
    const double df = 1.0 / (static_cast<double>(m) * spacing_mm);
    x.f.assign(p.size(), 0.0);
    x.d.assign(p.size(), 0.0);
    x.h2.assign(p.size(), 1.0);
    x.band.assign(p.size(), -1);
    x.first = p.size();
    x.n = p.size();
    // Band k is centred at 250 Hz · 2^((k + k0)·b) at the model's speed.
    const auto index = [&](double f) { return static_cast<int>(std::floor(std::log2(f * v / 250.0) / b + 0.5)); };
    const int k0 = index(f_lo);
    for (std::size_t i = 1; i < p.size(); ++i) {
      const double f = static_cast<double>(i) * df;
      x.f[i] = f;
      x.d[i] = db_of(f);
      const double h = display ? model.display.gain(Hertz(f * v)) : 1.0;
      x.h2[i] = h * h;
      if (f > top_cpm && x.n == p.size()) x.n = i;
      if (f < f_lo || i >= x.n) continue;
      x.band[i] = index(f) - k0;
      x.first = std::min(x.first, i);
    }
    const int bands = x.first < x.n ? x.band[x.n - 1] + 1 : 0;
    x.centre_hz.resize(static_cast<std::size_t>(bands));
    for (int k = 0; k < bands; ++k) x.centre_hz[static_cast<std::size_t>(k)] = 250.0 * std::exp2((k + k0) * b);
    // The band index never falls with frequency: each band is one run of bins.
    x.end.assign(static_cast<std::size_t>(bands), x.first);
    for (std::size_t i = x.first; i < x.n; ++i) x.end[static_cast<std::size_t>(x.band[i])] = i + 1;
    for (std::size_t k = 1; k < x.end.size(); ++k) x.end[k] = std::max(x.end[k], x.end[k - 1]);
    hit = cache.begin() + static_cast<std::ptrdiff_t>(&x - cache.data());
  }
  const Bins& x = *hit;
  const std::size_t bands = x.centre_hz.size();
  // Per band: energy, and its power-weighted sums of f, dB and dB², felt
  // (through the display) and as drawn.
  struct Sums {
    std::vector<double> e, f, d, dd;
    void reset(std::size_t n) { e.assign(n, 0.0), f.assign(n, 0.0), d.assign(n, 0.0), dd.assign(n, 0.0); }
    void add(std::size_t k, double w, double f_, double d_) { e[k] += w, f[k] += w * f_, d[k] += w * d_, dd[k] += w * d_ * d_; }
  };
  thread_local Sums felt, drawn;
  felt.reset(bands);
  drawn.reset(display ? bands : 0);
  // The peaks (a maximum does not depend on the order it is taken in).
  double peak = 0.0, peak_felt = 0.0;
  band_peaks()(p.data(), x.h2.data(), x.first, x.n, peak, peak_felt);
  const double floor = peak * std::pow(10.0, -masked_db / 10.0);
  const double floor_felt = peak_felt * std::pow(10.0, -masked_db / 10.0);
  double physical[4];  // sp, spf, spd, spdd
  band_sums()(BandSums{p.data(), x.f.data(), x.d.data(), x.h2.data(), x.end.data(), x.first, bands, floor, floor_felt,
                       felt.e.data(), felt.f.data(), felt.d.data(), felt.dd.data(), display ? drawn.e.data() : nullptr,
                       drawn.f.data(), drawn.d.data(), drawn.dd.data(), physical});
  const double sp = physical[0], spf = physical[1], spd = physical[2], spdd = physical[3];
  if (!(sp > 0.0)) throw InvalidArgument("the fine texture is empty: no spectral content above " + num(f_lo) + " cycles/mm");
  const double s = model.sensitivity_scale, g = model.weight_exponent;
  // Felt pitch and noisiness of one set of band sums.
  auto pool = [&](const Sums& u, double& pitch, double& noisiness) {
    thread_local std::vector<double> w;
    w.assign(bands, 0.0);
    // Sensation levels (dB, relative): band level above the scaled threshold.
    const double s_low = model.sensitivity_scale_low < 0.0 ? s : model.sensitivity_scale_low;
    auto level = [&](std::size_t k, double t_db) {
      // A band centred beyond the felt band (version 3) is not felt, whatever s (0 · ∞ is no level).
      if (std::isinf(t_db)) return -std::numeric_limits<double>::infinity();
      return 10.0 * std::log10(u.e[k]) - (x.centre_hz[k] < 250.0 ? s_low : s) * t_db;
    };
    double top = -1e300;
    for (std::size_t k = 0; k < bands; ++k) {
      if (!(u.e[k] > 0.0)) continue;
      const double hz = x.centre_hz[k];
      if (model.weighting == PerceptualModel::Weighting::channels)
        top = std::max({top, level(k, pacinian_db(hz)), level(k, non_pacinian_db(hz))});
      else
        top = std::max(top, level(k, threshold(hz)));
    }
    if (model.weighting == PerceptualModel::Weighting::channels) {
      double jp = 0, jn = 0;
      thread_local std::vector<double> wp, wn;
      wp.assign(bands, 0.0), wn.assign(bands, 0.0);
      for (std::size_t k = 0; k < bands; ++k) {
        if (!(u.e[k] > 0.0)) continue;
        const double hz = x.centre_hz[k];
        wp[k] = std::pow(10.0, g * (level(k, pacinian_db(hz)) - top) / 20.0);
        wn[k] = std::pow(10.0, g * (level(k, non_pacinian_db(hz)) - top) / 20.0);
        jp += wp[k], jn += wn[k];
      }
      // The stronger channel counts fully, the weaker about half.
      const double ap = jp >= jn ? 1.0 : 0.5, an = jp >= jn ? 0.5 : 1.0;
      for (std::size_t k = 0; k < bands; ++k) w[k] = ap * wp[k] + an * wn[k];
    } else {
      for (std::size_t k = 0; k < bands; ++k) {
        if (!(u.e[k] > 0.0)) continue;
        const double l = level(k, threshold(x.centre_hz[k])) - top;
        w[k] = model.weighting == PerceptualModel::Weighting::equal ? 1.0 / (1.0 + std::exp(-(l + model.window_db) / 1.5))
                                                                    : std::pow(10.0, g * l / 20.0);
      }
    }
    double sw = 0, swf = 0, swd = 0, swdd = 0;
    for (std::size_t k = 0; k < bands; ++k) {
      if (!(u.e[k] > 0.0) || !(w[k] > 0.0)) continue;
      const double a = w[k] / u.e[k];  // the band's weight shared over its bins by power
      sw += w[k], swf += a * u.f[k], swd += a * u.d[k], swdd += a * u.dd[k];
    }
    if (!(sw > 0.0)) throw InvalidArgument("the fine texture is empty: no spectral content above " + num(f_lo) + " cycles/mm");
    const double md = swd / sw;
    pitch = model.log_pitch ? md : db_of(swf / sw);
    noisiness = std::sqrt(std::max(0.0, swdd / sw - md * md));
  };
  Percept q;
  pool(felt, q.pitch_db, q.noisiness_db);
  q.mean_db = db_of(spf / sp);
  const double pd = spd / sp;
  q.spread_db = std::sqrt(std::max(0.0, spdd / sp - pd * pd));
  if (model.centroid) q.log_centroid_db = log_centroid(p, x.f, x.d, spacing_mm, v, f_lo, top_cpm);
  q.drawn_pitch_db = q.pitch_db;
  q.drawn_noisiness_db = q.noisiness_db;
  if (display) pool(drawn, q.drawn_pitch_db, q.drawn_noisiness_db);
  return q;
}

}  // namespace

PerceptualModel model_defaults(int version) {
  PerceptualModel m;
  if (version == 1) {
    m.version = 1;
    m.weight_exponent = 1.75;
    m.sensitivity_scale = 0.5;
    return m;
  }
  if (version == 3) {
    // docs/encoder.md §2, "Version 3": strokes at a lognormal range of
    // speeds (SD 0.6 of ln speed), sensitivity scale and exponent refitted.
    m.version = 3;
    m.speed_spread = 0.6;
    m.sensitivity_scale = 1.0;
    m.weight_exponent = 4.0;
    return m;
  }
  if (version != 2) throw FieldError("model", "is " + std::to_string(version) + "; allowed: 1, 2, 3");
  return m;
}

std::string_view to_string(PerceptualModel::Weighting w) {
  switch (w) {
    case PerceptualModel::Weighting::equal: return "equal";
    case PerceptualModel::Weighting::channels: return "channels";
    default: return "power";
  }
}

Percept perceive(std::span<const double> fine, double spacing_mm, const PerceptualModel& model, double f_min_cpm) {
  if (model.version == 1) return perceive_v1(fine, spacing_mm, model, f_min_cpm);
  if (model.version != 2 && model.version != 3)
    throw FieldError("model", "is " + std::to_string(model.version) + "; allowed: 1, 2, 3");
  if (!(model.band_octaves >= 0.05 && model.band_octaves <= 2.0))
    throw FieldError("band_octaves", "is " + num(model.band_octaves) + "; allowed: 0.05 … 2");
  if (model.version == 3 && !(model.felt_band_top.value() > 0.0 && std::isfinite(model.felt_band_top.value())))
    throw FieldError("felt_band_top", "is " + num(model.felt_band_top.value()) + " Hz; it must be > 0");
  if (model.version == 3 && !(model.speed_spread >= 0.0 && model.speed_spread <= 1.5))
    throw FieldError("speed_spread", "is " + num(model.speed_spread) + "; allowed: 0 … 1.5");
  if (model.version == 3 && !(model.felt_rolloff_db_per_octave >= 0.0 && model.felt_rolloff_db_per_octave <= 200.0))
    throw FieldError("felt_rolloff_db_per_octave", "is " + num(model.felt_rolloff_db_per_octave) + "; allowed: 0 … 200");
  if (model.version == 3 && !(model.felt_rolloff_knee.value() > 250.0 && std::isfinite(model.felt_rolloff_knee.value())))
    throw FieldError("felt_rolloff_knee", "is " + num(model.felt_rolloff_knee.value()) + " Hz; it must be > 250");
  return perceive_v2(fine, spacing_mm, model, f_min_cpm, model.version == 3);
}

double distance(const Percept& a, const Percept& b, const PerceptualModel& model) {
  const double dp = (a.pitch_db - b.pitch_db) / model.pitch_jnd_db;
  const double dn = (a.noisiness_db - b.noisiness_db) / model.noisiness_jnd_db;
  const double dm = a.mean_db - b.mean_db;
  const double ds = a.spread_db - b.spread_db;
  return std::sqrt(dp * dp + dn * dn + model.tie_weight * (dm * dm + ds * ds));
}

double fit_distance(const Percept& a, const Percept& b, const PerceptualModel& model) {
  const double d = distance(a, b, model);
  if (!display_in_loop(model) || model.drawn_weight == 0.0) return d;
  const double dp = model.drawn_weight * (a.drawn_pitch_db - b.drawn_pitch_db) / model.pitch_jnd_db;
  const double dn = model.drawn_weight * (a.drawn_noisiness_db - b.drawn_noisiness_db) / model.noisiness_jnd_db;
  return std::sqrt(d * d + dp * dp + dn * dn);
}

}  // namespace texel::codec
