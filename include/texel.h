/* texel.h — the C ABI of Texel, for device makers embedding C.
 *
 * A thin front door over the C++ library (docs/c-api.md): every function calls
 * the same library code as the `texel` command, so a map rendered here is the
 * same bytes as `texel render ... -o map.bin`. Style after miniaudio: opaque
 * handles, a status code from every call plus a description, config structs
 * with documented defaults, caller-owned buffers.
 *
 * Handles. texel_document (a parsed, validated texture document),
 * texel_surface (a document prepared for rendering), texel_encode_result and
 * texel_player are opaque. Each is created by a texel_*_create / _load /
 * _parse / _from_* function that writes it through an out-pointer (set to
 * NULL on failure) and is owned by the caller until its texel_*_destroy,
 * which accepts NULL as a no-op. No handle keeps a pointer into another: a
 * surface may outlive its document, a player the surface it was given.
 *
 * Status. Every function that can fail returns texel_status (TEXEL_OK = 0).
 * texel_last_error() then gives the engine's one-line message (naming the
 * field, the value and what is allowed); it is thread-local. No C++
 * exception ever crosses this boundary; running out of memory is
 * TEXEL_OUT_OF_MEMORY.
 *
 * Buffers. Results of data-dependent size are written into caller memory:
 * functions take (buffer, capacity, size_t* needed). A NULL buffer queries
 * the size into *needed and returns TEXEL_OK; a buffer shorter than needed
 * gets nothing written and TEXEL_BUFFER_TOO_SMALL, with *needed set. `needed`
 * may be NULL when the buffer is given. Text results count their
 * terminating NUL. Sample windows take (first, out, count): exactly count
 * samples are written.
 *
 * Threads. Documents, surfaces and encode results are immutable after
 * creation: any number of threads may use one concurrently. A player has one
 * control thread (set_surface, push, set_gain, collect, destroy) and one
 * real-time thread (process). Different handles are independent.
 *
 * Real time. texel_player_process never allocates, frees, locks, logs or
 * does I/O, and does not touch texel_last_error (it reports only through its
 * return value). Everything else may allocate and must stay off the audio
 * or display callback.
 *
 * Units are in the names: _db (dB re 1 cycle/mm), _mm, _cpm (cycles/mm),
 * _hz, _s.
 */
#ifndef TEXEL_H
#define TEXEL_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Marks what libtexel exports. The shared library (libtexel.so) exports
 * exactly these functions and nothing else: Texel's C++ inside is hidden
 * (docs/c-api.md "Linking"). Nothing for a caller to define. */
#if defined(TEXEL_BUILDING_LIBRARY) && (defined(__GNUC__) || defined(__clang__))
#define TEXEL_API __attribute__((visibility("default")))
#else
#define TEXEL_API
#endif

/* ---------------------------------------------------------------- version */

/* The version this header describes; texel_version() gives the library's. */
#define TEXEL_VERSION_MAJOR 0
#define TEXEL_VERSION_MINOR 1
#define TEXEL_VERSION_PATCH 0

/* The library's version; any pointer may be NULL. */
TEXEL_API void texel_version(int* major, int* minor, int* patch);
/* The library's version as text, e.g. "0.1.0" (static storage). */
TEXEL_API const char* texel_version_string(void);

/* ----------------------------------------------------------------- status */

typedef enum texel_status {
  TEXEL_OK = 0,
  TEXEL_INVALID_ARGUMENT, /* a parameter outside its range or set; a NULL handle or out-pointer */
  TEXEL_FORMAT_ERROR,     /* a document, profile or bitstream that does not parse or validate */
  TEXEL_IO_ERROR,         /* a file that cannot be read */
  TEXEL_BUFFER_TOO_SMALL, /* the caller's buffer (or the player's event queue) has no room */
  TEXEL_OUT_OF_MEMORY,
  TEXEL_INTERNAL /* a bug in Texel: please report it with texel_last_error() */
} texel_status;

/* A fixed name for a status, e.g. "TEXEL_FORMAT_ERROR" ("unknown status"
 * for a value outside the enum). Static storage. */
TEXEL_API const char* texel_status_string(texel_status status);
/* The engine's message for the most recent call on this thread that returned
 * texel_status: "" after a success. Valid until the next such call on this
 * thread. Never NULL. */
