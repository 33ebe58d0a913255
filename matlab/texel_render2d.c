/* texel_render2d — a 2-D document's friction bitmap (docs/matlab.md).
 * The MEX function over the C ABI (texel_mex.h); its usage, options and
 * results are documented in texel_render2d.m, the help text MATLAB and Octave show. */
#include "texel_mex.h"

struct render2d_args {
  double first_row, rows;
  int has_rows;
  int pixels; /* 0: amplitudes; 8 or 16: pixels of that depth; -1: the device's depth */
  char* file;
  double depth;
};

static int take(const char* name, const mxArray* v, void* ctx) {
  struct render2d_args* a = (struct render2d_args*)ctx;
  if (tm_is(name, "rows")) {
    if (!mxIsDouble(v) || mxIsComplex(v) || mxGetNumberOfElements(v) != 2)
      tm_usage("rows must be [first count]: the first row (0-based, y = first·pitch) and how many");
    a->first_row = mxGetPr(v)[0];
    a->rows = mxGetPr(v)[1];
    a->has_rows = 1;
  } else if (tm_is(name, "output")) {
    char* s = tm_text(name, v);
    if (tm_is(s, "amplitude"))
      a->pixels = 0;
    else if (tm_is(s, "pixels"))
      a->pixels = -1;
    else if (tm_is(s, "u8"))
      a->pixels = 8;
    else if (tm_is(s, "u16"))
      a->pixels = 16;
    else
      mexErrMsgIdAndTxt("texel:invalidArgument", "output '%s' is not one of amplitude, pixels, u8, u16", s);
    mxFree(s);
  } else if (tm_is(name, "file"))
    a->file = tm_text(name, v);
  else if (tm_is(name, "depth"))
    a->depth = tm_scalar(name, v);
  else
    return 0;
  return 1;
}

/* A whole number that fits an int, or a usage error naming it. */
static int whole(const char* name, double v) {
  if (!(v >= 0.0 && v <= 2147483647.0) || floor(v) != v)
    mexErrMsgIdAndTxt("texel:invalidArgument", "%s is %.17g; allowed: a whole number >= 0", name, v);
  return (int)v;
}

void mexFunction(int nlhs, mxArray* plhs[], int nrhs, const mxArray* prhs[]) {
  struct render2d_args a;
  texel_document* doc = NULL;
  texel_surface2d* surface = NULL;
  texel_bitmap_info info;
  texel_status st;
  char* path;
  mxArray* map = NULL;
  int first = 0, rows = 0, depth = 0;
  size_t w = 0, n = 0, i, j;
  if (nlhs > 2) tm_usage("returns at most [map, info]");
  if (nrhs < 1) tm_usage("give the 2-D document's path first");
  path = tm_text("the document path", prhs[0]);
  memset(&a, 0, sizeof a);
  tm_options(nrhs, prhs, 1, take, &a, "rows, output, file, depth");
  if (a.file && (a.has_rows || a.pixels != 0)) tm_usage("'file' writes the whole bitmap: give neither rows nor output");
  depth = whole("depth", a.depth);
  if (a.pixels > 0) depth = a.pixels;
  st = texel_document_load(path, &doc);
  if (st == TEXEL_OK) st = texel_surface2d_create(doc, &surface);
  if (st == TEXEL_OK) st = texel_surface2d_info(surface, &info);
  if (st == TEXEL_OK && a.file) {
    st = texel_surface2d_write(surface, a.file, depth);
  } else if (st == TEXEL_OK) {
    first = a.has_rows ? whole("rows(1)", a.first_row) : 0;
    rows = a.has_rows ? whole("rows(2)", a.rows) : info.height_px;
    w = (size_t)info.width_px;
    n = (size_t)rows * w;
    /* The library writes rows along y row-major; MATLAB's matrix is rows × width, column-major. */
    if (a.pixels == 0) {
      double* buffer = (double*)mxMalloc((n ? n : 1) * sizeof *buffer);
      st = texel_surface2d_render_rows(surface, first, rows, buffer, n);
      if (st == TEXEL_OK) {
        double* m;
        map = mxCreateDoubleMatrix((size_t)rows, w, mxREAL);
        m = mxGetPr(map);
        for (j = 0; j < (size_t)rows; ++j)
          for (i = 0; i < w; ++i) m[i * (size_t)rows + j] = buffer[j * w + i];
      }
      mxFree(buffer);
    } else {
      uint16_t* buffer = (uint16_t*)mxMalloc((n ? n : 1) * sizeof *buffer);
      const int bits = depth == 0 ? info.depth_bits : depth;
      st = texel_surface2d_render_pixels(surface, first, rows, depth, buffer, n);
      if (st == TEXEL_OK && bits == 8) {
        uint8_t* m;
        map = mxCreateNumericMatrix((size_t)rows, w, mxUINT8_CLASS, mxREAL);
        m = (uint8_t*)mxGetData(map);
        for (j = 0; j < (size_t)rows; ++j)
          for (i = 0; i < w; ++i) m[i * (size_t)rows + j] = (uint8_t)buffer[j * w + i];
      } else if (st == TEXEL_OK) {
        uint16_t* m;
        map = mxCreateNumericMatrix((size_t)rows, w, mxUINT16_CLASS, mxREAL);
        m = (uint16_t*)mxGetData(map);
        for (j = 0; j < (size_t)rows; ++j)
          for (i = 0; i < w; ++i) m[i * (size_t)rows + j] = buffer[j * w + i];
      }
      mxFree(buffer);
    }
  }
  if (st != TEXEL_OK) tm_keep_error();
  texel_surface2d_destroy(surface);
  texel_document_destroy(doc);
  if (st != TEXEL_OK) tm_raise(st);
  if (a.file) map = mxCreateDoubleMatrix(0, 0, mxREAL);
  plhs[0] = map;
  if (nlhs > 1) {
    mxArray* s = tm_struct();
    tm_set_scalar(s, "width_px", info.width_px);
    tm_set_scalar(s, "height_px", info.height_px);
    tm_set_scalar(s, "pixel_pitch_mm", info.pixel_pitch_mm);
    tm_set_scalar(s, "depth_bits", info.depth_bits);
    tm_set_text(s, "polarity", info.polarity == TEXEL_BRIGHTER_MORE_FRICTION ? "brighter_more_friction" : "darker_more_friction");
    tm_set_scalar(s, "first_row", first);
    plhs[1] = s;
  }
}
