/* The C ABI's 2-D surfaces and encode target, as a C user meets them: a
 * plain C99 program compiled from an empty folder against texel.h and the
 * built libtexel (tests/capi/run_surface2d_program.cmake). It compares with
 * what the CLI wrote for the same document:
 *   surface2d_program DOC.texel.json CLI.npy CLI.png CLI_CIRCLE.wav OUT_DIR
 * CLI.npy: `texel render DOC --surface 2d -o CLI.npy`; CLI.png the same as
 * .png; CLI_CIRCLE.wav: `texel swipe DOC --path circle --radius 1 --start 2
 * --start-y 1.2 --speed 50 --duration 0.2 --wav-format float`.
 * Exit status 0 when every check holds; each failure prints one line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "texel.h"

#define PI 3.14159265358979323846

static int failures = 0;

#define CHECK(cond, ...)                                          \
  do {                                                            \
    if (!(cond)) {                                                \
      fprintf(stderr, "line %d: ", __LINE__);                     \
      fprintf(stderr, __VA_ARGS__);                               \
      fprintf(stderr, " (last error: %s)\n", texel_last_error()); \
      ++failures;                                                 \
    }                                                             \
  } while (0)

static unsigned char* read_file(const char* path, size_t* size) {
  FILE* f = fopen(path, "rb");
  unsigned char* data;
  long n;
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  n = ftell(f);
  fseek(f, 0, SEEK_SET);
  data = (unsigned char*)malloc((size_t)n + 1);
  if (data && fread(data, 1, (size_t)n, f) != (size_t)n) {
    free(data);
    data = NULL;
  }
  fclose(f);
  *size = (size_t)n;
  return data;
}

static unsigned le32(const unsigned char* p) { return p[0] | (p[1] << 8) | (p[2] << 16) | ((unsigned)p[3] << 24); }

/* The float samples of a WAV's data chunk (IEEE float, as --wav-format float writes). */
static const unsigned char* wav_data(const unsigned char* wav, size_t size, size_t* bytes) {
  size_t pos = 12;
  while (pos + 8 <= size) {
    unsigned n = le32(wav + pos + 4);
    if (memcmp(wav + pos, "data", 4) == 0) {
      *bytes = n;
      return wav + pos + 8;
    }
    pos += 8 + n + (n & 1);
  }
  return NULL;
}

static void ridges(double* a, size_t n, double dx) {
  size_t i;
  int k;
  double lo = 1e300, hi = -1e300;
  for (i = 0; i < n; ++i) {
    double x = (double)i * dx, y = sin(2 * PI * 2 * x) + 0.5 * sin(2 * PI * 4 * x + 1) + 0.25 * sin(2 * PI * 6 * x + 2);
    for (k = 0; k < 40; ++k) y += 0.05 * sin(2 * PI * (6.0 + 0.3 * k) * x + k); /* grit around 6 … 18 cpm */
    a[i] = y;
    if (y < lo) lo = y;
    if (y > hi) hi = y;
  }
  for (i = 0; i < n; ++i) a[i] = (a[i] - lo) / (hi - lo);
}

