/* texel.h from plain C99 (-Wall -Wextra -Werror -pedantic): the header
 * compiles as C, links against the C++ library, and every function answers
 * valid and invalid arguments with the documented status. Prints one line
 * per failed check; exit status 1 if any failed. */
#include "texel.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures = 0;

#define CHECK(cond)                                                                              \
  do {                                                                                           \
    if (!(cond)) {                                                                               \
      ++failures;                                                                                \
      fprintf(stderr, "%s:%d: CHECK failed: %s (last error: %s)\n", __FILE__, __LINE__, #cond, \
              texel_last_error());                                                               \
    }                                                                                            \
  } while (0)

#define CHECK_STATUS(call, expected) CHECK((call) == (expected))

static void test_basics(void) {
  int major = -1, minor = -1, patch = -1;
  char text[32];
  texel_version(&major, &minor, &patch);
  CHECK(major == TEXEL_VERSION_MAJOR && minor == TEXEL_VERSION_MINOR && patch == TEXEL_VERSION_PATCH);
  sprintf(text, "%d.%d.%d", major, minor, patch);
  CHECK(strcmp(texel_version_string(), text) == 0);
  texel_version(NULL, NULL, NULL);
  CHECK(strcmp(texel_status_string(TEXEL_OK), "TEXEL_OK") == 0);
  CHECK(strcmp(texel_status_string(TEXEL_BUFFER_TOO_SMALL), "TEXEL_BUFFER_TOO_SMALL") == 0);
  CHECK(strcmp(texel_status_string((texel_status)42), "unknown status") == 0);
  CHECK(texel_last_error() != NULL);
}

static void test_devices(void) {
  texel_device_info info;
  CHECK_STATUS(texel_device_lookup("tpad", &info), TEXEL_OK);
  CHECK(info.samples == 19200 && info.format == TEXEL_SAMPLE_U16LE && info.bytes_per_sample == 2);
  CHECK(strcmp(texel_last_error(), "") == 0);
  CHECK_STATUS(texel_device_lookup("no-such-device", &info), TEXEL_INVALID_ARGUMENT);
  CHECK(strstr(texel_last_error(), "no-such-device") != NULL);
  CHECK_STATUS(texel_device_lookup(NULL, &info), TEXEL_INVALID_ARGUMENT);
  CHECK_STATUS(texel_device_lookup("tpad", NULL), TEXEL_INVALID_ARGUMENT);
}

