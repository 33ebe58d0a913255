/* texel_swipe2d — a 2-D document under a 2-D finger through the 2-D player (docs/matlab.md).
 * The MEX function over the C ABI (texel_mex.h); its usage, options and
 * results are documented in texel_swipe2d.m, the help text MATLAB and Octave show. */
#include "texel_mex.h"

struct swipe2d_args {
  texel_path2d_config path;
  texel_player_config player;
  texel_map2d_mode mode;
  texel_path_at_lift at_lift;
  double duration_s;
  int has_duration;
};

static int take(const char* name, const mxArray* v, void* ctx) {
  struct swipe2d_args* a = (struct swipe2d_args*)ctx;
  char* s;
  if (tm_is(name, "speed_mm_s"))
    a->path.speed_mm_s = tm_scalar(name, v);
  else if (tm_is(name, "angle_deg"))
    a->path.angle_deg = tm_scalar(name, v);
  else if (tm_is(name, "start_x_mm"))
    a->path.start_x_mm = tm_scalar(name, v);
  else if (tm_is(name, "start_y_mm"))
    a->path.start_y_mm = tm_scalar(name, v);
  else if (tm_is(name, "radius_mm"))
    a->path.radius_mm = tm_scalar(name, v);
  else if (tm_is(name, "leg_mm"))
    a->path.leg_mm = tm_scalar(name, v);
  else if (tm_is(name, "zigzag_deg"))
    a->path.zigzag_deg = tm_scalar(name, v);
  else if (tm_is(name, "duration_s")) {
    a->duration_s = tm_scalar(name, v);
    a->has_duration = 1;
  } else if (tm_is(name, "rate_hz"))
    a->player.rate_hz = tm_scalar(name, v);
  else if (tm_is(name, "gain"))
    a->player.gain = tm_scalar(name, v);
  else if (tm_is(name, "carrier_hz"))
    a->player.carrier_hz = tm_scalar(name, v);
  else if (tm_is(name, "output")) {
    s = tm_text(name, v);
    if (tm_is(s, "amplitude"))
      a->player.mode = TEXEL_OUTPUT_AMPLITUDE;
    else if (tm_is(s, "vibration"))
      a->player.mode = TEXEL_OUTPUT_VIBRATION;
    else if (tm_is(s, "carrier"))
      a->player.mode = TEXEL_OUTPUT_CARRIER;
    else
      mexErrMsgIdAndTxt("texel:invalidArgument", "output '%s' is not one of amplitude, vibration, carrier", s);
    mxFree(s);
  } else if (tm_is(name, "mode")) {
    s = tm_text(name, v);
    if (tm_is(s, "path"))
      a->mode = TEXEL_MAP2D_PATH;
    else if (tm_is(s, "bitmap"))
      a->mode = TEXEL_MAP2D_BITMAP;
    else
      mexErrMsgIdAndTxt("texel:invalidArgument", "mode '%s' is not one of path, bitmap", s);
    mxFree(s);
  } else if (tm_is(name, "path_at_lift")) {
    s = tm_text(name, v);
    if (tm_is(s, "keep"))
      a->at_lift = TEXEL_PATH_KEEP;
    else if (tm_is(s, "reset"))
      a->at_lift = TEXEL_PATH_RESET;
    else
      mexErrMsgIdAndTxt("texel:invalidArgument", "path_at_lift '%s' is not one of keep, reset", s);
    mxFree(s);
  } else
    return 0;
  return 1;
}

/* A recorded trace: an N×3 matrix of x_mm, y_mm, t_s or N×4 with touch. */
static texel_finger2d* trace_of(const mxArray* m, size_t* n) {
  size_t rows, columns, i;
  const double* d;
  texel_finger2d* t;
  if (!mxIsDouble(m) || mxIsComplex(m) || mxIsSparse(m)) tm_usage("the trace must be a real double matrix");
  rows = mxGetM(m);
  columns = mxGetN(m);
  if ((columns != 3 && columns != 4) || rows < 1)
    mexErrMsgIdAndTxt("texel:invalidArgument", "the trace is %u×%u; it must be N×3 (x_mm, y_mm, t_s) or N×4 (with touch), N >= 1",
                      (unsigned)rows, (unsigned)columns);
  d = mxGetPr(m);
  t = (texel_finger2d*)mxMalloc(rows * sizeof *t);
  for (i = 0; i < rows; ++i) {
    t[i].x_mm = d[i];
    t[i].y_mm = d[rows + i];
    t[i].t_s = d[2 * rows + i];
    t[i].touch = columns == 4 ? d[3 * rows + i] != 0.0 : 1;
  }
  *n = rows;
  return t;
}