TEXEL_API const char* texel_last_error(void);

/* ---------------------------------------------------------------- handles */

typedef struct texel_document texel_document;
typedef struct texel_surface texel_surface;
typedef struct texel_encode_result texel_encode_result;
typedef struct texel_player texel_player;

/* --------------------------------------------------------------- devices */

/* How a device stores one sample (device bytes, little-endian). */
typedef enum texel_sample_format {
  TEXEL_SAMPLE_U16LE = 0, /* round(a·65535) — tpad */
  TEXEL_SAMPLE_U8 = 1,    /* round(a·255) */
  TEXEL_SAMPLE_F32LE = 2,
  TEXEL_SAMPLE_F64LE = 3
} texel_sample_format;

typedef struct texel_device_info {
  int64_t samples;   /* samples along the active length, >= 1 */
  double spacing_mm; /* distance between samples, mm */
  double length_mm;  /* samples · spacing_mm */
  double refresh_hz; /* output update rate while playing */
  texel_sample_format format;
  size_t bytes_per_sample; /* of `format` */
} texel_device_info;

/* Looks a device profile up: a built-in name ("tpad", "tpad-tablet",
 * "generic"), NAME.json in a TEXEL_DEVICE_PATH directory, or a path to a
 * profile JSON file. Unknown names are TEXEL_INVALID_ARGUMENT. */
TEXEL_API texel_status texel_device_lookup(const char* name_or_path, texel_device_info* out);

/* ------------------------------------------------------------- parameters */

typedef enum texel_parameterization {
  TEXEL_PARAMETERIZATION_MOMENTS = 0, /* Central Pitch / Irregularity are the mean / SD in cpm, as dB */
  TEXEL_PARAMETERIZATION_LOG = 1      /* median, and SD of 10·log10 f */
} texel_parameterization;

/* A fine Texel texture over the whole device (what `texel render` flags
 * give). Start from texel_params_default(); the defaults are the studies'. */
typedef struct texel_params {
  double central_pitch_db;                 /* dB re 1 cpm, finite [10] */
  double irregularity_db;                  /* dB, finite [-5] */
  double texel_length_mm;                  /* mm, > 0 and <= 1000 [0.25] */
  uint64_t seed;                           /* the random draw [1] */
  texel_parameterization parameterization; /* [MOMENTS] */
  double quantization_db;                  /* frequency quantization step, 0 (off) … 20 dB [0] */
  double coarse_strength;                  /* C, 0 … 1 [0] */
  double fine_strength;                    /* F, 0 … 1 [1] */
  double coarse_sine_period_mm;            /* coarse profile: a sinusoid of this period (mm, > 0); 0 = constant [0] */
  double coarse_sine_phase_deg;            /* its phase, degrees, finite; used when the period is > 0 [0] */
} texel_params;

TEXEL_API texel_params texel_params_default(void);

/* -------------------------------------------------------------- documents */

/* Loads and validates a texture document (*.texel.json). */
TEXEL_API texel_status texel_document_load(const char* path, texel_document** out);
/* Parses and validates document JSON text of `length` bytes (no NUL needed). */
TEXEL_API texel_status texel_document_parse(const char* json, size_t length, texel_document** out);
/* One Texel texture over the whole of `device` (name or path, as
 * texel_device_lookup). */
TEXEL_API texel_status texel_document_from_params(const char* device, const texel_params* params, texel_document** out);
/* One reference texture (`texel reference --list` names them, e.g. "4sin",
 * "pink", "bandpass-f5-z0.5") with its default parameters over `device`. */
TEXEL_API texel_status texel_document_from_reference(const char* device, const char* name, uint64_t seed, texel_document** out);
/* The document as JSON text (NUL-terminated), the *.texel.json format. */
TEXEL_API texel_status texel_document_json(const texel_document* doc, char* buffer, size_t capacity, size_t* needed);
TEXEL_API void texel_document_destroy(texel_document* doc);

/* --------------------------------------------------------------- surfaces */