int main(int argc, char** argv) {
  texel_document *doc = NULL, *doc1d = NULL;
  texel_surface2d* s = NULL;
  texel_bitmap_info info;
  size_t n, size, bytes, i, needed = 0;
  double *whole, *strip;
  uint16_t* pixels;
  unsigned char *npy, *png, *mine, *wav;
  const unsigned char* expected;
  char path[4096];
  if (argc != 6) {
    fprintf(stderr, "usage: %s DOC CLI.npy CLI.png CLI_CIRCLE.wav OUT_DIR\n", argv[0]);
    return 2;
  }

  /* ------------------------------------------------ rendering to buffers */
  CHECK(texel_document_load(argv[1], &doc) == TEXEL_OK, "load %s", argv[1]);
  CHECK(texel_surface2d_create(doc, &s) == TEXEL_OK, "surface2d_create");
  if (failures) return 1;
  CHECK(texel_surface2d_info(s, &info) == TEXEL_OK && info.width_px == 80 && info.height_px == 48 &&
            info.pixel_pitch_mm == 0.05 && info.depth_bits == 16 && info.polarity == TEXEL_DARKER_MORE_FRICTION,
        "info %d x %d", info.width_px, info.height_px);
  n = (size_t)info.width_px * (size_t)info.height_px;
  whole = (double*)malloc(n * sizeof *whole);
  strip = (double*)malloc(n * sizeof *strip);
  pixels = (uint16_t*)malloc(n * sizeof *pixels);
  CHECK(texel_surface2d_render_rows(s, 0, info.height_px, whole, n) == TEXEL_OK, "render_rows whole");
  /* Strips of 7 rows (the last one shorter) give the whole map's values. */
  for (i = 0; i < (size_t)info.height_px; i += 7) {
    int rows = info.height_px - (int)i < 7 ? info.height_px - (int)i : 7;
    CHECK(texel_surface2d_render_rows(s, (int)i, rows, strip + i * (size_t)info.width_px, (size_t)rows * (size_t)info.width_px) ==
              TEXEL_OK,
          "render_rows strip at %u", (unsigned)i);
  }
  CHECK(memcmp(whole, strip, n * sizeof *whole) == 0, "strips differ from the whole bitmap");
  /* The CLI's .npy: a header, then the same float64 values. */
  npy = read_file(argv[2], &size);
  CHECK(npy && size >= n * 8 && memcmp(npy + size - n * 8, whole, n * 8) == 0, "amplitudes differ from %s", argv[2]);
  CHECK(texel_surface2d_render_pixels(s, 0, info.height_px, 0, pixels, n) == TEXEL_OK, "render_pixels");
  for (i = 0; i < n; ++i)
    if (pixels[i] != (uint16_t)(whole[i] * 65535.0 + 0.5)) break;
  CHECK(i == n, "pixel %u is %u, amplitude %.17g", (unsigned)i, i < n ? pixels[i] : 0, i < n ? whole[i] : 0.0);
  /* A PNG written through the library is the CLI's, byte for byte. */
  sprintf(path, "%s/c.png", argv[5]);
  CHECK(texel_surface2d_write(s, path, 0) == TEXEL_OK, "write %s", path);
  png = read_file(argv[3], &size);
  mine = read_file(path, &bytes);
  CHECK(png && mine && size == bytes && memcmp(png, mine, size) == 0, "%s differs from %s", path, argv[3]);

  /* ------------------------------------------------------------- errors */
  CHECK(texel_surface2d_render_rows(s, 40, 9, whole, 9 * 80) == TEXEL_INVALID_ARGUMENT &&
            strstr(texel_last_error(), "first_row 40 and rows 9"),
        "rows past the end");
  CHECK(texel_surface2d_render_rows(s, 0, 2, whole, 100) == TEXEL_INVALID_ARGUMENT && strstr(texel_last_error(), "count is 100"),
        "wrong count");
  CHECK(texel_surface2d_render_pixels(s, 0, 1, 12, pixels, 80) == TEXEL_INVALID_ARGUMENT &&
            strstr(texel_last_error(), "depth_bits is 12"),
        "bad depth");
  sprintf(path, "%s/c.bmp", argv[5]);
  CHECK(texel_surface2d_write(s, path, 0) == TEXEL_INVALID_ARGUMENT && !fopen(path, "rb"), "a .bmp is refused, none left");
  {
    texel_params p = texel_params_default();
    texel_surface2d* none = (texel_surface2d*)&p;
    CHECK(texel_document_from_params("tpad", &p, &doc1d) == TEXEL_OK, "1-D document");
    CHECK(texel_surface2d_create(doc1d, &none) == TEXEL_INVALID_ARGUMENT && none == NULL &&
              strstr(texel_last_error(), "not a 2-D document"),
          "a 1-D document has no 2-D surface");
  }

  /* ------------------------------------------------------ 2-D swipes */
  {
    texel_path2d_config pc = texel_path2d_config_default();
    texel_player_config config = texel_player_config_default();
    texel_finger2d* trace;
    float *out, *x, *y;
    const size_t frames = 9600; /* 0.2 s at 48 kHz */
    pc.shape = TEXEL_PATH2D_CIRCLE;
    pc.radius_mm = 1;
    pc.start_x_mm = 2;
    pc.start_y_mm = 1.2;
    pc.speed_mm_s = 50;
    pc.duration_s = 0.2;
    CHECK(texel_path2d_simulate(&pc, NULL, 0, &needed) == TEXEL_OK && needed == 202, "path size %u", (unsigned)needed);
    trace = (texel_finger2d*)malloc(needed * sizeof *trace);
    CHECK(texel_path2d_simulate(&pc, trace, needed - 1, &n) == TEXEL_BUFFER_TOO_SMALL && n == needed, "short buffer");
    CHECK(texel_path2d_simulate(&pc, trace, needed, NULL) == TEXEL_OK && trace[0].x_mm == 3.0 && trace[needed - 1].touch == 0,
          "path samples");
    out = (float*)malloc(frames * sizeof *out);
    x = (float*)malloc(frames * sizeof *x);
    y = (float*)malloc(frames * sizeof *y);
    config.mode = TEXEL_OUTPUT_VIBRATION; /* as texel swipe's default */
    CHECK(texel_swipe_2d(doc, trace, needed, TEXEL_MAP2D_PATH, TEXEL_PATH_KEEP, &config, out, frames, x, y) == TEXEL_OK,
          "swipe_2d");
    wav = read_file(argv[4], &size);
    expected = wav ? wav_data(wav, size, &bytes) : NULL;
    CHECK(expected && bytes == frames * 4 && memcmp(expected, out, bytes) == 0, "swipe differs from %s", argv[4]);
    CHECK(fabsf(x[0] - 3.0f) < 1e-6f && fabsf(y[0] - 1.2f) < 1e-6f, "first position (%g, %g)", x[0], y[0]);
    CHECK(
        texel_swipe_2d(doc, trace, needed, TEXEL_MAP2D_BITMAP, TEXEL_PATH_RESET, &config, out, frames, NULL, NULL) == TEXEL_OK &&
            memcmp(expected, out, bytes) != 0,
        "bitmap mode plays the bitmap");
    CHECK(texel_swipe_2d(doc, trace, needed, (texel_map2d_mode)5, TEXEL_PATH_KEEP, &config, out, frames, NULL, NULL) ==
                  TEXEL_INVALID_ARGUMENT &&
              strstr(texel_last_error(), "mode is 5"),
          "bad mode");
    CHECK(texel_swipe_2d(doc, trace, needed, TEXEL_MAP2D_PATH, (texel_path_at_lift)2, &config, out, frames, NULL, NULL) ==
                  TEXEL_INVALID_ARGUMENT &&
              strstr(texel_last_error(), "at_lift is 2"),
          "bad at_lift");
    trace[5].t_s = 0.0;
    CHECK(texel_swipe_2d(doc, trace, needed, TEXEL_MAP2D_PATH, TEXEL_PATH_KEEP, &config, out, frames, NULL, NULL) ==
                  TEXEL_INVALID_ARGUMENT &&
              strstr(texel_last_error(), "trace[5].t_s"),
          "times going back");
    pc.shape = (texel_path2d_shape)3;
    CHECK(texel_path2d_simulate(&pc, NULL, 0, &needed) == TEXEL_INVALID_ARGUMENT && strstr(texel_last_error(), "shape is 3"),
          "bad shape");
    free(trace), free(out), free(x), free(y);
  }

  /* ------------------------------------------------------ encode target */
  {
    enum { count = 8192 };
    static double a[count];
    texel_encode_options o = texel_encode_options_default();
    texel_encode_result *felt = NULL, *centroid = NULL, *bad = NULL;
    texel_params pf, pc;
    texel_encode_flags ff, fc;
    ridges(a, count, 0.01);
    CHECK(o.target == TEXEL_TARGET_AUTOMATIC, "default target");
    CHECK(texel_encode_with(a, count, 0.01, &o, &felt) == TEXEL_OK, "encode automatic");
    o.target = TEXEL_TARGET_CENTROID;
    CHECK(texel_encode_with(a, count, 0.01, &o, &centroid) == TEXEL_OK, "encode centroid");
    CHECK(texel_encode_result_params(felt, &pf, NULL) == TEXEL_OK && texel_encode_result_params(centroid, &pc, NULL) == TEXEL_OK,
          "params");
    CHECK(texel_encode_result_flags(felt, &ff) == TEXEL_OK && ff.target == TEXEL_TARGET_FELT, "a map's automatic target is felt");
    CHECK(texel_encode_result_flags(centroid, &fc) == TEXEL_OK && fc.target == TEXEL_TARGET_CENTROID, "centroid target");
    CHECK(pc.central_pitch_db > pf.central_pitch_db + 1.0, "centroid %.2f dB vs felt %.2f dB", pc.central_pitch_db,
          pf.central_pitch_db);
    printf("encode target: felt %.2f dB, centroid %.2f dB\n", pf.central_pitch_db, pc.central_pitch_db);
    o.target = (texel_encode_target)7;
    CHECK(texel_encode_with(a, count, 0.01, &o, &bad) == TEXEL_INVALID_ARGUMENT && bad == NULL &&
              strstr(texel_last_error(), "target is 7; allowed: TEXEL_TARGET_AUTOMATIC (0)"),
          "bad target");
    texel_encode_result_destroy(felt);
    texel_encode_result_destroy(centroid);
  }

  /* ------------------------------------------------------ 2-D encoding */
  {
    enum { side = 400 }; /* 20 mm at 0.05 mm: 1024 samples along every direction */
    static double map[side * side];
    texel_encode2d_options o2 = texel_encode2d_options_default();
    texel_encode2d_result *r = NULL, *bad = NULL;
    texel_document* encoded = NULL;
    texel_surface2d* es = NULL;
    texel_bitmap_info ei;
    char* json;
    int j, k;
    FILE* saved;
    for (j = 0; j < side; ++j)
      for (k = 0; k < side; ++k) {
        const double x = k * 0.05, y = j * 0.05;
        map[j * side + k] = 0.5 + 0.25 * sin(2 * PI * (2 * x + y)) + 0.25 * sin(2 * PI * (-1.5 * x + 2.5 * y));
      }
    CHECK(o2.directions == 18 && o2.scan_samples == 16384 && o2.correction_rounds == 1, "2-D encoder defaults");
    o2.directions = 4; /* cheap: the encoder's own tests measure its accuracy */
    o2.scan_samples = 1024;
    o2.correction_rounds = 0;
    CHECK(texel_encode_2d(map, side, side, 0.05, NULL, &o2, &r) == TEXEL_OK, "encode_2d");
    CHECK(texel_encode2d_result_json(r, NULL, 0, &needed) == TEXEL_OK && needed > 1, "json size");
    json = (char*)malloc(needed);
    CHECK(texel_encode2d_result_json(r, json, needed, NULL) == TEXEL_OK && strstr(json, "\"central_pitch_db\"") &&
              strlen(json) + 1 == needed,
          "json");
    CHECK(texel_encode2d_result_document(r, &encoded) == TEXEL_OK && texel_surface2d_create(encoded, &es) == TEXEL_OK &&
              texel_surface2d_info(es, &ei) == TEXEL_OK && ei.width_px == side && ei.height_px == side,
          "the encoded document is a 2-D surface of the map's size");
    sprintf(path, "%s/encoded.texel.json", argv[5]);
    CHECK(texel_encode2d_result_save(r, path) == TEXEL_OK && (saved = fopen(path, "rb")) != NULL && fclose(saved) == 0, "save %s",
          path);
    /* The same map as a .npy file (float64, C order) encodes to the same result. */
    sprintf(path, "%s/map.npy", argv[5]);
    {
      static const char magic[] = "\x93NUMPY\x01\x00";
      char header[128];
      int len = sprintf(header, "{'descr': '<f8', 'fortran_order': False, 'shape': (%d, %d), }", side, side);
      texel_encode2d_result* from_file = NULL;
      char* file_json;
      size_t file_needed = 0;
      FILE* f = fopen(path, "wb");
      while ((10 + len + 1) % 64 != 0) header[len++] = ' ';
      header[len++] = '\n';
      CHECK(f && fwrite(magic, 1, 8, f) == 8 && fputc(len & 0xff, f) != EOF && fputc(len >> 8, f) != EOF &&
                fwrite(header, 1, (size_t)len, f) == (size_t)len && fwrite(map, sizeof map[0], side * side, f) == side * side &&
                fclose(f) == 0,
            "write %s", path);
      CHECK(texel_encode_2d_file(path, 0.05, NULL, -1, 0.0, NULL, &o2, &from_file) == TEXEL_OK &&
                texel_encode2d_result_json(from_file, NULL, 0, &file_needed) == TEXEL_OK,
            "encode_2d_file %s", path);
      file_json = (char*)malloc(file_needed ? file_needed : 1);
      CHECK(file_needed == needed && texel_encode2d_result_json(from_file, file_json, file_needed, NULL) == TEXEL_OK &&
                strcmp(file_json, json) == 0,
            "encoding %s differs from encoding the same map in memory", path);
      free(file_json);
      texel_encode2d_result_destroy(from_file);
      CHECK(texel_encode_2d_file(path, 0.05, NULL, 7, 0.0, NULL, &o2, &bad) == TEXEL_INVALID_ARGUMENT && bad == NULL &&
                strstr(texel_last_error(), "polarity is 7"),
            "a polarity outside the enumeration");
      CHECK(texel_encode_2d_file(path, 0.0, NULL, -1, 0.0, NULL, &o2, &bad) == TEXEL_INVALID_ARGUMENT &&
                strstr(texel_last_error(), "pixel pitch"),
            "a .npy without a pitch");
      CHECK(texel_encode_2d_file(argv[4], 0.05, NULL, -1, 0.0, NULL, &o2, &bad) == TEXEL_INVALID_ARGUMENT &&
                strstr(texel_last_error(), "is not a 2-D input"),
            "a WAV is not a 2-D input");
    }
    CHECK(texel_encode_2d(map, side, 0, 0.05, NULL, &o2, &bad) == TEXEL_INVALID_ARGUMENT && bad == NULL &&
              strstr(texel_last_error(), "height_px"),
          "an empty map");
    /* The one input rule: a value outside [0, 1] scales the map to full range (never refused or clamped); a
       non-finite one is refused, naming the argument. */
    map[7] = 1.5;
    CHECK(texel_encode_2d(map, side, side, 0.05, NULL, &o2, &bad) == TEXEL_OK && bad != NULL, "a map outside [0, 1]");
    texel_encode2d_result_destroy(bad);
    bad = NULL;
    map[7] = NAN;
    CHECK(texel_encode_2d(map, side, side, 0.05, NULL, &o2, &bad) == TEXEL_INVALID_ARGUMENT && bad == NULL &&
              strstr(texel_last_error(), "'amplitudes' holds a non-finite value"),
          "a non-finite value");
    printf("encode_2d: %s\n", json);
    free(json);
    texel_surface2d_destroy(es);
    texel_document_destroy(encoded);
    texel_encode2d_result_destroy(r);
  }

  texel_surface2d_destroy(s);
  texel_document_destroy(doc);
  texel_document_destroy(doc1d);
  free(whole), free(strip), free(pixels), free(npy), free(png), free(mine), free(wav);
  if (failures == 0) printf("2-D surfaces and encode target: every check passed\n");
  return failures == 0 ? 0 : 1;
}
