// The log-spectral centroid of a vibration, as the recorded-input and 2-D
// player tests measure it: the power-weighted mean of 10·log10 f (dB re
// 1 Hz) over 20 Hz … 0.45·rate (Welch, Hann, 4096-sample segments).
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "texel/spectrum.hpp"

namespace texel::test_support {

inline double log_centroid_db(const std::vector<double>& x, double rate) {
  WelchOptions o;
  o.segment = 4096;
  // The spectrum tools take a sample spacing; for a time signal it is 1/rate
  // and the "cycles per mm" they report are hertz.
  const Psd p = welch_psd(x, Millimetres(1.0 / rate), o);
  double sw = 0, swd = 0;
  for (std::size_t k = 1; k < p.frequency_cpm.size(); ++k) {
    const double f = p.frequency_cpm[k];
    if (f < 20.0 || f > 0.45 * rate) continue;
    sw += p.density[k], swd += p.density[k] * 10.0 * std::log10(f);
  }
  return swd / sw;
}

}  // namespace texel::test_support
