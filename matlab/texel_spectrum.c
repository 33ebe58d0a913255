/* texel_spectrum — what `texel spectrum` reports for a map (docs/matlab.md).
 * The MEX function over the C ABI (texel_mex.h); its usage, options and
 * results are documented in texel_spectrum.m, the help text MATLAB and Octave show. */
#include "texel_mex.h"

struct spectrum_args {
  texel_spectrum_options options;
  double spacing_mm;
  int has_spacing;
};

static int take(const char* name, const mxArray* v, void* ctx) {
  struct spectrum_args* a = (struct spectrum_args*)ctx;
  texel_spectrum_options* o = &a->options;
  if (tm_is(name, "spacing_mm")) {
    a->spacing_mm = tm_scalar(name, v);
    a->has_spacing = 1;
  } else if (tm_is(name, "window")) {
    char* w = tm_text(name, v);
    if (tm_is(w, "blackman-harris"))
      o->window = TEXEL_WINDOW_BLACKMAN_HARRIS;
    else if (tm_is(w, "hann"))
      o->window = TEXEL_WINDOW_HANN;
    else if (tm_is(w, "flat-top"))
      o->window = TEXEL_WINDOW_FLAT_TOP;
    else if (tm_is(w, "rectangular"))
      o->window = TEXEL_WINDOW_RECTANGULAR;
    else
      mexErrMsgIdAndTxt("texel:invalidArgument", "window '%s' is not one of blackman-harris, hann, flat-top, rectangular", w);
    mxFree(w);
  } else if (tm_is(name, "zero_pad")) {
    const uint64_t z = tm_count(name, v);
    o->zero_pad = z > 1000 ? 1000u : (unsigned)z; /* out of range either way: libtexel names it */
  } else if (tm_is(name, "threshold_db"))
    o->threshold_db = tm_scalar(name, v);
  else if (tm_is(name, "max_peaks"))
    o->max_peaks = (size_t)tm_count(name, v);
  else if (tm_is(name, "welch_segment"))
    o->welch_segment = (size_t)tm_count(name, v);
  else if (tm_is(name, "welch_overlap"))
    o->welch_overlap = tm_scalar(name, v);
  else
    return 0;
  return 1;
}

/* One series of the analysis as a column (NULL after a failure). */
static mxArray* series(const texel_spectrum* s, texel_spectrum_series which, texel_status* st) {
  size_t n = 0;
  mxArray* a;
  if (*st != TEXEL_OK) return NULL;
  *st = texel_spectrum_get_series(s, which, NULL, 0, &n);
  if (*st != TEXEL_OK) return NULL;
  a = mxCreateDoubleMatrix(n, 1, mxREAL);
  *st = texel_spectrum_get_series(s, which, mxGetPr(a), n, NULL);
  return a;
}

void mexFunction(int nlhs, mxArray* plhs[], int nrhs, const mxArray* prhs[]) {
  struct spectrum_args a;
  texel_spectrum* spec = NULL;
  texel_spectrum_summary m;
  mxArray *r, *peaks, *bands, *v[11];
  size_t count = 0;
  double* amplitude;
  texel_status st;
  int k;
  if (nlhs > 1) tm_usage("returns one struct");
  if (nrhs < 1) tm_usage("give the map (a numeric vector) first");
  memset(&a, 0, sizeof a);
  a.options = texel_spectrum_options_default();
  amplitude = tm_map("the map", prhs[0], &count);
  tm_options(nrhs, prhs, 1, take, &a, "spacing_mm, window, zero_pad, threshold_db, max_peaks, welch_segment, welch_overlap");
  if (!a.has_spacing) tm_usage("the map needs 'spacing_mm' (the distance between its samples, mm)");
  st = texel_spectrum_analyse(amplitude, count, a.spacing_mm, &a.options, &spec);
  if (st == TEXEL_OK) st = texel_spectrum_get_summary(spec, &m);
  for (k = 0; k < 11; ++k) v[k] = series(spec, (texel_spectrum_series)k, &st);
  if (st != TEXEL_OK) tm_keep_error();
  texel_spectrum_destroy(spec);
  if (st != TEXEL_OK) tm_raise(st);

  r = tm_struct();
  tm_set_scalar(r, "samples", (double)m.samples);
  tm_set_scalar(r, "spacing_mm", m.spacing_mm);
  tm_set_scalar(r, "nfft", (double)m.nfft);
  tm_set_scalar(r, "bin_cpm", m.bin_cpm);
  tm_set_scalar(r, "resolution_cpm", m.resolution_cpm);
  tm_set_scalar(r, "mean_amplitude", m.mean_amplitude);
  tm_set_scalar(r, "rms_amplitude", m.rms_amplitude);
  tm_set_scalar(r, "centroid_cpm", m.centroid_cpm);
  tm_set_scalar(r, "log_centroid_db", m.log_centroid_db);
  tm_set_scalar(r, "spread_cpm", m.spread_cpm);
  tm_set_scalar(r, "log_spread_db", m.log_spread_db);
  tm_set_scalar(r, "welch_segment", (double)m.welch_segment);
  tm_set_scalar(r, "welch_segments", (double)m.welch_segments);
  tm_set_scalar(r, "psd_bin_cpm", m.psd_bin_cpm);
  tm_set(r, "frequency_cpm", v[TEXEL_SERIES_FREQUENCY_CPM]);
  tm_set(r, "magnitude", v[TEXEL_SERIES_MAGNITUDE]);
  tm_set(r, "psd_frequency_cpm", v[TEXEL_SERIES_PSD_FREQUENCY_CPM]);
  tm_set(r, "psd", v[TEXEL_SERIES_PSD]);
  peaks = tm_struct();
  tm_set(peaks, "frequency_cpm", v[TEXEL_SERIES_PEAK_FREQUENCY_CPM]);
  tm_set(peaks, "amplitude", v[TEXEL_SERIES_PEAK_AMPLITUDE]);
  tm_set(peaks, "level_db", v[TEXEL_SERIES_PEAK_LEVEL_DB]);
  tm_set(r, "peaks", peaks);
  bands = tm_struct();
  tm_set(bands, "lo_cpm", v[TEXEL_SERIES_BAND_LO_CPM]);
  tm_set(bands, "hi_cpm", v[TEXEL_SERIES_BAND_HI_CPM]);
  tm_set(bands, "mean_square", v[TEXEL_SERIES_BAND_MEAN_SQUARE]);
  tm_set(bands, "fraction", v[TEXEL_SERIES_BAND_FRACTION]);
  tm_set(r, "bands", bands);
  plhs[0] = r;
}
