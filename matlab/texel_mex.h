/* texel_mex.h — what the MEX functions share (docs/matlab.md).
 *
 * The MEX functions are thin front doors over the C ABI (texel.h): they read
 * MATLAB name/value pairs into the C structs, call libtexel, and return
 * arrays and structs whose field names carry their units. A failed call
 * becomes a MATLAB error whose identifier names the status ("texel:invalidArgument")
 * and whose message is libtexel's one line, the message the texel command
 * prints for the same mistake. Plain C over the MEX API that both MATLAB's
 * `mex` and Octave's `mkoctfile --mex` compile (mxGetPr, not the R2018a-only
 * typed accessors). Every function is static: each MEX file is one
 * translation unit that includes this header.
 *
 * Errors raised with mexErrMsgIdAndTxt leave the function at once (a long
 * jump), so every libtexel handle is destroyed before an error is raised;
 * mxArrays and mxMalloc memory are freed by MATLAB itself. */
#ifndef TEXEL_MEX_H
#define TEXEL_MEX_H

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mex.h"
#include "texel.h"

/* MATLAB error identifiers, one per status. */
static const char* tm_status_id(texel_status s) {
  switch (s) {
    case TEXEL_INVALID_ARGUMENT: return "texel:invalidArgument";
    case TEXEL_FORMAT_ERROR: return "texel:formatError";
    case TEXEL_IO_ERROR: return "texel:ioError";
    case TEXEL_BUFFER_TOO_SMALL: return "texel:bufferTooSmall";
    case TEXEL_OUT_OF_MEMORY: return "texel:outOfMemory";
    default: return "texel:internal";
  }
}

/* Raises libtexel's last error as a MATLAB error (the message is copied
 * first: the caller destroys its handles between the failed call and this). */
static char tm_message[1024];
static void tm_keep_error(void) { snprintf(tm_message, sizeof tm_message, "%s", texel_last_error()); }
static void tm_raise(texel_status s) { mexErrMsgIdAndTxt(tm_status_id(s), "%s", tm_message); }
/* For calls with no handle to clean up. */
static void tm_check(texel_status s) {
  if (s != TEXEL_OK) {
    tm_keep_error();
    tm_raise(s);
  }
}

static void tm_usage(const char* message) { mexErrMsgIdAndTxt("texel:invalidArgument", "%s", message); }

/* A char argument as a NUL-terminated string (mxFree'd by MATLAB on exit). */
static char* tm_text(const char* name, const mxArray* a) {
  char* s;
  if (!mxIsChar(a)) {
    mexErrMsgIdAndTxt("texel:invalidArgument", "%s must be text (char)", name);
  }
  s = mxArrayToString(a);
  if (!s) mexErrMsgIdAndTxt("texel:invalidArgument", "%s must be a char row", name);
  return s;
}

/* A real scalar. */
static double tm_scalar(const char* name, const mxArray* a) {
  if (!(mxIsNumeric(a) || mxIsLogical(a)) || mxIsComplex(a) || mxGetNumberOfElements(a) != 1)
    mexErrMsgIdAndTxt("texel:invalidArgument", "%s must be a real scalar", name);
  return mxGetScalar(a);
}

/* A non-negative integer (seeds, counts): uint64/int64 exactly, doubles when whole and below 2^53. */
static uint64_t tm_count(const char* name, const mxArray* a) {
  double v;
  if (mxGetNumberOfElements(a) == 1 && (mxIsUint64(a) || mxIsInt64(a)) && !mxIsComplex(a)) {
    uint64_t u;
    memcpy(&u, mxGetData(a), sizeof u);
    if (mxIsInt64(a) && (int64_t)u < 0) mexErrMsgIdAndTxt("texel:invalidArgument", "%s must be >= 0", name);
    return u;
  }
  v = tm_scalar(name, a);
  if (!(v >= 0.0 && v <= 9007199254740992.0) || floor(v) != v)
    mexErrMsgIdAndTxt("texel:invalidArgument", "%s is %.17g; allowed: a whole number 0 … 2^53 (pass uint64 for larger seeds)",
                      name, v);
  return (uint64_t)v;
}