/* Prepares every region's texture for rendering (allocates; O(texels)). */
TEXEL_API texel_status texel_surface_create(const texel_document* doc, texel_surface** out);
/* Shorthand: texel_document_from_params then texel_surface_create. */
TEXEL_API texel_status texel_surface_from_params(const char* device, const texel_params* params, texel_surface** out);
/* The surface's device grid and format. */
TEXEL_API texel_status texel_surface_device(const texel_surface* surface, texel_device_info* out);
/* Samples in the whole map (texel_device_info.samples). */
TEXEL_API texel_status texel_surface_size(const texel_surface* surface, size_t* samples);

/* Amplitudes in [0, 1] of samples [first, first + count) of the map; needs
 * first + count <= size. Any window gives the same values as the whole map. */
TEXEL_API texel_status texel_surface_render(const texel_surface* surface, int64_t first, double* out, size_t count);
/* The same window as round(a·65535) in host byte order, whatever the device
 * format (on a little-endian host this is the tpad .bin file). */
TEXEL_API texel_status texel_surface_render_u16(const texel_surface* surface, int64_t first, uint16_t* out, size_t count);
/* The same window in the device's own format (texel_device_info.format):
 * count · bytes_per_sample bytes, exactly `texel render -o map.bin`. */
TEXEL_API texel_status texel_surface_render_native(const texel_surface* surface, int64_t first, size_t count, void* buffer,
                                                   size_t capacity, size_t* needed);
TEXEL_API void texel_surface_destroy(texel_surface* surface);

/* ------------------------------------------------------------------ codec */

/* Encodes a map of `count` amplitudes sampled every `spacing_mm` (the
 * encoder's defaults, as `texel encode`): a .texel bitstream of a few bytes.
 * Takes from well under a second to a few seconds.
 *
 * Amplitudes are read by the library's one rule for every front door (the
 * CLI's files, Python's arrays; docs/c-api.md "Input amplitudes"): a map
 * whose values all lie in [0, 1] is encoded as it is; a map with any value
 * outside [0, 1] (raw counts, signed data) is first scaled to full range,
 * a = 0.5 + 0.5·y/max|y| with y the map minus its mean. Refused with
 * TEXEL_INVALID_ARGUMENT: count < 2, a non-finite value, and a constant map
 * outside [0, 1] (it holds no texture). Nothing is clamped. */
TEXEL_API texel_status texel_encode(const double* amplitudes, size_t count, double spacing_mm, texel_encode_result** out);
/* What Central Pitch matches (docs/encoder.md §3, "Targets"). */
typedef enum texel_encode_target {
  TEXEL_TARGET_AUTOMATIC = 0, /* centroid for time recordings (.wav, time .csv), felt for maps: the default */
  TEXEL_TARGET_FELT = 1,      /* the perceptual model's felt pitch */
  TEXEL_TARGET_CENTROID = 2   /* the input's log-spectral centroid: the decoded texture swiped at swipe_speed_mm_s */
} texel_encode_target;

/* What the encoder is given besides the samples; every field has the
 * default of `texel encode` (texel_encode_options_default()). */
typedef struct texel_encode_options {
  double boundary_mm;                      /* fine/coarse boundary, mm, > 0 [1] */
  double texel_length_mm;                  /* texel length of the encoding, 0.001 … 65.535 mm [0.25] */
  texel_parameterization parameterization; /* [MOMENTS] */
  uint64_t seed;                           /* seed written to the bitstream [1] */
  unsigned coarse_bits;                    /* bits per coarse level, 1 … 16 [6] */
  size_t max_bytes;                        /* bitstream budget in bytes; 0 = none [0] */
  int recover_texel;                       /* 1: recognise Texel renderings and recover their parameters [1] */
  double swipe_speed_mm_s;                 /* finger speed of the perceptual model, mm/s, > 0 [100] */
  int model_version;                       /* perceptual model: 2, or 1 (the model before) [2] */
  int refuse_no_texture;                   /* 1: an input without texture is TEXEL_INVALID_ARGUMENT; 0: encoded as a
                                              flat surface with texel_encode_flags.no_texture set [0] */
  /* Appended after 0.1.0. */
  texel_encode_target target; /* what Central Pitch matches (`texel encode --target`) [AUTOMATIC] */
} texel_encode_options;

TEXEL_API texel_encode_options texel_encode_options_default(void);

/* texel_encode with options (NULL = the defaults); amplitudes read as by texel_encode. */
TEXEL_API texel_status texel_encode_with(const double* amplitudes, size_t count, double spacing_mm,
                                         const texel_encode_options* options, texel_encode_result** out);

