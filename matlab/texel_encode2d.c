/* texel_encode2d — Texel parameters and a version-4 2-D document for a friction bitmap, a height map or a bundle of scans.
 * The MEX function over the C ABI (texel_mex.h); its usage, options and
 * results are documented in texel_encode2d.m, the help text MATLAB and Octave show. */
#include "texel_mex.h"

struct encode2d_args {
  texel_encode_options options;
  texel_encode2d_options options2d;
  double pitch_mm;
  double swipe_speed_mm_s;
  int polarity;
  char* device;
  char* save;
};

static int take(const char* name, const mxArray* v, void* ctx) {
  struct encode2d_args* a = (struct encode2d_args*)ctx;
  char* s;
  if (tm_take_encode_option(name, v, &a->options)) return 1;
  if (tm_is(name, "pitch_mm"))
    a->pitch_mm = tm_scalar(name, v);
  else if (tm_is(name, "device"))
    a->device = tm_text(name, v);
  else if (tm_is(name, "polarity")) {
    s = tm_text(name, v);
    if (tm_is(s, "darker_more_friction"))
      a->polarity = TEXEL_DARKER_MORE_FRICTION;
    else if (tm_is(s, "brighter_more_friction"))
      a->polarity = TEXEL_BRIGHTER_MORE_FRICTION;
    else
      mexErrMsgIdAndTxt("texel:invalidArgument", "polarity '%s' is not one of darker_more_friction, brighter_more_friction", s);
    mxFree(s);
  } else if (tm_is(name, "swipe_speed_mm_s"))
    a->swipe_speed_mm_s = tm_scalar(name, v);
  else if (tm_is(name, "save"))
    a->save = tm_text(name, v);
  else if (tm_is(name, "directions")) {
    const uint64_t n = tm_count(name, v);
    a->options2d.directions = n > 100000 ? 100000 : (int)n; /* out of range either way: libtexel names it */
  } else if (tm_is(name, "scan_samples"))
    a->options2d.scan_samples = (size_t)tm_count(name, v);
  else if (tm_is(name, "correction_rounds")) {
    const uint64_t n = tm_count(name, v);
    a->options2d.correction_rounds = n > 1000 ? 1000 : (int)n;
  } else
    return 0;
  return 1;
}

/* A height × width real matrix (rows along y, as imread gives an image) as
 * the row-major amplitudes the C ABI takes. */
static double* map_of(const mxArray* m, int* width, int* height) {
  size_t rows, columns, j, k;
  const double* d;
  double* out;
  if (!mxIsDouble(m) || mxIsComplex(m) || mxIsSparse(m) || mxGetNumberOfDimensions(m) != 2)
    tm_usage(
        "the map must be a real double matrix (height × width, values in [0, 1]; double(imread(f)) / 65535 for a 16-bit PNG)");
  rows = mxGetM(m);
  columns = mxGetN(m);
  if (rows > 1000000 || columns > 1000000) tm_usage("the map has more than 10^6 rows or columns");
  d = mxGetPr(m);
  out = (double*)mxMalloc((rows * columns > 0 ? rows * columns : 1) * sizeof *out);
  for (j = 0; j < rows; ++j)
    for (k = 0; k < columns; ++k) out[j * columns + k] = d[k * rows + j];
  *width = (int)columns;
  *height = (int)rows;
  return out;
}

void mexFunction(int nlhs, mxArray* plhs[], int nrhs, const mxArray* prhs[]) {
  struct encode2d_args a;
  texel_encode2d_result* result = NULL;
  texel_status st;
  size_t needed = 0;
  char* json;
  mxArray* text;
  mxArray* decoded = NULL;
  if (nlhs > 1) tm_usage("returns one struct");
  if (nrhs < 1) tm_usage("give the map (a height × width matrix) or a file path (.png, .npy, .scans.json) first");
  memset(&a, 0, sizeof a);
  a.options = texel_encode_options_default();
  a.options2d = texel_encode2d_options_default();
  a.polarity = -1;
  tm_options(nrhs, prhs, 1, take, &a,
             "pitch_mm, device, polarity, swipe_speed_mm_s, save, directions, scan_samples, correction_rounds, boundary_mm, "
             "texel_length_mm, parameterization, seed, target");
  if (mxIsChar(prhs[0])) {
    char* path = tm_text("the path", prhs[0]);
    st = texel_encode_2d_file(path, a.pitch_mm, a.device, a.polarity, a.swipe_speed_mm_s, &a.options, &a.options2d, &result);
  } else {
    int width = 0, height = 0;
    double* map = map_of(prhs[0], &width, &height);
    if (a.device || a.polarity != -1 || a.swipe_speed_mm_s != 0.0)
      tm_usage("device, polarity and swipe_speed_mm_s are for files; a matrix needs 'pitch_mm' alone");
    if (a.pitch_mm == 0.0) tm_usage("a matrix needs 'pitch_mm' (the distance between its pixels, mm)");
    st = texel_encode_2d(map, width, height, a.pitch_mm, &a.options, &a.options2d, &result);
  }
  if (st == TEXEL_OK && a.save) st = texel_encode2d_result_save(result, a.save);
  if (st == TEXEL_OK) st = texel_encode2d_result_json(result, NULL, 0, &needed);
  json = (char*)mxMalloc(needed ? needed : 1);
  if (st == TEXEL_OK) st = texel_encode2d_result_json(result, json, needed, NULL);
  if (st != TEXEL_OK) tm_keep_error();
  texel_encode2d_result_destroy(result);
  if (st != TEXEL_OK) tm_raise(st);
  /* The library's JSON (the one serialisation every front door prints) as a
   * struct: jsondecode, in MATLAB since R2016b and in Octave since 7. */
  text = mxCreateString(json);
  if (mexCallMATLAB(1, &decoded, 1, &text, "jsondecode") != 0 || !decoded)
    mexErrMsgIdAndTxt("texel:ioError", "jsondecode is not available (MATLAB R2016b or later, GNU Octave 7 or later)");
  if (a.save) tm_set_text(decoded, "document", a.save);
  plhs[0] = decoded;
}