static void test_documents_and_surfaces(void) {
  texel_params p = texel_params_default();
  texel_document* doc = NULL;
  texel_surface* surface = NULL;
  size_t n = 0, needed = 0, i;
  double* amplitudes;
  uint16_t* u16;
  unsigned char* bytes;
  char* json;
  const char* bad_json = "{ \"format\": ";

  CHECK(p.central_pitch_db == 10.0 && p.irregularity_db == -5.0 && p.texel_length_mm == 0.25 && p.seed == 1);
  p.seed = 7;
  CHECK_STATUS(texel_document_from_params("tpad", &p, &doc), TEXEL_OK);
  CHECK_STATUS(texel_surface_create(doc, &surface), TEXEL_OK);
  CHECK_STATUS(texel_surface_size(surface, &n), TEXEL_OK);
  CHECK(n == 19200);

  amplitudes = malloc(n * sizeof *amplitudes);
  u16 = malloc(n * sizeof *u16);
  bytes = malloc(2 * n);
  CHECK_STATUS(texel_surface_render(surface, 0, amplitudes, n), TEXEL_OK);
  CHECK_STATUS(texel_surface_render_u16(surface, 0, u16, n), TEXEL_OK);
  CHECK_STATUS(texel_surface_render_native(surface, 0, n, NULL, 0, &needed), TEXEL_OK);
  CHECK(needed == 2 * n);
  CHECK_STATUS(texel_surface_render_native(surface, 0, n, bytes, 2 * n - 1, &needed), TEXEL_BUFFER_TOO_SMALL);
  CHECK_STATUS(texel_surface_render_native(surface, 0, n, bytes, 2 * n, NULL), TEXEL_OK);
  for (i = 0; i < n; ++i) {
    const double a = amplitudes[i];
    if (!(a >= 0.0 && a <= 1.0) || u16[i] != (uint16_t)(a * 65535.0 + 0.5) ||
        u16[i] != (uint16_t)(bytes[2 * i] | (bytes[2 * i + 1] << 8))) {
      CHECK(!"amplitude, u16 and device bytes agree");
      break;
    }
  }
  /* A window equals the same samples of the whole map. */
  {
    double window[100];
    CHECK_STATUS(texel_surface_render(surface, 9000, window, 100), TEXEL_OK);
    CHECK(memcmp(window, amplitudes + 9000, sizeof window) == 0);
    CHECK_STATUS(texel_surface_render(surface, 19150, window, 100), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_surface_render(surface, -1, window, 1), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_surface_render(NULL, 0, window, 1), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_surface_render(surface, 0, NULL, 1), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_surface_render_u16(NULL, 0, u16, 1), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_surface_render_native(NULL, 0, 1, bytes, 2, NULL), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_surface_render_native(surface, 0, 1, NULL, 0, NULL), TEXEL_INVALID_ARGUMENT);
  }

  /* JSON round trip: query, too small, fill, parse. */
  CHECK_STATUS(texel_document_json(doc, NULL, 0, &needed), TEXEL_OK);
  json = malloc(needed);
  CHECK_STATUS(texel_document_json(doc, json, needed - 1, NULL), TEXEL_BUFFER_TOO_SMALL);
  CHECK_STATUS(texel_document_json(doc, json, needed, NULL), TEXEL_OK);
  CHECK(strlen(json) + 1 == needed);
  {
    texel_document* again = NULL;
    texel_surface* s2 = NULL;
    double a0 = -1.0;
    CHECK_STATUS(texel_document_parse(json, strlen(json), &again), TEXEL_OK);
    CHECK_STATUS(texel_surface_create(again, &s2), TEXEL_OK);
    CHECK_STATUS(texel_surface_render(s2, 123, &a0, 1), TEXEL_OK);
    CHECK(a0 == amplitudes[123]);
    texel_surface_destroy(s2);
    texel_document_destroy(again);
  }
  free(json);

  /* Bad input. */
  {
    texel_document* d = (texel_document*)&p;
    texel_surface* s = (texel_surface*)&p;
    texel_params q = texel_params_default();
    CHECK_STATUS(texel_document_parse(bad_json, strlen(bad_json), &d), TEXEL_FORMAT_ERROR);
    CHECK(d == NULL);
    CHECK_STATUS(texel_document_parse(NULL, 0, &d), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_document_load("/nonexistent/x.texel.json", &d), TEXEL_IO_ERROR);
    CHECK(strstr(texel_last_error(), "/nonexistent/x.texel.json") != NULL);
    CHECK_STATUS(texel_document_load(NULL, &d), TEXEL_INVALID_ARGUMENT);
    q.central_pitch_db = NAN;
    CHECK_STATUS(texel_surface_from_params("tpad", &q, &s), TEXEL_INVALID_ARGUMENT);
    CHECK(s == NULL && strstr(texel_last_error(), "central_pitch_db") != NULL);
    q = texel_params_default();
    q.parameterization = (texel_parameterization)5;
    CHECK_STATUS(texel_document_from_params("tpad", &q, &d), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_document_from_params("tpad", NULL, &d), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_document_from_params("tpad", &q, NULL), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_surface_create(NULL, &s), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_surface_size(NULL, &n), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_surface_device(surface, NULL), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_document_json(NULL, NULL, 0, &needed), TEXEL_INVALID_ARGUMENT);
  }

  /* A reference by name. */
  {
    texel_document* ref = NULL;
    CHECK_STATUS(texel_document_from_reference("tpad", "4sin", 1, &ref), TEXEL_OK);
    texel_document_destroy(ref);
    CHECK_STATUS(texel_document_from_reference("tpad", "no-such", 1, &ref), TEXEL_INVALID_ARGUMENT);
    CHECK(ref == NULL);
  }

  /* Encode the map, decode it on tpad. */
  {
    texel_device_info info;
    texel_encode_result* r = NULL;
    texel_document* decoded = NULL;
    texel_params got;
    uint8_t stream[256];
    double jnd = -1.0;
    int has_profile = -1;
    CHECK_STATUS(texel_surface_device(surface, &info), TEXEL_OK);
    CHECK_STATUS(texel_encode(amplitudes, n, info.spacing_mm, &r), TEXEL_OK);
    CHECK_STATUS(texel_encode_result_bytes(r, NULL, 0, &needed), TEXEL_OK);
    CHECK(needed > 0 && needed <= sizeof stream);
    CHECK_STATUS(texel_encode_result_bytes(r, stream, 1, NULL), TEXEL_BUFFER_TOO_SMALL);
    CHECK_STATUS(texel_encode_result_bytes(r, stream, sizeof stream, &needed), TEXEL_OK);
    CHECK_STATUS(texel_encode_result_params(r, &got, &has_profile), TEXEL_OK);
    CHECK(fabs(got.central_pitch_db - 10.0) < 0.5 && has_profile == 0);
    CHECK_STATUS(texel_encode_result_distance(r, &jnd), TEXEL_OK);
    CHECK(jnd >= 0.0);
    CHECK_STATUS(texel_decode(stream, needed, "tpad", &decoded), TEXEL_OK);
    texel_document_destroy(decoded);
    stream[0] ^= 0xFF;
    CHECK_STATUS(texel_decode(stream, needed, "tpad", &decoded), TEXEL_FORMAT_ERROR);
    CHECK(decoded == NULL);
    texel_encode_result_destroy(r);
    CHECK_STATUS(texel_encode(amplitudes, 10, info.spacing_mm, &r), TEXEL_INVALID_ARGUMENT);
    CHECK(r == NULL);
    CHECK_STATUS(texel_encode_result_bytes(NULL, stream, sizeof stream, NULL), TEXEL_INVALID_ARGUMENT);
    CHECK_STATUS(texel_encode(amplitudes, n, NAN, &r), TEXEL_INVALID_ARGUMENT);
    {
      texel_encode_options options = texel_encode_options_default();
      options.seed = 5;
      CHECK_STATUS(texel_encode_with(amplitudes, n, info.spacing_mm, &options, &r), TEXEL_OK);
      CHECK_STATUS(texel_encode_result_params(r, &got, NULL), TEXEL_OK);
      CHECK(got.seed == 5);
      texel_encode_result_destroy(r);
      options.coarse_bits = 0;
      CHECK_STATUS(texel_encode_with(amplitudes, n, info.spacing_mm, &options, &r), TEXEL_INVALID_ARGUMENT);
      CHECK(r == NULL);
      CHECK_STATUS(texel_encode_file("/nonexistent/map.npy", NULL, 0.0, NULL, &r), TEXEL_IO_ERROR);
    }
  }

  free(bytes);
  free(u16);
  free(amplitudes);
  texel_surface_destroy(surface);
  texel_document_destroy(doc);
}