/* A map given as an array, read as the library reads the same array from a
 * .npy file (docs/c-api.md "Input amplitudes"): double and single as they
 * are, uint16 as round(a·65535) (/65535: texel_render's 'u16'), int16 /32768.
 * uint8 is refused: texel_render's 'native' output is the device's bytes as
 * uint8 (two per sample on a 16-bit device), not amplitudes; so are the other
 * integer classes, which no Texel output produces. */
static double* tm_map(const char* name, const mxArray* a, size_t* count) {
  size_t n, i;
  double* out;
  const mxClassID c = mxGetClassID(a);
  if (!mxIsNumeric(a) || mxIsComplex(a) || mxIsSparse(a))
    mexErrMsgIdAndTxt("texel:invalidArgument", "%s must be a real numeric vector", name);
  if (c == mxUINT8_CLASS)
    mexErrMsgIdAndTxt("texel:invalidArgument",
                      "%s is uint8, which Texel reads as device bytes (texel_render's 'native' output), not amplitudes; "
                      "give amplitudes as double in [0, 1] (texel_render's default output) or uint16 (its 'u16' output)",
                      name);
  if (c != mxDOUBLE_CLASS && c != mxSINGLE_CLASS && c != mxUINT16_CLASS && c != mxINT16_CLASS)
    mexErrMsgIdAndTxt("texel:invalidArgument",
                      "%s is %s; allowed: double or single amplitudes, uint16 (/65535) or int16 (/32768)", name,
                      mxGetClassName(a));
  n = mxGetNumberOfElements(a);
  if (n > 0 && mxGetM(a) != 1 && mxGetN(a) != 1)
    mexErrMsgIdAndTxt("texel:invalidArgument", "%s must be a vector (N×1 or 1×N)", name);
  out = (double*)mxMalloc((n ? n : 1) * sizeof *out);
  if (c == mxDOUBLE_CLASS) {
    if (n) memcpy(out, mxGetPr(a), n * sizeof *out);
  } else {
    const void* d = mxGetData(a);
    for (i = 0; i < n; ++i) {
      if (c == mxSINGLE_CLASS)
        out[i] = ((const float*)d)[i];
      else if (c == mxUINT16_CLASS)
        out[i] = ((const uint16_t*)d)[i] / 65535.0;
      else
        out[i] = ((const int16_t*)d)[i] / 32768.0;
    }
  }
  *count = n;
  return out;
}

/* Case-insensitive equality of an option name. */
static int tm_is(const char* a, const char* b) {
  for (; *a && *b; ++a, ++b)
    if (tolower((unsigned char)*a) != tolower((unsigned char)*b)) return 0;
  return *a == *b;
}

/* Walks name/value pairs from prhs[first]: calls `take(name, value, ctx)`,
 * which returns 0 for a name it does not know. */
typedef int (*tm_take_fn)(const char* name, const mxArray* value, void* ctx);
static void tm_options(int nrhs, const mxArray* prhs[], int first, tm_take_fn take, void* ctx, const char* allowed) {
  int i;
  if ((nrhs - first) % 2 != 0) tm_usage("options come in name/value pairs");
  for (i = first; i < nrhs; i += 2) {
    char* name = tm_text("an option name", prhs[i]);
    if (!take(name, prhs[i + 1], ctx))
      mexErrMsgIdAndTxt("texel:invalidArgument", "unknown option '%s'; allowed: %s", name, allowed);
    mxFree(name);
  }
}

/* Parameterization names as the CLI spells them. */
static texel_parameterization tm_parameterization(const mxArray* a) {
  char* s = tm_text("parameterization", a);
  texel_parameterization p = TEXEL_PARAMETERIZATION_MOMENTS;
  if (tm_is(s, "log"))
    p = TEXEL_PARAMETERIZATION_LOG;
  else if (!tm_is(s, "moments"))
    mexErrMsgIdAndTxt("texel:invalidArgument", "parameterization '%s' is not one of moments, log", s);
  mxFree(s);
  return p;
}

