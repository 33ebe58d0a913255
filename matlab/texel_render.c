/* texel_render — a Texel texture's map on a device (docs/matlab.md).
 * The MEX function over the C ABI (texel_mex.h); its usage, options and
 * results are documented in texel_render.m, the help text MATLAB and Octave show. */
#include "texel_mex.h"

struct render_args {
  texel_params params;
  char* device;
  char* document;
  enum tm_output output;
  int from_params;
};

static int take(const char* name, const mxArray* v, void* ctx) {
  struct render_args* a = (struct render_args*)ctx;
  texel_params* p = &a->params;
  if (tm_take_map_option(name, v, &a->device, &a->output)) return 1;
  if (tm_is(name, "document")) {
    a->document = tm_text(name, v);
    return 1;
  }
  a->from_params = 1;
  if (tm_is(name, "central_pitch_db"))
    p->central_pitch_db = tm_scalar(name, v);
  else if (tm_is(name, "irregularity_db"))
    p->irregularity_db = tm_scalar(name, v);
  else if (tm_is(name, "texel_length_mm"))
    p->texel_length_mm = tm_scalar(name, v);
  else if (tm_is(name, "seed"))
    p->seed = tm_count(name, v);
  else if (tm_is(name, "parameterization"))
    p->parameterization = tm_parameterization(v);
  else if (tm_is(name, "quantization_db"))
    p->quantization_db = tm_scalar(name, v);
  else if (tm_is(name, "coarse_strength"))
    p->coarse_strength = tm_scalar(name, v);
  else if (tm_is(name, "fine_strength"))
    p->fine_strength = tm_scalar(name, v);
  else if (tm_is(name, "coarse_sine_period_mm"))
    p->coarse_sine_period_mm = tm_scalar(name, v);
  else if (tm_is(name, "coarse_sine_phase_deg"))
    p->coarse_sine_phase_deg = tm_scalar(name, v);
  else
    return 0;
  return 1;
}

void mexFunction(int nlhs, mxArray* plhs[], int nrhs, const mxArray* prhs[]) {
  struct render_args a;
  texel_document* doc = NULL;
  texel_status st;
  if (nlhs > 2) tm_usage("returns at most [map, info]");
  memset(&a, 0, sizeof a);
  a.params = texel_params_default();
  tm_options(nrhs, prhs, 0, take, &a,
             "device, central_pitch_db, irregularity_db, texel_length_mm, seed, parameterization, quantization_db, "
             "coarse_strength, fine_strength, coarse_sine_period_mm, coarse_sine_phase_deg, document, output");
  if (a.document) {
    if (a.from_params) tm_usage("give either 'document' or texture parameters, not both");
    st = texel_document_load(a.document, &doc);
  } else {
    st = texel_document_from_params(a.device ? a.device : "tpad", &a.params, &doc);
  }
  tm_check(st);
  tm_render_document(doc, a.document ? NULL : (a.device ? a.device : "tpad"), a.output, nlhs, plhs);
  if (nlhs > 1 && !a.document) tm_set(plhs[1], "params", tm_params_struct(&a.params));
}