/* Encodes a file through the engine's one signal loader, as `texel encode
 * PATH`: .bin (needs `device`), .npy, .csv, .mat, .wav and time/value .csv
 * recordings (need swipe_speed_mm_s > 0: the finger speed that turns time
 * into position), a *.texel.json document or a .texel bitstream (rendered on
 * `device`, or on the document's own). `device` may be NULL (name or path
 * otherwise, as texel_device_lookup; its frequency response is in the
 * perceptual model's loop, as `texel encode --device`); swipe_speed_mm_s 0 =
 * none, > 0 also sets the perceptual model's speed (as `texel encode
 * --swipe-speed`). */
TEXEL_API texel_status texel_encode_file(const char* path, const char* device, double swipe_speed_mm_s,
                                         const texel_encode_options* options, texel_encode_result** out);

/* The bitstream bytes (a .texel file). */
TEXEL_API texel_status texel_encode_result_bytes(const texel_encode_result* result, uint8_t* buffer, size_t capacity,
                                                 size_t* needed);
/* The parameters the bitstream decodes to. A coarse profile other than a
 * sinusoid is not expressible in texel_params: coarse_sine_period_mm is 0 and
 * *has_coarse_profile (if not NULL) is 1; render such a result through
 * texel_decode. */
TEXEL_API texel_status texel_encode_result_params(const texel_encode_result* result, texel_params* out, int* has_coarse_profile);
/* Distance between the input and the decoded texture under the perceptual
 * model, in just-noticeable differences. */
TEXEL_API texel_status texel_encode_result_distance(const texel_encode_result* result, double* jnd);
/* What the encoder says about its own answer (docs/encoder.md, "Honest
 * results"). */
typedef struct texel_encode_flags {
  int model_version;             /* the perceptual model that decided: 1 or 2 */
  int no_texture;                /* 1: the input had no texture (variation at most 2^-16): a flat surface, Central
                                    Pitch and Irregularity are defaults, not estimates */
  int central_pitch_at_bound;    /* 1: Central Pitch ended at an edge of the search box (a limit, not an estimate) */
  int irregularity_at_bound;     /* 1: Irregularity ended at an edge of the search box */
  int irregularity_identifiable; /* 0: a narrower distribution feels the same, or a value is at a bound */
  /* Appended after 0.1.0. */
  texel_encode_target target; /* the target the fit matched: FELT or CENTROID (never AUTOMATIC) */
} texel_encode_flags;
TEXEL_API texel_status texel_encode_result_flags(const texel_encode_result* result, texel_encode_flags* out);
TEXEL_API void texel_encode_result_destroy(texel_encode_result* result);

/* Decodes a bitstream to the document it stands for on `device` (name or
 * path): rendering it gives `texel decode`'s map byte for byte. */
TEXEL_API texel_status texel_decode(const uint8_t* bytes, size_t size, const char* device, texel_document** out);

/* --------------------------------------------------------------- spectrum */

/* What `texel spectrum` reports for a map: the magnitude spectrum, the Welch
 * power spectral density, the peaks, the spectral centroid and spread, and
 * the band energies, computed by the same library function. */
typedef struct texel_spectrum texel_spectrum;

/* The magnitude spectrum's window (`texel spectrum --window`). */
typedef enum texel_window {
  TEXEL_WINDOW_BLACKMAN_HARRIS = 0, /* the default: low leakage */
  TEXEL_WINDOW_HANN = 1,
  TEXEL_WINDOW_FLAT_TOP = 2, /* accurate peak amplitudes */
  TEXEL_WINDOW_RECTANGULAR = 3
} texel_window;

/* Start from texel_spectrum_options_default() (the CLI's defaults). */
typedef struct texel_spectrum_options {
  texel_window window;  /* [BLACKMAN_HARRIS] */
  unsigned zero_pad;    /* zero padding factor, 1 … 16 [4] */
  double threshold_db;  /* peaks within this many dB of the highest, -300 … 0 [-40] */
  size_t max_peaks;     /* most peaks to report, 1 … 100000 [32] */
  size_t welch_segment; /* Welch segment, samples; 0 = about a quarter of the map [0] */
  double welch_overlap; /* Welch overlap, 0 … 0.95 [0.5] */
} texel_spectrum_options;

