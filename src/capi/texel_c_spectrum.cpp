// The C ABI: the spectral report of a map (texel_c_internal.hpp).
#include "texel_c_internal.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

using namespace capi_detail;

extern "C" {

// --------------------------------------------------------------- spectrum

texel_spectrum_options texel_spectrum_options_default(void) {
  const texel::AnalysisOptions a;
  texel_spectrum_options o{};
  o.window = TEXEL_WINDOW_BLACKMAN_HARRIS;
  o.zero_pad = static_cast<unsigned>(a.spectrum.zero_pad);
  o.threshold_db = a.peaks.threshold.value();
  o.max_peaks = a.peaks.max_peaks;
  o.welch_segment = a.welch.segment;
  o.welch_overlap = a.welch.overlap;
  return o;
}

texel_status texel_spectrum_analyse(const double* amplitudes, std::size_t count, double spacing_mm,
                                    const texel_spectrum_options* options, texel_spectrum** out) {
  return create(out, [&] {
    const texel_spectrum_options o = options ? *options : texel_spectrum_options_default();
    texel::AnalysisOptions a;
    switch (enum_value(o.window)) {
      case TEXEL_WINDOW_BLACKMAN_HARRIS: a.spectrum.window = texel::Window::blackman_harris; break;
      case TEXEL_WINDOW_HANN: a.spectrum.window = texel::Window::hann; break;
      case TEXEL_WINDOW_FLAT_TOP: a.spectrum.window = texel::Window::flat_top; break;
      case TEXEL_WINDOW_RECTANGULAR: a.spectrum.window = texel::Window::rectangular; break;
      default:
        throw InvalidArgument("window is " + std::to_string(enum_value(o.window)) +
                              "; allowed: TEXEL_WINDOW_BLACKMAN_HARRIS (0), TEXEL_WINDOW_HANN (1), TEXEL_WINDOW_FLAT_TOP (2), "
                              "TEXEL_WINDOW_RECTANGULAR (3)");
    }
    // The ranges `texel spectrum` checks, under the C field names.
    if (o.zero_pad < 1 || o.zero_pad > 16)
      throw InvalidArgument("zero_pad is " + std::to_string(o.zero_pad) + "; allowed: 1 … 16");
    need_finite(o.threshold_db, "threshold_db");
    if (!(o.threshold_db <= 0.0 && o.threshold_db >= -300.0))
      throw InvalidArgument("threshold_db is " + num(o.threshold_db) + " dB; allowed: -300 … 0");
    if (o.max_peaks < 1 || o.max_peaks > 100000)
      throw InvalidArgument("max_peaks is " + std::to_string(o.max_peaks) + "; allowed: 1 … 100000");
    need_finite(o.welch_overlap, "welch_overlap");
    if (!(o.welch_overlap >= 0.0 && o.welch_overlap <= 0.95))
      throw InvalidArgument("welch_overlap is " + num(o.welch_overlap) + "; allowed: 0 … 0.95");
    need_finite(spacing_mm, "spacing_mm");
    if (count > 0) need(amplitudes, "amplitudes");
    if (count < 16) throw InvalidArgument("count is " + std::to_string(count) + " samples; a spectrum needs at least 16");
    a.spectrum.zero_pad = static_cast<int>(o.zero_pad);
    a.peaks.threshold = texel::DecibelsLevel{o.threshold_db};
    a.peaks.max_peaks = o.max_peaks;
    a.welch.segment = o.welch_segment;
    a.welch.overlap = o.welch_overlap;
    auto s = std::make_unique<texel_spectrum>();
    s->report = texel::analyse_spectrum(std::span<const double>(amplitudes, count), texel::Millimetres(spacing_mm), a);
    s->samples = count;
    s->spacing_mm = spacing_mm;
    return s;
  });
}

texel_status texel_spectrum_get_summary(const texel_spectrum* spectrum, texel_spectrum_summary* out) {
  return guarded([&] {
    const texel_spectrum& s = need(spectrum, "spectrum");
    const texel::SpectralReport& r = s.report;
    texel_spectrum_summary m{};
    m.samples = s.samples;
    m.spacing_mm = s.spacing_mm;
    m.nfft = r.spectrum.nfft;
    m.bin_cpm = r.spectrum.bin.value();
    m.resolution_cpm = r.spectrum.resolution.value();
    m.mean_amplitude = r.mean;
    m.rms_amplitude = r.rms;
    m.centroid_cpm = r.summary.centroid.value();
    m.log_centroid_db = r.summary.log_centroid.value();
    m.spread_cpm = r.summary.spread.value();
    m.log_spread_db = r.summary.log_spread.value();
    m.welch_segment = r.psd.segment;
    m.welch_segments = r.psd.segments;
    m.psd_bin_cpm = r.psd.bin.value();
    need(out, "out") = m;
  });
}

texel_status texel_spectrum_get_series(const texel_spectrum* spectrum, texel_spectrum_series series, double* values,
                                       std::size_t capacity, std::size_t* needed) {
  return guarded([&] {
    const texel::SpectralReport& r = need(spectrum, "spectrum").report;
    std::vector<double> picked;
    const std::vector<double>* v = &picked;
    switch (enum_value(series)) {
      case TEXEL_SERIES_FREQUENCY_CPM: v = &r.spectrum.frequency_cpm; break;
      case TEXEL_SERIES_MAGNITUDE: v = &r.spectrum.magnitude; break;
      case TEXEL_SERIES_PSD_FREQUENCY_CPM: v = &r.psd.frequency_cpm; break;
      case TEXEL_SERIES_PSD: v = &r.psd.density; break;
      case TEXEL_SERIES_PEAK_FREQUENCY_CPM:
        for (const auto& p : r.peaks) picked.push_back(p.frequency.value());
        break;
      case TEXEL_SERIES_PEAK_AMPLITUDE:
        for (const auto& p : r.peaks) picked.push_back(p.amplitude);
        break;
      case TEXEL_SERIES_PEAK_LEVEL_DB:
        for (const auto& p : r.peaks) picked.push_back(p.level.value());
        break;
      case TEXEL_SERIES_BAND_LO_CPM:
        for (const auto& b : r.bands) picked.push_back(b.lo.value());
        break;
      case TEXEL_SERIES_BAND_HI_CPM:
        for (const auto& b : r.bands) picked.push_back(b.hi.value());
        break;
      case TEXEL_SERIES_BAND_MEAN_SQUARE:
        for (const auto& b : r.bands) picked.push_back(b.mean_square);
        break;
      case TEXEL_SERIES_BAND_FRACTION:
        for (const auto& b : r.bands) picked.push_back(b.fraction);
        break;
      default:
        throw InvalidArgument("series is " + std::to_string(enum_value(series)) +
                              "; allowed: TEXEL_SERIES_FREQUENCY_CPM (0) … TEXEL_SERIES_BAND_FRACTION (10)");
    }
    if (!check_count(v->size(), values, capacity, needed, "values", "values")) return;
    std::copy(v->begin(), v->end(), values);
  });
}

void texel_spectrum_destroy(texel_spectrum* spectrum) { delete spectrum; }

}  // extern "C"
