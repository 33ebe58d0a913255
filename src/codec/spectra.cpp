// Analysis spectra of the encoder (docs/encoder.md, the model's table: spectrum;
// §1 step 4: the band-spectrum check). Analysis only (never feeds rendered
// samples), so the C library's math and the spectrum module's float FFT
// (noise floor near −130 dB, far below the model's 50 dB masking floor) are
// fine here.
#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <numbers>
#include <numeric>
#include <vector>

#include "../spectrum/fft.hpp"
#include "encoder_parts.hpp"
#include "texel/detail/detfft.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel::codec::parts {
namespace {

std::size_t next_pow2(std::size_t n) {
  std::size_t m = 1;
  while (m < n) m <<= 1;
  return m;
}

constexpr std::size_t max_segment = 1u << 15;

}  // namespace

/// One-sided power spectrum (arbitrary scale) of a zero-mean signal: a Hann
/// periodogram zero-padded to a power of two, or Welch's average of
/// half-overlapping 2^15-sample segments for long signals. Bin i is at
/// i/(M·spacing) cpm; returns M through `m_out`.
/// Not texel::welch_psd: that has no zero padding (its bins would sit on a
/// different grid), a periodic rather than this half-sample-centred Hann
/// window, and an n/4 auto segment; the model's thresholds and the codec
/// tests were set with this computation. The transform is the encoder's own
/// double-precision Pow2RealFft (a few dozen per encode: KISS FFT's float
/// transform was 40 % of an encode).
void power_spectrum(std::span<const double> x, std::vector<double>& p, std::size_t& m_out) {
  const std::size_t n = x.size();
  const std::size_t seg = std::min(n, max_segment);
  // At least 4: the shortest transform Pow2RealFft has (inputs of two or
  // three samples only).
  const std::size_t m = seg < 2 ? next_pow2(seg) : std::max<std::size_t>(4, next_pow2(seg));
  m_out = m;
  p.resize(m / 2 + 1);  // every bin is written below
  // Per thread: the window of the last segment length and the plan of the
  // last transform length, with its work buffers (an encode analyses a few
  // dozen signals of the same length).
  struct Scratch {
    std::vector<double> win;
    std::unique_ptr<texel::detail::Pow2RealFft> fft;
  };
  thread_local Scratch sc;
  if (sc.win.size() != seg) {
    sc.win.resize(seg);
    for (std::size_t i = 0; i < seg; ++i)
      sc.win[i] = 0.5 - 0.5 * std::cos(2.0 * M_PI * (static_cast<double>(i) + 0.5) / static_cast<double>(seg));
  }
  const std::vector<double>& win = sc.win;
  if (m < 2) {
    // One sample (or none): only the DC bin, and no real FFT of length 1.
    p[0] = seg == 1 ? x[0] * win[0] * x[0] * win[0] : 0.0;
    return;
  }
  if (!sc.fft || sc.fft->size() != m) sc.fft = std::make_unique<texel::detail::Pow2RealFft>(m);
  texel::detail::Pow2RealFft* fft = sc.fft.get();
  std::size_t count = 0;
  const std::size_t hop = seg == n ? n : seg / 2;
  for (std::size_t start = 0; start + seg <= n; start += hop) {
    // |X|² of the windowed, zero-padded segment: the first stored (0 + v is
    // v: no zeroed spectrum needed), the others added.
    fft->add_power(x.subspan(start, seg), win, p, count > 0);
    ++count;
  }
  for (double& v : p) v /= static_cast<double>(std::max<std::size_t>(count, 1));
}

std::vector<double> power_spectrum(std::span<const double> x, std::size_t& m_out) {
  std::vector<double> p;
  power_spectrum(x, p, m_out);
  return p;
}

void centre(std::vector<double>& x) {
  if (x.empty()) return;
  const double mean = std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
  for (double& v : x) v -= mean;
}

void centre(std::vector<double>& x, std::vector<double>& y) {
  if (x.size() != y.size() || x.empty()) {
    centre(x), centre(y);
    return;
  }
  // std::accumulate's sums ((0 + x0) + x1) + …, the two interleaved.
  double sx = 0.0, sy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) sx += x[i], sy += y[i];
  const double mx = sx / static_cast<double>(x.size()), my = sy / static_cast<double>(y.size());
  for (double& v : x) v -= mx;
  for (double& v : y) v -= my;
}

std::vector<double> centred(std::span<const double> x) {
  const double mean = std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
  std::vector<double> y(x.begin(), x.end());
  for (double& v : y) v -= mean;
  return y;
}