TEXEL_API texel_spectrum_options texel_spectrum_options_default(void);

/* Analyses `count` amplitudes (>= 16) sampled every `spacing_mm` (options
 * NULL = the defaults), as `texel spectrum` does a map file. */
TEXEL_API texel_status texel_spectrum_analyse(const double* amplitudes, size_t count, double spacing_mm,
                                              const texel_spectrum_options* options, texel_spectrum** out);

/* The scalars of an analysis (`texel spectrum --json` names). */
typedef struct texel_spectrum_summary {
  size_t samples;         /* input samples */
  double spacing_mm;      /* input spacing */
  size_t nfft;            /* transform length of the magnitude spectrum */
  double bin_cpm;         /* its bin spacing, cycles/mm */
  double resolution_cpm;  /* 1 / map length, cycles/mm */
  double mean_amplitude;  /* removed before the analysis */
  double rms_amplitude;   /* about the mean */
  double centroid_cpm;    /* spectral centroid, cycles/mm */
  double log_centroid_db; /* log-frequency centroid, dB re 1 cycle/mm */
  double spread_cpm;      /* spectral spread, cycles/mm */
  double log_spread_db;   /* log-frequency spread, dB */
  size_t welch_segment;   /* Welch segment length used, samples */
  size_t welch_segments;  /* segments averaged */
  double psd_bin_cpm;     /* Welch bin spacing, cycles/mm */
} texel_spectrum_summary;

TEXEL_API texel_status texel_spectrum_get_summary(const texel_spectrum* spectrum, texel_spectrum_summary* out);

/* The arrays of an analysis; each series has its own length. */
typedef enum texel_spectrum_series {
  TEXEL_SERIES_FREQUENCY_CPM = 0,      /* magnitude spectrum bins, cycles/mm */
  TEXEL_SERIES_MAGNITUDE = 1,          /* amplitude-calibrated magnitude per bin */
  TEXEL_SERIES_PSD_FREQUENCY_CPM = 2,  /* Welch bins, cycles/mm */
  TEXEL_SERIES_PSD = 3,                /* one-sided density, amplitude²/(cycle/mm) */
  TEXEL_SERIES_PEAK_FREQUENCY_CPM = 4, /* interpolated peak frequencies, ascending */
  TEXEL_SERIES_PEAK_AMPLITUDE = 5,     /* their heights (magnitude units) */
  TEXEL_SERIES_PEAK_LEVEL_DB = 6,      /* dB re the highest peak, <= 0 */
  TEXEL_SERIES_BAND_LO_CPM = 7,        /* band energy: decades up to Nyquist */
  TEXEL_SERIES_BAND_HI_CPM = 8,
  TEXEL_SERIES_BAND_MEAN_SQUARE = 9, /* amplitude² in the band */
  TEXEL_SERIES_BAND_FRACTION = 10    /* share of the total, 0 … 1 */
} texel_spectrum_series;

/* Copies one series into `values` (capacity and *needed count values, not
 * bytes; otherwise the buffer rule of this header). */
TEXEL_API texel_status texel_spectrum_get_series(const texel_spectrum* spectrum, texel_spectrum_series series, double* values,
                                                 size_t capacity, size_t* needed);
TEXEL_API void texel_spectrum_destroy(texel_spectrum* spectrum);

/* ----------------------------------------------------------------- player */

typedef enum texel_output_mode {
  TEXEL_OUTPUT_AMPLITUDE = 0, /* a(x) in [0, 1], for friction displays */
  TEXEL_OUTPUT_VIBRATION = 1, /* a(x) band-passed, zero-mean, in [-1, 1] */
  TEXEL_OUTPUT_CARRIER = 2    /* a(x)·sin(2π·carrier_hz·t) */
} texel_output_mode;

/* How the player respects the display's frequency response (the device
 * profile's "response", docs/format.md "Frequency response"). LIMIT: a
 * 2nd-order Butterworth low-pass at the frequency where the display is
 * response_limit_db down, so the player never drives what the display cannot
 * reproduce (tpad: first order at 400 Hz, limited at 3.98 kHz; skipped when
 * that is above 0.45·rate_hz, e.g. at the tpad's 8333 Hz refresh; a flat
 * profile such as generic is never limited). OFF: played flat. */