/* The 1-D encoder's options every encoding function takes (texel_encode,
 * texel_encode2d): boundary_mm, texel_length_mm, parameterization, seed,
 * target. 1 if `name` is one of them (stored in *o), else 0. */
static int tm_take_encode_option(const char* name, const mxArray* v, texel_encode_options* o) {
  char* s;
  if (tm_is(name, "boundary_mm"))
    o->boundary_mm = tm_scalar(name, v);
  else if (tm_is(name, "texel_length_mm"))
    o->texel_length_mm = tm_scalar(name, v);
  else if (tm_is(name, "parameterization"))
    o->parameterization = tm_parameterization(v);
  else if (tm_is(name, "seed"))
    o->seed = tm_count(name, v);
  else if (tm_is(name, "target")) {
    s = tm_text(name, v);
    if (tm_is(s, "automatic"))
      o->target = TEXEL_TARGET_AUTOMATIC;
    else if (tm_is(s, "felt"))
      o->target = TEXEL_TARGET_FELT;
    else if (tm_is(s, "centroid"))
      o->target = TEXEL_TARGET_CENTROID;
    else
      mexErrMsgIdAndTxt("texel:invalidArgument", "target '%s' is not one of automatic, felt, centroid", s);
    mxFree(s);
  } else
    return 0;
  return 1;
}

static const char* tm_parameterization_name(texel_parameterization p) {
  return p == TEXEL_PARAMETERIZATION_LOG ? "log" : "moments";
}

/* Struct building: a 1×1 struct with no fields, then fields one by one. */
static mxArray* tm_struct(void) { return mxCreateStructMatrix(1, 1, 0, NULL); }
static void tm_set(mxArray* s, const char* field, mxArray* value) {
  int k = mxGetFieldNumber(s, field);
  if (k < 0) k = mxAddField(s, field);
  mxSetFieldByNumber(s, 0, k, value);
}
static void tm_set_scalar(mxArray* s, const char* field, double v) { tm_set(s, field, mxCreateDoubleScalar(v)); }
static void tm_set_text(mxArray* s, const char* field, const char* v) { tm_set(s, field, mxCreateString(v)); }
static mxArray* tm_uint64(uint64_t v) {
  mxArray* a = mxCreateNumericMatrix(1, 1, mxUINT64_CLASS, mxREAL);
  memcpy(mxGetData(a), &v, sizeof v);
  return a;
}

/* texel_params as a struct, the units in the field names (texel.h's names). */
static mxArray* tm_params_struct(const texel_params* p) {
  mxArray* s = tm_struct();
  tm_set_scalar(s, "central_pitch_db", p->central_pitch_db);
  tm_set_scalar(s, "irregularity_db", p->irregularity_db);
  tm_set_scalar(s, "texel_length_mm", p->texel_length_mm);
  tm_set(s, "seed", tm_uint64(p->seed));
  tm_set_text(s, "parameterization", tm_parameterization_name(p->parameterization));
  tm_set_scalar(s, "quantization_db", p->quantization_db);
  tm_set_scalar(s, "coarse_strength", p->coarse_strength);
  tm_set_scalar(s, "fine_strength", p->fine_strength);
  tm_set_scalar(s, "coarse_sine_period_mm", p->coarse_sine_period_mm);
  tm_set_scalar(s, "coarse_sine_phase_deg", p->coarse_sine_phase_deg);
  return s;
}

static const char* tm_format_name(texel_sample_format f) {
  switch (f) {
    case TEXEL_SAMPLE_U16LE: return "u16le";
    case TEXEL_SAMPLE_U8: return "u8";
    case TEXEL_SAMPLE_F32LE: return "f32le";
    case TEXEL_SAMPLE_F64LE: return "f64le";
  }
  return "unknown";
}