/// How differently two signals of the same length distribute their power
/// over half-octave bands (0.01 cpm … Nyquist): the power-weighted mean
/// absolute level difference in dB, each spectrum normalised to unit power
/// and floored 40 dB below it.
double shape_distance_db(const std::vector<double>& x, const std::vector<double>& y, double dx) {
  std::size_t m = 0;
  const std::vector<double> px = power_spectrum(centred(x), m);
  const std::vector<double> py = power_spectrum(centred(y), m);
  const double df = 1.0 / (static_cast<double>(m) * dx);
  std::vector<double> bx, by;
  for (std::size_t i = 1; i < px.size(); ++i) {
    const double f = static_cast<double>(i) * df;
    if (f < 0.01) continue;
    const auto band = static_cast<std::size_t>(std::floor(2.0 * std::log2(f / 0.01)));
    if (band >= bx.size()) bx.resize(band + 1, 0.0), by.resize(band + 1, 0.0);
    bx[band] += px[i];
    by[band] += py[i];
  }
  const double tx = std::accumulate(bx.begin(), bx.end(), 0.0), ty = std::accumulate(by.begin(), by.end(), 0.0);
  if (!(tx > 0 && ty > 0)) return 0.0;
  double num_ = 0.0, den = 0.0;
  for (std::size_t b = 0; b < bx.size(); ++b) {
    const double u = bx[b] / tx + 1e-4, v = by[b] / ty + 1e-4;
    const double w = std::max(u, v);
    num_ += w * std::fabs(10.0 * std::log10(u / v));
    den += w;
  }
  return num_ / den;
}

double log_centroid_db(std::span<const double> x, double dx, double v, double f_split, double* below, double top_cpm) {
  std::size_t m = 0;
  const std::vector<double> p = power_spectrum(centred(x), m);
  const double df = 1.0 / (static_cast<double>(m) * dx);
  const double lo = centroid_low_hz / v, hi = std::min(centroid_top_nyquist * 0.5 / dx, top_cpm);
  double sp = 0.0, spd = 0.0, all = 0.0, sb = 0.0;
  for (std::size_t i = 1; i < p.size(); ++i) {
    const double f = static_cast<double>(i) * df;
    if (f >= lo && f <= hi) sp += p[i], spd += p[i] * db_of(f);
    all += p[i], sb += f < f_split ? p[i] : 0.0;
  }
  if (below) *below = all > 0.0 ? sb / all : 0.0;
  return sp > 0.0 ? spd / sp : 0.0;
}

double power_share_above(std::span<const double> x, double dx, double f_cpm) {
  std::size_t m = 0;
  const std::vector<double> p = power_spectrum(centred(x), m);
  const double df = 1.0 / (static_cast<double>(m) * dx);
  double all = 0.0, above = 0.0;
  for (std::size_t i = 1; i < p.size(); ++i) {
    all += p[i];
    if (static_cast<double>(i) * df > f_cpm) above += p[i];
  }
  return all > 0.0 ? above / all : 0.0;
}

void lowpass_felt(std::vector<double>& x, double dx, double top_cpm) {
  const std::size_t n = x.size();
  std::size_t size = 2;
  while (size < n) size <<= 1;
  const double mean = std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(n);
  std::vector<double> re(size, 0.0), im(size, 0.0);
  for (std::size_t i = 0; i < n; ++i) re[i] = x[i] - mean;
  const texel::detail::DetFft fft(size);
  fft.forward(re.data(), im.data());
  // Gain 1 up to the top, a raised cosine to 0 at 1.2 × top (a brick wall
  // would ring over the whole signal), 0 above; the same on the mirrored
  // half, so the result is real. The percept already stops at the top.
  const double df = 1.0 / (static_cast<double>(size) * dx);
  for (std::size_t k = 0; k <= size / 2; ++k) {
    const double f = static_cast<double>(k) * df;
    const double u = (f - top_cpm) / (0.2 * top_cpm);
    const double g = u <= 0.0 ? 1.0 : u >= 1.0 ? 0.0 : 0.5 + 0.5 * std::cos(std::numbers::pi * u);
    re[k] *= g, im[k] *= g;
    if (k != 0 && k != size / 2) re[size - k] *= g, im[size - k] *= g;
  }
  fft.inverse(re.data(), im.data());
  const double scale = 1.0 / static_cast<double>(size);
  for (std::size_t i = 0; i < n; ++i) x[i] = mean + re[i] * scale;
}

}  // namespace texel::codec::parts