typedef enum texel_response_handling {
  TEXEL_RESPONSE_LIMIT = 0, /* [choice], the default */
  TEXEL_RESPONSE_OFF = 1
} texel_response_handling;

/* Start from texel_player_config_default(). Fields are only ever appended
 * (this header has no struct_size field): a program must be compiled against
 * the texel.h of the library it links (docs/c-api.md "Extending structs"). */
typedef struct texel_player_config {
  double rate_hz;         /* output rate, 100 … 384000 [48000]; tpad: 8333 */
  texel_output_mode mode; /* [AMPLITUDE] */
  double gain;            /* 0 … 1 [1] */
  double carrier_hz;      /* carrier mode: 0 … rate/2 [250] */
  double prediction_s;    /* latency compensation look-ahead, 0 … 0.1 s [0] */
  /* Appended after 0.1.0. The response itself is the device's of each
   * surface given to texel_player_set_surface. */
  texel_response_handling response_handling; /* [LIMIT] */
  double response_limit_db;                  /* LIMIT: the display's attenuation where driving stops, 3 … 60 dB [20] */
} texel_player_config;

TEXEL_API texel_player_config texel_player_config_default(void);

/* Prepares a player (allocates all it will ever need); silent until
 * texel_player_set_surface. */
TEXEL_API texel_status texel_player_create(const texel_player_config* config, texel_player** out);
/* Control thread: renders the surface's whole map into a new player map and
 * swaps it in (process crossfades to it). The map carries the frequency
 * response of the surface's device, which the player respects from the swap
 * on (config.response_handling); surfaces of different devices may follow
 * one another. Allocates; frees maps process has retired. The surface may be
 * destroyed afterwards. */
TEXEL_API texel_status texel_player_set_surface(texel_player* player, const texel_surface* surface);
/* Control thread: queues one finger sample (time-ordered; t_s on the
 * player's clock, 0 = first output sample; x_mm in device coordinates;
 * touch 0 = lifted). TEXEL_BUFFER_TOO_SMALL: the event queue is full (let
 * process run, then push again). */
TEXEL_API texel_status texel_player_push(texel_player* player, double t_s, double x_mm, int touch);
/* Control thread: queues a gain change (clamped to [0, 1], ramped over a block). */
TEXEL_API texel_status texel_player_set_gain(texel_player* player, double gain);
/* Control thread: frees maps process has retired; *freed (may be NULL) gets
 * their number. */
TEXEL_API texel_status texel_player_collect(texel_player* player, size_t* freed);
/* Real-time thread: the next `frames` output samples into out[0 … frames),
 * and, if positions_mm is not NULL, the finger position used for each.
 * Real-time safe: never allocates, frees, locks, logs or does I/O; does not
 * set texel_last_error. TEXEL_INVALID_ARGUMENT for a NULL player or out. */
TEXEL_API texel_status texel_player_process(texel_player* player, float* out, size_t frames, float* positions_mm);
/* Output samples produced so far (any thread); 0 for NULL. */
TEXEL_API uint64_t texel_player_samples(const texel_player* player);
/* Stop the real-time thread first. */
TEXEL_API void texel_player_destroy(texel_player* player);

/* ----------------------------------------------------------- 2-D surfaces */

/* A version-4 document with a 2-D surface (docs/format.md "2-D surfaces") on
 * a device with a bitmap grid renders to a friction bitmap, row j at
 * y = j·pitch, column i at x = i·pitch, and plays under a 2-D finger through
 * the 2-D player (docs/player.md "The 2-D player"): the same library calls
 * as `texel render DOC --surface 2d` and `texel swipe DOC --path|--trace-2d`. */
typedef struct texel_surface2d texel_surface2d;

typedef enum texel_bitmap_polarity {
  TEXEL_DARKER_MORE_FRICTION = 0,  /* pixel = a·max */
  TEXEL_BRIGHTER_MORE_FRICTION = 1 /* pixel = (1 − a)·max */
} texel_bitmap_polarity;

typedef struct texel_bitmap_info {
  int width_px;          /* pixels along x */
  int height_px;         /* pixels (rows) along y */
  double pixel_pitch_mm; /* pixel spacing on both axes */
  int depth_bits;        /* 8 or 16: the device's bitmap depth */
  texel_bitmap_polarity polarity;
} texel_bitmap_info;

