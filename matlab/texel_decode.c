/* texel_decode — the map a .texel bitstream stands for on a device.
 * The MEX function over the C ABI (texel_mex.h); its usage, options and
 * results are documented in texel_decode.m, the help text MATLAB and Octave show. */
#include "texel_mex.h"

struct decode_args {
  char* device;
  enum tm_output output;
};

static int take(const char* name, const mxArray* v, void* ctx) {
  struct decode_args* a = (struct decode_args*)ctx;
  return tm_take_map_option(name, v, &a->device, &a->output);
}

/* The bytes of a file, in mxMalloc memory. */
static uint8_t* read_file(const char* path, size_t* size) {
  FILE* f = fopen(path, "rb");
  uint8_t* bytes = NULL;
  size_t cap = 0, n = 0, got;
  if (!f) mexErrMsgIdAndTxt("texel:ioError", "cannot read '%s'", path);
  do {
    if (n == cap) {
      cap = cap ? cap * 2 : 4096;
      bytes = (uint8_t*)mxRealloc(bytes, cap);
    }
    got = fread(bytes + n, 1, cap - n, f);
    n += got;
  } while (got > 0);
  if (ferror(f)) {
    fclose(f);
    mexErrMsgIdAndTxt("texel:ioError", "cannot read '%s'", path);
  }
  fclose(f);
  *size = n;
  return bytes;
}

void mexFunction(int nlhs, mxArray* plhs[], int nrhs, const mxArray* prhs[]) {
  struct decode_args a;
  texel_document* doc = NULL;
  const uint8_t* bytes;
  size_t size;
  const char* device;
  if (nlhs > 2) tm_usage("returns at most [map, info]");
  if (nrhs < 1) tm_usage("give the bitstream (uint8) or a .texel path first");
  memset(&a, 0, sizeof a);
  if (mxIsChar(prhs[0])) {
    bytes = read_file(tm_text("the path", prhs[0]), &size);
  } else if (mxIsUint8(prhs[0]) && !mxIsComplex(prhs[0])) {
    bytes = (const uint8_t*)mxGetData(prhs[0]);
    size = mxGetNumberOfElements(prhs[0]);
  } else {
    tm_usage("the bitstream must be uint8 bytes or the path of a .texel file");
    return;
  }
  tm_options(nrhs, prhs, 1, take, &a, "device, output");
  device = a.device ? a.device : "tpad";
  tm_check(texel_decode(bytes, size, device, &doc));
  tm_render_document(doc, device, a.output, nlhs, plhs);
}