static void test_player(void) {
  texel_player_config c = texel_player_config_default();
  texel_player* player = NULL;
  texel_surface* surface = NULL;
  texel_params p = texel_params_default();
  float out[128], pos[128];
  float peak = 0.0f;
  int i;
  size_t freed = 0;

  c.rate_hz = 8333.0;
  CHECK_STATUS(texel_player_create(&c, &player), TEXEL_OK);
  CHECK_STATUS(texel_surface_from_params("tpad", &p, &surface), TEXEL_OK);
  CHECK_STATUS(texel_player_set_surface(player, surface), TEXEL_OK);
  texel_surface_destroy(surface); /* the player keeps its own map */
  for (i = 0; i <= 100; ++i) CHECK_STATUS(texel_player_push(player, i * 0.001, 10.0 + i * 0.1, 1), TEXEL_OK);
  for (i = 0; i < 4; ++i) {
    int k;
    CHECK_STATUS(texel_player_process(player, out, 128, pos), TEXEL_OK);
    for (k = 0; k < 128; ++k)
      if (out[k] > peak) peak = out[k];
  }
  CHECK(peak > 0.5f && peak <= 1.0f);
  CHECK(texel_player_samples(player) == 512);
  CHECK_STATUS(texel_player_set_gain(player, 0.25), TEXEL_OK);
  CHECK_STATUS(texel_player_collect(player, &freed), TEXEL_OK);

  CHECK_STATUS(texel_player_push(player, NAN, 0.0, 1), TEXEL_INVALID_ARGUMENT);
  CHECK_STATUS(texel_player_push(NULL, 0.0, 0.0, 1), TEXEL_INVALID_ARGUMENT);
  CHECK_STATUS(texel_player_set_gain(player, NAN), TEXEL_INVALID_ARGUMENT);
  CHECK_STATUS(texel_player_set_surface(player, NULL), TEXEL_INVALID_ARGUMENT);
  CHECK_STATUS(texel_player_process(NULL, out, 128, NULL), TEXEL_INVALID_ARGUMENT);
  CHECK_STATUS(texel_player_process(player, NULL, 128, NULL), TEXEL_INVALID_ARGUMENT);
  CHECK_STATUS(texel_player_collect(NULL, NULL), TEXEL_INVALID_ARGUMENT);
  texel_player_destroy(player);

  c.mode = (texel_output_mode)9;
  player = (texel_player*)&c;
  CHECK_STATUS(texel_player_create(&c, &player), TEXEL_INVALID_ARGUMENT);
  CHECK(player == NULL && strstr(texel_last_error(), "mode") != NULL);
  c = texel_player_config_default();
  c.rate_hz = NAN;
  CHECK_STATUS(texel_player_create(&c, &player), TEXEL_INVALID_ARGUMENT);
  CHECK_STATUS(texel_player_create(NULL, &player), TEXEL_INVALID_ARGUMENT);
  /* The response fields appended after 0.1.0: defaults, OFF, bad values. */
  c = texel_player_config_default();
  CHECK(c.response_handling == TEXEL_RESPONSE_LIMIT && c.response_limit_db == 20.0);
  c.response_handling = TEXEL_RESPONSE_OFF;
  CHECK_STATUS(texel_player_create(&c, &player), TEXEL_OK);
  texel_player_destroy(player);
  c.response_handling = (texel_response_handling)5;
  CHECK_STATUS(texel_player_create(&c, &player), TEXEL_INVALID_ARGUMENT);
  CHECK(player == NULL && strstr(texel_last_error(), "response_handling") != NULL);
  c = texel_player_config_default();
  c.response_limit_db = 100.0;
  CHECK_STATUS(texel_player_create(&c, &player), TEXEL_INVALID_ARGUMENT);
  CHECK(player == NULL && strstr(texel_last_error(), "response_limit_db") != NULL);
}

int main(void) {
  test_basics();
  test_devices();
  test_documents_and_surfaces();
  test_player();
  texel_document_destroy(NULL);
  texel_surface_destroy(NULL);
  texel_encode_result_destroy(NULL);
  texel_player_destroy(NULL);
  if (failures) {
    fprintf(stderr, "%d check(s) failed\n", failures);
    return 1;
  }
  printf("texel.h from C99: all checks passed\n");
  return 0;
}