/* Prepares a 2-D document's fields for rendering; TEXEL_INVALID_ARGUMENT for
 * a document without a 2-D surface or a device without a bitmap grid. */
TEXEL_API texel_status texel_surface2d_create(const texel_document* doc, texel_surface2d** out);
TEXEL_API texel_status texel_surface2d_info(const texel_surface2d* surface, texel_bitmap_info* out);
/* Amplitudes in [0, 1] of pixel rows [first_row, first_row + rows), row-major
 * into out; count must be rows · width_px. Any strip gives the same values as
 * the whole bitmap (render a large map a strip at a time). */
TEXEL_API texel_status texel_surface2d_render_rows(const texel_surface2d* surface, int first_row, int rows, double* out,
                                                   size_t count);
/* The same rows as the pixels a bitmap of depth_bits (8 or 16; 0 = the
 * device's) stores, the device's polarity applied: exactly the pixels of
 * `texel render DOC --surface 2d --depth D -o map.png`. */
TEXEL_API texel_status texel_surface2d_render_pixels(const texel_surface2d* surface, int first_row, int rows, int depth_bits,
                                                     uint16_t* out, size_t count);
/* Writes the bitmap to `path` by extension (.png, .npy, .mat, .gltf, .glb),
 * strip by strip and atomically (nothing is left on failure), as `texel
 * render DOC --surface 2d -o PATH`; depth_bits as above (PNG only). */
TEXEL_API texel_status texel_surface2d_write(const texel_surface2d* surface, const char* path, int depth_bits);
TEXEL_API void texel_surface2d_destroy(texel_surface2d* surface);

/* One finger sample on a 2-D surface. */
typedef struct texel_finger2d {
  double x_mm, y_mm; /* position, surface coordinates */
  double t_s;        /* time on the player's clock, non-decreasing */
  int touch;         /* 0 = lifted */
} texel_finger2d;

typedef enum texel_path2d_shape {
  TEXEL_PATH2D_LINE = 0,   /* straight at angle_deg */
  TEXEL_PATH2D_CIRCLE = 1, /* centred on the start, radius_mm */
  TEXEL_PATH2D_ZIGZAG = 2  /* legs of leg_mm, zigzag_deg between them, about angle_deg */
} texel_path2d_shape;

/* A simulated stroke at constant speed (`texel swipe --path`); start from
 * texel_path2d_config_default(). */
typedef struct texel_path2d_config {
  texel_path2d_shape shape; /* [LINE] */
  double speed_mm_s;        /* > 0 [100] */
  double angle_deg;         /* [0] */
  double start_x_mm;        /* where the finger lands; circle: its centre [0] */
  double start_y_mm;        /* [0] */
  double radius_mm;         /* circle, > 0 [20] */
  double leg_mm;            /* zigzag leg, > 0 [10] */
  double zigzag_deg;        /* angle between legs, 0 < · < 180 [90] */
  double duration_s;        /* > 0 [1] */
  double rate_hz;           /* samples per second, > 0 [1000] */
} texel_path2d_config;

TEXEL_API texel_path2d_config texel_path2d_config_default(void);
/* The stroke's samples (touching throughout, a lifted sample at the end),
 * under the buffer rule of this header (capacity and *needed in samples). */
TEXEL_API texel_status texel_path2d_simulate(const texel_path2d_config* config, texel_finger2d* trace, size_t capacity,
                                             size_t* needed);

/* What the 2-D player plays of a document. */
typedef enum texel_map2d_mode {
  TEXEL_MAP2D_PATH = 0,  /* path-indexed: the texture along the finger's travelled path, the coarse profile at (x, y) */
  TEXEL_MAP2D_BITMAP = 1 /* the document's friction bitmap at (x, y) */
} texel_map2d_mode;

typedef enum texel_path_at_lift {
  TEXEL_PATH_KEEP = 0, /* the path continues across lifts: the default */
  TEXEL_PATH_RESET = 1 /* every stroke starts the texture over */
} texel_path_at_lift;

