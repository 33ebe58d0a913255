/* The same map as main.cpp through the C ABI (texel.h), from plain C99.
 * Usage: consumer_c OUTPUT */
#include <stdio.h>
#include <stdlib.h>

#include "texel.h"

int main(int argc, char** argv) {
  texel_params params = texel_params_default();
  texel_surface* surface = NULL;
  uint16_t* map = NULL;
  size_t samples = 0;
  texel_status status;
  FILE* f;
  int ok;

  if (argc != 2) {
    fprintf(stderr, "usage: consumer_c OUTPUT\n");
    return 2;
  }
  params.central_pitch_db = 10.0;
  params.irregularity_db = -5.0;
  params.texel_length_mm = 0.25;
  params.seed = 7;
  status = texel_surface_from_params("tpad", &params, &surface);
  if (status == TEXEL_OK) status = texel_surface_size(surface, &samples);
  if (status == TEXEL_OK) {
    map = malloc(samples * sizeof *map);
    status = map ? texel_surface_render_u16(surface, 0, map, samples) : TEXEL_OUT_OF_MEMORY;
  }
  texel_surface_destroy(surface);
  if (status != TEXEL_OK) {
    fprintf(stderr, "consumer_c: %s: %s\n", texel_status_string(status), texel_last_error());
    free(map);
    return 1;
  }
  f = fopen(argv[1], "wb");
  ok = f && fwrite(map, sizeof *map, samples, f) == samples;
  if (f && fclose(f) != 0) ok = 0;
  free(map);
  if (!ok) {
    fprintf(stderr, "consumer_c: cannot write %s\n", argv[1]);
    if (f) remove(argv[1]);
    return 1;
  }
  printf("%s: %zu samples (texel %s)\n", argv[1], samples, texel_version_string());
  return 0;
}
