/* texel_reference — one of Texel's reference textures on a device.
 * The MEX function over the C ABI (texel_mex.h); its usage, options and
 * results are documented in texel_reference.m, the help text MATLAB and Octave show. */
#include "texel_mex.h"

struct reference_args {
  uint64_t seed;
  char* device;
  enum tm_output output;
};

static int take(const char* name, const mxArray* v, void* ctx) {
  struct reference_args* a = (struct reference_args*)ctx;
  if (!tm_is(name, "seed")) return tm_take_map_option(name, v, &a->device, &a->output);
  a->seed = tm_count(name, v);
  return 1;
}

void mexFunction(int nlhs, mxArray* plhs[], int nrhs, const mxArray* prhs[]) {
  struct reference_args a;
  texel_document* doc = NULL;
  char* name;
  const char* device;
  if (nlhs > 2) tm_usage("returns at most [map, info]");
  if (nrhs < 1) tm_usage("give the reference's name first, e.g. texel_reference('pink')");
  memset(&a, 0, sizeof a);
  a.seed = 1;
  name = tm_text("the reference name", prhs[0]);
  tm_options(nrhs, prhs, 1, take, &a, "seed, device, output");
  device = a.device ? a.device : "tpad";
  tm_check(texel_document_from_reference(device, name, a.seed, &doc));
  tm_render_document(doc, device, a.output, nlhs, plhs);
  if (nlhs > 1) {
    tm_set_text(plhs[1], "name", name);
    tm_set(plhs[1], "seed", tm_uint64(a.seed));
  }
}