/* Plays a document under a 2-D trace through the 2-D real-time player, off
 * line (`texel swipe DOC --trace-2d`): `frames` output samples into out and,
 * if not NULL, the finger position used for each into x_mm / y_mm. The
 * device's frequency response is the document's. TEXEL_MAP2D_PATH plays a
 * 2-D surface of one region, or a 1-D document's first Texel texture. */
TEXEL_API texel_status texel_swipe_2d(const texel_document* doc, const texel_finger2d* trace, size_t samples,
                                      texel_map2d_mode mode, texel_path_at_lift at_lift, const texel_player_config* config,
                                      float* out, size_t frames, float* x_mm, float* y_mm);

/* ------------------------------------------------------------ 2-D encoding */

/* What the 2-D encoder found (docs/encoder.md, "2-D inputs"): a version-4
 * 2-D document with one region covering the map, its coarse image and the
 * per-direction diagnostics. */
typedef struct texel_encode2d_result texel_encode2d_result;

/* The 2-D encoder's own settings; start from texel_encode2d_options_default(). */
typedef struct texel_encode2d_options {
  int directions;        /* scan directions over the half turn, >= 2 [18] */
  size_t scan_samples;   /* samples per direction (parallel scans joined), >= 1024 [16384] */
  int correction_rounds; /* analysis-by-synthesis rounds through the 2-D design, 0 = none [1] */
} texel_encode2d_options;

TEXEL_API texel_encode2d_options texel_encode2d_options_default(void);

/* Encodes a map of width_px × height_px values (row-major, rows
 * along y, pixel pitch pitch_mm), read by the library's one input rule: all in
 * [0, 1], amplitudes as they are; any value outside, the map scaled to full
 * range (a = 0.5 + 0.5·y/max|y|, y the zero-mean values; never clamped);
 * refused with TEXEL_INVALID_ARGUMENT naming `amplitudes` when a value is not
 * finite or the map is constant outside [0, 1] (as texel_encode; c-api.md
 * "Input amplitudes"). The 1-D encoder's settings from `options`
 * (the perceptual model, target, …; NULL = the defaults), the 2-D encoder's
 * from `options2d` (NULL = the defaults). With the defaults a 400 × 400 map
 * takes about ten seconds. */
TEXEL_API texel_status texel_encode_2d(const double* amplitudes, int width_px, int height_px, double pitch_mm,
                                       const texel_encode_options* options, const texel_encode2d_options* options2d,
                                       texel_encode2d_result** out);
/* Encodes a 2-D input file as `texel encode` does: a grey 8/16-bit .png, a
 * 2-D .npy (a height map, values outside [0, 1], is scaled) or a .scans.json
 * bundle of 1-D scans. pitch_mm: the pixel pitch (> 0), or 0 to take the
 * device's bitmap pitch; device: a built-in profile name or a profile's
 * path, or NULL (then pitch_mm is required); polarity: how a PNG's levels
 * read (TEXEL_DARKER_MORE_FRICTION or TEXEL_BRIGHTER_MORE_FRICTION), or -1
 * for the device's (darker_more_friction without one); swipe_speed_mm_s:
 * for recorded scans in a bundle, 0 for none. The device's frequency
 * response is the perceptual model's display, as for texel_encode_file. */
TEXEL_API texel_status texel_encode_2d_file(const char* path, double pitch_mm, const char* device, int polarity,
                                            double swipe_speed_mm_s, const texel_encode_options* options,
                                            const texel_encode2d_options* options2d, texel_encode2d_result** out);
/* The document (a new handle, the caller's). Its region names its coarse
 * image as "coarse.npy" beside the document: texel_encode2d_result_save
 * writes both; rendering the document needs the image there. */
TEXEL_API texel_status texel_encode2d_result_document(const texel_encode2d_result* result, texel_document** out);
/* The result as JSON text (NUL-terminated; the buffer rule): parameters,
 * per-direction rows, anisotropy, flags, model, as `texel encode --json`. */
TEXEL_API texel_status texel_encode2d_result_json(const texel_encode2d_result* result, char* buffer, size_t capacity,
                                                  size_t* needed);
/* Writes the document to document_path and its coarse image beside it,
 * atomically (nothing is left on failure). */
TEXEL_API texel_status texel_encode2d_result_save(const texel_encode2d_result* result, const char* document_path);
TEXEL_API void texel_encode2d_result_destroy(texel_encode2d_result* result);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* TEXEL_H */
