/* Render a Texel texture for the TPaD in a few lines of C and write the
 * device file: the same bytes as
 *   texel render --central-pitch 10 --irregularity -5 --texel-length 0.25 --seed 7 -o map.bin
 * Usage: render [OUTPUT]   (default map.bin) */
#include <stdio.h>
#include <stdlib.h>

#include "texel.h"

int main(int argc, char** argv) {
  const char* path = argc > 1 ? argv[1] : "map.bin";
  texel_params params = texel_params_default();
  texel_surface* surface = NULL;
  uint16_t* map = NULL;
  size_t samples = 0;
  texel_status status;
  FILE* f;
  int ok;

  params.central_pitch_db = 10.0; /* dB re 1 cycle/mm */
  params.irregularity_db = -5.0;
  params.texel_length_mm = 0.25;
  params.seed = 7;
  status = texel_surface_from_params("tpad", &params, &surface);
  if (status == TEXEL_OK) status = texel_surface_size(surface, &samples);
  if (status == TEXEL_OK) {
    map = malloc(samples * sizeof *map); /* caller-owned memory */
    status = map ? texel_surface_render_u16(surface, 0, map, samples) : TEXEL_OUT_OF_MEMORY;
  }
  texel_surface_destroy(surface);
  if (status != TEXEL_OK) {
    fprintf(stderr, "render: %s: %s\n", texel_status_string(status), texel_last_error());
    free(map);
    return 2;
  }
  /* uint16 in host order: the tpad .bin format on a little-endian host. */
  f = fopen(path, "wb");
  ok = f && fwrite(map, sizeof *map, samples, f) == samples;
  if (f && fclose(f) != 0) ok = 0;
  free(map);
  if (!ok) {
    fprintf(stderr, "render: cannot write %s\n", path);
    if (f) remove(path); /* never leave a half-written map */
    return 1;
  }
  printf("%s: %zu samples\n", path, samples);
  return 0;
}