/* How a map is returned: amplitudes in [0, 1] (double), round(a·65535)
 * (uint16) or the device's own bytes, the .bin file (uint8). */
enum tm_output { TM_AMPLITUDE, TM_U16, TM_NATIVE };

static enum tm_output tm_output_of(const mxArray* a) {
  char* s = tm_text("output", a);
  enum tm_output o = TM_AMPLITUDE;
  if (tm_is(s, "u16"))
    o = TM_U16;
  else if (tm_is(s, "native"))
    o = TM_NATIVE;
  else if (!tm_is(s, "amplitude"))
    mexErrMsgIdAndTxt("texel:invalidArgument", "output '%s' is not one of amplitude, u16, native", s);
  mxFree(s);
  return o;
}

/* The options of every function that returns a map: device and output.
 * Returns 0 for another name. */
static int tm_take_map_option(const char* name, const mxArray* v, char** device, enum tm_output* output) {
  if (tm_is(name, "device"))
    *device = tm_text(name, v);
  else if (tm_is(name, "output"))
    *output = tm_output_of(v);
  else
    return 0;
  return 1;
}

/* Renders a document (taken over: destroyed here) into plhs[0] (the map) and,
 * when asked, plhs[1] (its device grid and the document's JSON). */
static void tm_render_document(texel_document* doc, const char* device_name, enum tm_output output, int nlhs, mxArray* plhs[]) {
  texel_surface* surface = NULL;
  texel_device_info info;
  size_t samples = 0, needed = 0, i;
  texel_status st = texel_surface_create(doc, &surface);
  mxArray* map = NULL;
  char* json = NULL;
  if (st == TEXEL_OK) st = texel_surface_device(surface, &info);
  if (st == TEXEL_OK) st = texel_surface_size(surface, &samples);
  if (st == TEXEL_OK && nlhs > 1) st = texel_document_json(doc, NULL, 0, &needed);
  if (st == TEXEL_OK && nlhs > 1) {
    json = (char*)mxMalloc(needed);
    st = texel_document_json(doc, json, needed, NULL);
  }
  if (st == TEXEL_OK) {
    switch (output) {
      case TM_AMPLITUDE:
        map = mxCreateDoubleMatrix(samples, 1, mxREAL);
        st = texel_surface_render(surface, 0, mxGetPr(map), samples);
        break;
      case TM_U16:
        map = mxCreateNumericMatrix(samples, 1, mxUINT16_CLASS, mxREAL);
        st = texel_surface_render_u16(surface, 0, (uint16_t*)mxGetData(map), samples);
        break;
      case TM_NATIVE:
        map = mxCreateNumericMatrix(samples * info.bytes_per_sample, 1, mxUINT8_CLASS, mxREAL);
        st = texel_surface_render_native(surface, 0, samples, mxGetData(map), samples * info.bytes_per_sample, NULL);
        break;
    }
  }
  if (st != TEXEL_OK) tm_keep_error();
  texel_surface_destroy(surface);
  texel_document_destroy(doc);
  if (st != TEXEL_OK) tm_raise(st);
  plhs[0] = map;
  if (nlhs > 1) {
    mxArray* s = tm_struct();
    mxArray* x = mxCreateDoubleMatrix(samples, 1, mxREAL);
    double* px = mxGetPr(x);
    for (i = 0; i < samples; ++i) px[i] = (double)i * info.spacing_mm;
    if (device_name) tm_set_text(s, "device", device_name);
    tm_set_scalar(s, "samples", (double)info.samples);
    tm_set_scalar(s, "spacing_mm", info.spacing_mm);
    tm_set_scalar(s, "length_mm", info.length_mm);
    tm_set_scalar(s, "refresh_hz", info.refresh_hz);
    tm_set_text(s, "format", tm_format_name(info.format));
    tm_set_scalar(s, "bytes_per_sample", (double)info.bytes_per_sample);
    tm_set(s, "position_mm", x);
    tm_set_text(s, "document", json);
    plhs[1] = s;
  }
}

#endif /* TEXEL_MEX_H */
