/* texel_encode — Texel parameters and a .texel bitstream for a map or a recording.
 * The MEX function over the C ABI (texel_mex.h); its usage, options and
 * results are documented in texel_encode.m, the help text MATLAB and Octave show. */
#include "texel_mex.h"

struct encode_args {
  texel_encode_options options;
  double spacing_mm;
  int has_spacing;
  double swipe_speed_mm_s;
  char* device;
};

static int take(const char* name, const mxArray* v, void* ctx) {
  struct encode_args* a = (struct encode_args*)ctx;
  texel_encode_options* o = &a->options;
  if (tm_take_encode_option(name, v, o)) return 1;
  if (tm_is(name, "spacing_mm")) {
    a->spacing_mm = tm_scalar(name, v);
    a->has_spacing = 1;
  } else if (tm_is(name, "device"))
    a->device = tm_text(name, v);
  else if (tm_is(name, "swipe_speed_mm_s"))
    a->swipe_speed_mm_s = tm_scalar(name, v);
  else if (tm_is(name, "coarse_bits")) {
    const uint64_t bits = tm_count(name, v);
    o->coarse_bits = bits > 1000 ? 1000u : (unsigned)bits; /* out of range either way: libtexel names it */
  } else if (tm_is(name, "max_bytes"))
    o->max_bytes = (size_t)tm_count(name, v);
  else if (tm_is(name, "recover_texel"))
    o->recover_texel = tm_scalar(name, v) != 0.0;
  else
    return 0;
  return 1;
}

void mexFunction(int nlhs, mxArray* plhs[], int nrhs, const mxArray* prhs[]) {
  struct encode_args a;
  texel_encode_result* result = NULL;
  texel_params params;
  int has_profile = 0;
  double jnd = 0.0;
  texel_encode_flags flags;
  size_t nbytes = 0;
  mxArray* bitstream = NULL;
  texel_status st;
  mxArray* r;
  if (nlhs > 1) tm_usage("returns one struct");
  if (nrhs < 1) tm_usage("give the map (a numeric vector) or a file path first");
  memset(&a, 0, sizeof a);
  a.options = texel_encode_options_default();
  tm_options(nrhs, prhs, 1, take, &a,
             "spacing_mm, device, swipe_speed_mm_s, boundary_mm, texel_length_mm, parameterization, seed, coarse_bits, "
             "max_bytes, recover_texel, target");
  if (mxIsChar(prhs[0])) {
    char* path = tm_text("the path", prhs[0]);
    if (a.has_spacing) tm_usage("spacing_mm is for arrays; a file carries its own spacing");
    st = texel_encode_file(path, a.device, a.swipe_speed_mm_s, &a.options, &result);
  } else {
    size_t count = 0;
    double* amplitude = tm_map("the map", prhs[0], &count);
    if (!a.has_spacing) tm_usage("an array needs 'spacing_mm' (the distance between its samples, mm)");
    if (a.device || a.swipe_speed_mm_s != 0.0) tm_usage("device and swipe_speed_mm_s are for files; an array is a map");
    st = texel_encode_with(amplitude, count, a.spacing_mm, &a.options, &result);
  }
  if (st == TEXEL_OK) st = texel_encode_result_params(result, &params, &has_profile);
  if (st == TEXEL_OK) st = texel_encode_result_distance(result, &jnd);
  if (st == TEXEL_OK) st = texel_encode_result_flags(result, &flags);
  if (st == TEXEL_OK) st = texel_encode_result_bytes(result, NULL, 0, &nbytes);
  if (st == TEXEL_OK) {
    bitstream = mxCreateNumericMatrix(nbytes, 1, mxUINT8_CLASS, mxREAL);
    st = texel_encode_result_bytes(result, (uint8_t*)mxGetData(bitstream), nbytes, NULL);
  }
  if (st != TEXEL_OK) tm_keep_error();
  texel_encode_result_destroy(result);
  if (st != TEXEL_OK) tm_raise(st);
  r = tm_params_struct(&params);
  tm_set(r, "has_coarse_profile", mxCreateLogicalScalar(has_profile != 0));
  tm_set_scalar(r, "distance_jnd", jnd);
  tm_set_text(r, "target", flags.target == TEXEL_TARGET_CENTROID ? "centroid" : "felt");
  tm_set(r, "bitstream", bitstream);
  plhs[0] = r;
}