void mexFunction(int nlhs, mxArray* plhs[], int nrhs, const mxArray* prhs[]) {
  struct swipe2d_args a;
  texel_document* doc = NULL;
  texel_finger2d* trace = NULL;
  size_t samples = 0, frames;
  double frames_d;
  texel_status st;
  char* path;
  mxArray *out, *x, *y;
  if (nlhs > 3) tm_usage("returns at most [output, x_mm, y_mm]");
  if (nrhs < 2) tm_usage("give the document's path and a path name ('line', 'circle', 'zigzag') or an N×3 trace");
  path = tm_text("the document path", prhs[0]);
  memset(&a, 0, sizeof a);
  a.path = texel_path2d_config_default();
  a.player = texel_player_config_default();
  a.player.mode = TEXEL_OUTPUT_VIBRATION; /* as texel swipe */
  a.mode = TEXEL_MAP2D_PATH;
  a.at_lift = TEXEL_PATH_KEEP;
  tm_options(nrhs, prhs, 2, take, &a,
             "speed_mm_s, angle_deg, start_x_mm, start_y_mm, radius_mm, leg_mm, zigzag_deg, duration_s, rate_hz, output, "
             "gain, carrier_hz, mode, path_at_lift");
  if (mxIsChar(prhs[1])) { /* a simulated stroke, as texel swipe --path */
    char* shape = tm_text("the path", prhs[1]);
    if (tm_is(shape, "line"))
      a.path.shape = TEXEL_PATH2D_LINE;
    else if (tm_is(shape, "circle"))
      a.path.shape = TEXEL_PATH2D_CIRCLE;
    else if (tm_is(shape, "zigzag"))
      a.path.shape = TEXEL_PATH2D_ZIGZAG;
    else
      mexErrMsgIdAndTxt("texel:invalidArgument", "path '%s' is not one of line, circle, zigzag", shape);
    a.path.duration_s = a.has_duration ? a.duration_s : 2.0;
    tm_check(texel_path2d_simulate(&a.path, NULL, 0, &samples));
    trace = (texel_finger2d*)mxMalloc(samples * sizeof *trace);
    tm_check(texel_path2d_simulate(&a.path, trace, samples, NULL));
  } else {
    trace = trace_of(prhs[1], &samples);
  }
  if (!a.has_duration) a.duration_s = mxIsChar(prhs[1]) ? 2.0 : trace[samples - 1].t_s;
  frames_d = floor(a.duration_s * a.player.rate_hz + 0.5);
  if (!(a.duration_s > 0.0 && a.duration_s <= 86400.0) || !(frames_d >= 1.0 && frames_d <= 2e9))
    mexErrMsgIdAndTxt("texel:invalidArgument", "duration_s is %.17g; allowed > 0 … 86400 s with at least one output sample",
                      a.duration_s);
  frames = (size_t)frames_d;
  out = mxCreateNumericMatrix(frames, 1, mxSINGLE_CLASS, mxREAL);
  x = mxCreateNumericMatrix(frames, 1, mxSINGLE_CLASS, mxREAL);
  y = mxCreateNumericMatrix(frames, 1, mxSINGLE_CLASS, mxREAL);
  st = texel_document_load(path, &doc);
  if (st == TEXEL_OK)
    st = texel_swipe_2d(doc, trace, samples, a.mode, a.at_lift, &a.player, (float*)mxGetData(out), frames, (float*)mxGetData(x),
                        (float*)mxGetData(y));
  if (st != TEXEL_OK) tm_keep_error();
  texel_document_destroy(doc);
  if (st != TEXEL_OK) tm_raise(st);
  plhs[0] = out;
  if (nlhs > 1) plhs[1] = x;
  if (nlhs > 2) plhs[2] = y;
}
