// The C ABI (include/texel.h): a thin front door over the library.
//
// Every entry point that can fail runs its body through `guarded`, which turns
// the project's exception families into status codes and keeps the message in
// a thread-local slot for texel_last_error(): no exception crosses the
// boundary (miniaudio's ma_result + description pattern). Arguments the C
// caller supplies — NULL pointers, enum values outside their enum, non-finite
// numbers, windows past the end of the map — are checked here with messages
// that name the C parameter, the way the CLI names its flags; everything else
// is the library's own validation.
//
// texel_player_process is the exception: it is real-time, so it neither
// allocates nor touches the (std::string) error slot; it only returns a code.
#include "texel.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <memory>
#include <new>
#include <span>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "texel/bitmap_file.hpp"
#include "texel/codec.hpp"
#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/encode2d.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/reference.hpp"
#include "texel/signal.hpp"
#include "texel/spectrum.hpp"
#include "texel/surface.hpp"
#include "texel/surface2d.hpp"
#include "texel/texture.hpp"

struct texel_document {
  texel::Document doc;
};

struct texel_surface {
  texel::DeviceProfile device;
  texel::Surface surface;
};

struct texel_encode_result {
  texel::codec::EncodeResult result;
};

struct texel_spectrum {
  texel::SpectralReport report;
  std::size_t samples = 0;
  double spacing_mm = 0.0;
};

struct texel_surface2d {
  texel::Surface2D surface;
};

struct texel_encode2d_result {
  texel::codec::Encode2DResult result;
};

struct texel_player {
  texel::Player player;
  explicit texel_player(const texel::PlayerConfig& c) : player(c) {}
};

namespace {

using texel::InvalidArgument;

// The last error of this thread. `fixed` points at static text when building
// a message could itself fail (out of memory).
thread_local std::string t_message;
thread_local const char* t_fixed = nullptr;

texel_status fail(texel_status status, const char* what) noexcept {
  try {
    t_message.assign(what);
    t_fixed = nullptr;
  } catch (...) {
    t_fixed = "out of memory while reporting an error";
  }
  return status;
}

// Thrown (and caught by `guarded`) when a caller buffer or the player's event
// queue has no room: not an error of the library, so not a texel::Error.
struct BufferTooSmall {
  std::string message;
};

template <class F>
texel_status guarded(F&& body) noexcept {
  t_message.clear();  // keeps its capacity: never allocates
  t_fixed = nullptr;
  try {
    body();
    return TEXEL_OK;
  } catch (const BufferTooSmall& e) {
    return fail(TEXEL_BUFFER_TOO_SMALL, e.message.c_str());
  } catch (const texel::InvalidArgument& e) {
    return fail(TEXEL_INVALID_ARGUMENT, e.what());
  } catch (const texel::FormatError& e) {
    return fail(TEXEL_FORMAT_ERROR, e.what());
  } catch (const texel::IoError& e) {
    return fail(TEXEL_IO_ERROR, e.what());
  } catch (const std::bad_alloc&) {
    t_fixed = "out of memory";
    return TEXEL_OUT_OF_MEMORY;
  } catch (const std::exception& e) {
    return fail(TEXEL_INTERNAL, e.what());
  } catch (...) {
    t_fixed = "unknown exception inside Texel";
    return TEXEL_INTERNAL;
  }
}

template <class T>
T& need(T* p, const char* name) {
  if (!p) throw InvalidArgument(std::string(name) + " is NULL");
  return *p;
}

const char* need_text(const char* p, const char* name) {
  if (!p) throw InvalidArgument(std::string(name) + " is NULL");
  return p;
}

// The integer a C caller stored in an enum. C allows any int there; in C++ a
// load of an enum object outside its range is undefined (and UBSan's `enum`
// check stops on it), so the bytes are copied instead of loaded as the enum.
template <class E>
long long enum_value(const E& e) {
  std::underlying_type_t<E> v;
  static_assert(sizeof v == sizeof e);
  std::memcpy(&v, &e, sizeof v);
  return static_cast<long long>(static_cast<int>(v));
}

// The library value of a C enum field: one row per C value (value, library
// value, C name); any other value is refused, naming the field and listing
// what is allowed ("mode is 5; allowed: TEXEL_MAP2D_PATH (0), ...").
template <class To>
struct Choice {
  long long c;
  To value;
  const char* name;
};
template <class To, class E>
To choose(const E& e, const char* field, std::initializer_list<Choice<To>> choices) {
  const long long v = enum_value(e);
  std::string allowed;
  for (const Choice<To>& c : choices) {
    if (c.c == v) return c.value;
    allowed += (allowed.empty() ? "" : ", ") + std::string(c.name) + " (" + std::to_string(c.c) + ")";
  }
  throw InvalidArgument(std::string(field) + " is " + std::to_string(v) + "; allowed: " + allowed);
}

void need_finite(double v, const char* name) {
  if (!std::isfinite(v)) throw InvalidArgument(std::string(name) + " is not a finite number");
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The buffer rule of check_buffer for a result of `size` elements (`unit`)
// in the buffer the caller names `name`.
bool check_count(std::size_t size, const void* buffer, std::size_t capacity, std::size_t* needed, const char* name,
                 const char* unit) {
  if (!buffer && !needed)
    throw InvalidArgument(std::string(name) + " and needed are both NULL; give a buffer or ask for the size");
  if (needed) *needed = size;
  if (!buffer) return false;
  if (capacity < size)
    throw BufferTooSmall{std::string(name) + " holds " + std::to_string(capacity) + " " + unit + "; " + std::to_string(size) +
                         " needed"};
  return true;
}

// The (buffer, capacity, needed) rule of texel.h for a result of `size`
// bytes: true when the caller gave a buffer with room for it.
bool check_buffer(std::size_t size, const void* buffer, std::size_t capacity, std::size_t* needed) {
  return check_count(size, buffer, capacity, needed, "buffer", "bytes");
}

void copy_out(const void* data, std::size_t size, void* buffer, std::size_t capacity, std::size_t* needed) {
  if (check_buffer(size, buffer, capacity, needed) && size) std::memcpy(buffer, data, size);
}

texel_sample_format to_c(texel::SampleFormat f) {
  switch (f) {
    case texel::SampleFormat::u16le: return TEXEL_SAMPLE_U16LE;
    case texel::SampleFormat::u8: return TEXEL_SAMPLE_U8;
    case texel::SampleFormat::f32le: return TEXEL_SAMPLE_F32LE;
    case texel::SampleFormat::f64le: return TEXEL_SAMPLE_F64LE;
  }
  return TEXEL_SAMPLE_U16LE;
}

texel_device_info info_of(const texel::DeviceProfile& d) {
  texel_device_info i{};
  i.samples = d.samples;
  i.spacing_mm = d.spacing.value();
  i.length_mm = d.length().value();
  i.refresh_hz = d.refresh.value();
  i.format = to_c(d.format);
  i.bytes_per_sample = texel::bytes_per_sample(d.format);
  return i;
}

// A C parameterization value (any int a C caller stored) as the library's.
texel::Parameterization parameterization_of(const texel_parameterization& p) {
  switch (enum_value(p)) {
    case TEXEL_PARAMETERIZATION_MOMENTS: return texel::Parameterization::moments;
    case TEXEL_PARAMETERIZATION_LOG: return texel::Parameterization::log;
    default:
      throw InvalidArgument("parameterization is " + std::to_string(enum_value(p)) +
                            "; allowed: TEXEL_PARAMETERIZATION_MOMENTS (0), TEXEL_PARAMETERIZATION_LOG (1)");
  }
}

texel_parameterization to_c(texel::Parameterization p) {
  return p == texel::Parameterization::log ? TEXEL_PARAMETERIZATION_LOG : TEXEL_PARAMETERIZATION_MOMENTS;
}

// texel_params -> TexelSpec, checking what the C caller can get wrong with
// the C field names (the CLI checks the same values under its flag names).
texel::TexelSpec spec_of(const texel_params& p) {
  need_finite(p.central_pitch_db, "central_pitch_db");
  need_finite(p.irregularity_db, "irregularity_db");
  need_finite(p.texel_length_mm, "texel_length_mm");
  need_finite(p.quantization_db, "quantization_db");
  need_finite(p.coarse_strength, "coarse_strength");
  need_finite(p.fine_strength, "fine_strength");
  need_finite(p.coarse_sine_period_mm, "coarse_sine_period_mm");
  need_finite(p.coarse_sine_phase_deg, "coarse_sine_phase_deg");
  texel::TexelSpec s;
  s.central_pitch = texel::Decibels(p.central_pitch_db);
  s.irregularity = texel::Decibels(p.irregularity_db);
  s.texel_length = texel::Millimetres(p.texel_length_mm);
  s.seed = p.seed;
  s.parameterization = parameterization_of(p.parameterization);
  if (!(p.quantization_db >= 0.0 && p.quantization_db <= 20.0))
    throw InvalidArgument("quantization_db is " + num(p.quantization_db) + "; allowed: 0 (off) … 20 dB");
  s.quantization_db = p.quantization_db;
  s.coarse_strength = p.coarse_strength;
  s.fine_strength = p.fine_strength;
  if (p.coarse_sine_period_mm < 0.0)
    throw InvalidArgument("coarse_sine_period_mm is " + num(p.coarse_sine_period_mm) +
                          "; allowed: 0 (constant profile) or a period > 0 mm");
  if (p.coarse_sine_period_mm > 0.0)
    s.coarse = texel::SineProfile{texel::Millimetres(p.coarse_sine_period_mm), p.coarse_sine_phase_deg};
  texel::validate(s);
  return s;
}

texel_params params_of(const texel::TexelSpec& s, int* has_profile) {
  texel_params p = texel_params_default();
  p.central_pitch_db = s.central_pitch.value();
  p.irregularity_db = s.irregularity.value();
  p.texel_length_mm = s.texel_length.value();
  p.seed = s.seed;
  p.parameterization = to_c(s.parameterization);
  p.quantization_db = s.quantization_db;
  p.coarse_strength = s.coarse_strength;
  p.fine_strength = s.fine_strength;
  int other = 0;
  if (const auto* sine = std::get_if<texel::SineProfile>(&s.coarse)) {
    p.coarse_sine_period_mm = sine->period.value();
    p.coarse_sine_phase_deg = sine->phase_deg;
  } else if (!std::holds_alternative<texel::ConstantProfile>(s.coarse)) {
    other = 1;
  }
  if (has_profile) *has_profile = other;
  return p;
}

// Checks a window [first, first + count) against the map's size.
void check_window(const texel_surface& s, std::int64_t first, std::size_t count) {
  const auto size = static_cast<std::uint64_t>(s.surface.grid().count);
  if (first < 0 || static_cast<std::uint64_t>(first) > size || count > size - static_cast<std::uint64_t>(first))
    throw InvalidArgument("window first=" + std::to_string(first) + " count=" + std::to_string(count) + " is outside the map's " +
                          std::to_string(size) + " samples");
}

// Renders a window chunk by chunk (bounded scratch memory), handing each
// chunk's amplitudes and its offset in the window to `emit`.
template <class Emit>
void render_chunks(const texel_surface& s, std::int64_t first, std::size_t count, Emit&& emit) {
  constexpr std::size_t chunk = std::size_t{1} << 16;
  std::vector<double> scratch(std::min(count, chunk));
  for (std::size_t done = 0; done < count; done += chunk) {
    const std::size_t len = std::min(chunk, count - done);
    std::span<double> part(scratch.data(), len);
    s.surface.render(first + static_cast<std::int64_t>(done), part);
    emit(std::span<const double>(part), done);
  }
}

texel::DeviceProfile device_named(const char* name) { return texel::load_device(need_text(name, "device")); }

// texel_encode_options -> EncoderConfig with the C field names; the encoder
// validates ranges itself (its FieldErrors name the same fields).
texel::codec::EncoderConfig config_of(const texel_encode_options& o) {
  need_finite(o.boundary_mm, "boundary_mm");
  need_finite(o.texel_length_mm, "texel_length_mm");
  need_finite(o.swipe_speed_mm_s, "swipe_speed_mm_s");
  texel::codec::EncoderConfig c;
  c.boundary = texel::Millimetres(o.boundary_mm);
  c.texel_length = texel::Millimetres(o.texel_length_mm);
  c.parameterization = parameterization_of(o.parameterization);
  c.seed = o.seed;
  c.coarse_bits = o.coarse_bits;
  if (o.max_bytes > 0) c.max_bytes = o.max_bytes;
  if (o.recover_texel != 0 && o.recover_texel != 1)
    throw InvalidArgument("recover_texel is " + std::to_string(o.recover_texel) + "; allowed: 0, 1");
  c.recover_texel = o.recover_texel == 1;
  if (o.refuse_no_texture != 0 && o.refuse_no_texture != 1)
    throw InvalidArgument("refuse_no_texture is " + std::to_string(o.refuse_no_texture) + "; allowed: 0, 1");
  if (o.model_version != 1 && o.model_version != 2)
    throw InvalidArgument("model_version is " + std::to_string(o.model_version) + "; allowed: 1, 2");
  c.model = texel::codec::model_defaults(o.model_version);
  c.model.swipe_speed = texel::MmPerSecond(o.swipe_speed_mm_s);
  c.no_texture =
      o.refuse_no_texture ? texel::codec::EncoderConfig::NoTexture::refuse : texel::codec::EncoderConfig::NoTexture::flag;
  using Target = texel::codec::EncoderConfig::Target;
  c.target = choose<Target>(o.target, "target",
                            {{TEXEL_TARGET_AUTOMATIC, Target::automatic, "TEXEL_TARGET_AUTOMATIC"},
                             {TEXEL_TARGET_FELT, Target::felt, "TEXEL_TARGET_FELT"},
                             {TEXEL_TARGET_CENTROID, Target::centroid, "TEXEL_TARGET_CENTROID"}});
  return c;
}

// texel_player_config -> PlayerConfig (validated), with the C field names.
texel::PlayerConfig player_config_of(const texel_player_config& c) {
  texel::PlayerConfig pc;
  pc.rate_hz = c.rate_hz;
  pc.mode = choose<texel::OutputMode>(c.mode, "mode",
                                      {{TEXEL_OUTPUT_AMPLITUDE, texel::OutputMode::amplitude, "TEXEL_OUTPUT_AMPLITUDE"},
                                       {TEXEL_OUTPUT_VIBRATION, texel::OutputMode::vibration, "TEXEL_OUTPUT_VIBRATION"},
                                       {TEXEL_OUTPUT_CARRIER, texel::OutputMode::carrier, "TEXEL_OUTPUT_CARRIER"}});
  pc.gain = c.gain;
  pc.carrier_hz = c.carrier_hz;
  pc.prediction_s = c.prediction_s;
  pc.response_handling =
      choose<texel::ResponseHandling>(c.response_handling, "response_handling",
                                      {{TEXEL_RESPONSE_LIMIT, texel::ResponseHandling::limit, "TEXEL_RESPONSE_LIMIT"},
                                       {TEXEL_RESPONSE_OFF, texel::ResponseHandling::off, "TEXEL_RESPONSE_OFF"}});
  pc.response_limit_db = c.response_limit_db;
  // The library's extrapolation window must cover the look-ahead.
  pc.extrapolate_s = std::max(pc.extrapolate_s, std::isfinite(c.prediction_s) ? c.prediction_s : 0.0);
  texel::validate(pc);
  return pc;
}

// The numbers of a 2-D path config (texel_path2d_config and Path2DConfig
// use the same names), either way.
template <class From, class To>
void copy_path_numbers(const From& c, To& p) {
  p.speed_mm_s = c.speed_mm_s;
  p.angle_deg = c.angle_deg;
  p.start_x_mm = c.start_x_mm;
  p.start_y_mm = c.start_y_mm;
  p.radius_mm = c.radius_mm;
  p.leg_mm = c.leg_mm;
  p.zigzag_deg = c.zigzag_deg;
  p.duration_s = c.duration_s;
  p.rate_hz = c.rate_hz;
}

// A row range and buffer of a 2-D surface, named as the C parameters.
void check_rows(const texel::Surface2D& s, int first_row, int rows, const void* out, std::size_t count) {
  const texel::BitmapGeometry& g = s.geometry();
  if (first_row < 0 || rows < 0 || first_row > g.height || rows > g.height - first_row)
    throw InvalidArgument("first_row " + std::to_string(first_row) + " and rows " + std::to_string(rows) +
                          " are not within the bitmap's " + std::to_string(g.height) + " rows");
  const std::size_t n = static_cast<std::size_t>(rows) * static_cast<std::size_t>(g.width);
  if (count != n)
    throw InvalidArgument("count is " + std::to_string(count) + "; " + std::to_string(rows) + " rows of " +
                          std::to_string(g.width) + " pixels are " + std::to_string(n));
  if (n > 0 && !out) throw InvalidArgument("out is NULL");
}

std::unique_ptr<texel_encode_result> encoded(const texel::codec::Signal& signal, const texel::codec::EncoderConfig& config) {
  return std::make_unique<texel_encode_result>(texel_encode_result{texel::codec::encode(signal, config)});
}

// A map in memory, read by the library's one rule (docs/format.md "Input
// signals", Scaling): as the float64 .npy file that holds it, through the
// signal loader — values in [0, 1] as they are; a map with any value outside
// [0, 1] scaled to full range (a = 0.5 + 0.5·y/max|y|, y the zero-mean map);
// a constant map outside [0, 1], fewer than 2 samples or a non-finite value
// refused. So `texel encode map.npy` and Python's texel.encode(array) read
// the same array to the same samples. The loader's FormatErrors are about a
// file; here the array is an argument, so they become InvalidArgument naming
// `amplitudes`.
texel::Signal map_signal(const double* amplitudes, std::size_t count, double spacing_mm) {
  texel::SignalOptions options;
  options.spacing = texel::Millimetres(spacing_mm);
  const std::string npy = texel::npy_bytes(std::span<const double>(amplitudes, count));
  try {
    texel::Signal s = texel::decode_signal(texel::byte_view(npy), texel::SignalFormat::npy, options, "amplitudes");
    if (s.description.starts_with(".npy")) s.description.replace(0, 4, "C API map");
    return s;
  } catch (const texel::FormatError& e) {
    throw InvalidArgument(e.what());
  }
}

template <class Handle, class Make>
texel_status create(Handle** out, Make&& make) {
  if (out) *out = nullptr;
  return guarded([&] {
    need(out, "out");
    *out = make().release();
  });
}

/// The 2-D encoder's settings from the C structs (NULL: the defaults).
texel::codec::Encode2DConfig config2d_of(const texel_encode_options* options, const texel_encode2d_options* options2d) {
  texel::codec::Encode2DConfig config;
  if (options) config.encoder = config_of(*options);
  if (options2d) {
    config.directions = options2d->directions;
    config.scan_samples = options2d->scan_samples;
    config.correction_rounds = options2d->correction_rounds;
  }
  return config;
}
}  // namespace

extern "C" {

// ---------------------------------------------------------------- version

void texel_version(int* major, int* minor, int* patch) {
  if (major) *major = TEXEL_VERSION_MAJOR_;
  if (minor) *minor = TEXEL_VERSION_MINOR_;
  if (patch) *patch = TEXEL_VERSION_PATCH_;
}

const char* texel_version_string(void) { return TEXEL_VERSION_STRING; }

// ----------------------------------------------------------------- status

const char* texel_status_string(texel_status status) {
  switch (enum_value(status)) {
    case TEXEL_OK: return "TEXEL_OK";
    case TEXEL_INVALID_ARGUMENT: return "TEXEL_INVALID_ARGUMENT";
    case TEXEL_FORMAT_ERROR: return "TEXEL_FORMAT_ERROR";
    case TEXEL_IO_ERROR: return "TEXEL_IO_ERROR";
    case TEXEL_BUFFER_TOO_SMALL: return "TEXEL_BUFFER_TOO_SMALL";
    case TEXEL_OUT_OF_MEMORY: return "TEXEL_OUT_OF_MEMORY";
    case TEXEL_INTERNAL: return "TEXEL_INTERNAL";
  }
  return "unknown status";
}

const char* texel_last_error(void) { return t_fixed ? t_fixed : t_message.c_str(); }

// ---------------------------------------------------------------- devices

texel_status texel_device_lookup(const char* name_or_path, texel_device_info* out) {
  return guarded([&] {
    need(out, "out");
    *out = info_of(device_named(name_or_path));
  });
}

texel_params texel_params_default(void) {
  const texel::TexelSpec s;
  texel_params p{};
  p.central_pitch_db = s.central_pitch.value();
  p.irregularity_db = s.irregularity.value();
  p.texel_length_mm = s.texel_length.value();
  p.seed = s.seed;
  p.parameterization = TEXEL_PARAMETERIZATION_MOMENTS;
  p.quantization_db = s.quantization_db;
  p.coarse_strength = s.coarse_strength;
  p.fine_strength = s.fine_strength;
  p.coarse_sine_period_mm = 0.0;
  p.coarse_sine_phase_deg = 0.0;
  return p;
}

// -------------------------------------------------------------- documents

texel_status texel_document_load(const char* path, texel_document** out) {
  return create(out,
                [&] { return std::make_unique<texel_document>(texel_document{texel::load_document(need_text(path, "path"))}); });
}

texel_status texel_document_parse(const char* json, std::size_t length, texel_document** out) {
  return create(out, [&] {
    const std::string_view text(need_text(json, "json"), length);
    return std::make_unique<texel_document>(texel_document{texel::parse_document(text, "json")});
  });
}

texel_status texel_document_from_params(const char* device, const texel_params* params, texel_document** out) {
  return create(out, [&] {
    const texel::TexelSpec spec = spec_of(need(params, "params"));
    return std::make_unique<texel_document>(texel_document{texel::make_document(device_named(device), spec)});
  });
}

texel_status texel_document_from_reference(const char* device, const char* name, std::uint64_t seed, texel_document** out) {
  return create(out, [&] {
    texel::ReferenceSpec spec;
    spec.name = need_text(name, "name");
    spec.seed = seed;
    texel::validate(spec);
    texel::Document doc = texel::make_reference_document(device_named(device), spec);
    doc.description = "Texel reference " + spec.name;  // as `texel reference`
    return std::make_unique<texel_document>(texel_document{std::move(doc)});
  });
}

texel_status texel_document_json(const texel_document* doc, char* buffer, std::size_t capacity, std::size_t* needed) {
  return guarded([&] {
    const std::string text = texel::document_json(need(doc, "doc").doc);
    copy_out(text.c_str(), text.size() + 1, buffer, capacity, needed);
  });
}

void texel_document_destroy(texel_document* doc) { delete doc; }

// --------------------------------------------------------------- surfaces

texel_status texel_surface_create(const texel_document* doc, texel_surface** out) {
  return create(out, [&] {
    const texel::Document& d = need(doc, "doc").doc;
    return std::make_unique<texel_surface>(texel_surface{d.device, texel::prepare_surface(d)});
  });
}

texel_status texel_surface_from_params(const char* device, const texel_params* params, texel_surface** out) {
  return create(out, [&] {
    const texel::TexelSpec spec = spec_of(need(params, "params"));
    const texel::Document d = texel::make_document(device_named(device), spec);
    return std::make_unique<texel_surface>(texel_surface{d.device, texel::prepare_surface(d)});
  });
}

texel_status texel_surface_device(const texel_surface* surface, texel_device_info* out) {
  return guarded([&] {
    const texel_surface& s = need(surface, "surface");
    need(out, "out") = info_of(s.device);
  });
}

texel_status texel_surface_size(const texel_surface* surface, std::size_t* samples) {
  return guarded([&] {
    const texel_surface& s = need(surface, "surface");
    need(samples, "samples") = static_cast<std::size_t>(s.surface.grid().count);
  });
}

texel_status texel_surface_render(const texel_surface* surface, std::int64_t first, double* out, std::size_t count) {
  return guarded([&] {
    const texel_surface& s = need(surface, "surface");
    check_window(s, first, count);
    if (count == 0) return;
    need(out, "out");
    s.surface.render(first, std::span<double>(out, count));
  });
}

texel_status texel_surface_render_u16(const texel_surface* surface, std::int64_t first, std::uint16_t* out, std::size_t count) {
  return guarded([&] {
    const texel_surface& s = need(surface, "surface");
    check_window(s, first, count);
    if (count == 0) return;
    need(out, "out");
    render_chunks(s, first, count, [&](std::span<const double> a, std::size_t at) {
      texel::encode_u16(a, std::span<std::uint16_t>(out + at, a.size()));
    });
  });
}

texel_status texel_surface_render_native(const texel_surface* surface, std::int64_t first, std::size_t count, void* buffer,
                                         std::size_t capacity, std::size_t* needed) {
  return guarded([&] {
    const texel_surface& s = need(surface, "surface");
    check_window(s, first, count);
    const std::size_t bps = texel::bytes_per_sample(s.device.format);
    if (!check_buffer(count * bps, buffer, capacity, needed)) return;  // count <= samples: no overflow
    auto* bytes = static_cast<std::byte*>(buffer);
    render_chunks(s, first, count, [&](std::span<const double> a, std::size_t at) {
      texel::encode_samples(s.device.format, a, std::span<std::byte>(bytes + at * bps, a.size() * bps));
    });
  });
}

void texel_surface_destroy(texel_surface* surface) { delete surface; }

// ------------------------------------------------------------------ codec

texel_encode_options texel_encode_options_default(void) {
  const texel::codec::EncoderConfig c;
  texel_encode_options o{};
  o.boundary_mm = c.boundary.value();
  o.texel_length_mm = c.texel_length.value();
  o.parameterization =
      c.parameterization == texel::Parameterization::log ? TEXEL_PARAMETERIZATION_LOG : TEXEL_PARAMETERIZATION_MOMENTS;
  o.seed = c.seed;
  o.coarse_bits = c.coarse_bits;
  o.max_bytes = c.max_bytes.value_or(0);
  o.recover_texel = c.recover_texel ? 1 : 0;
  o.swipe_speed_mm_s = c.model.swipe_speed.value();
  o.model_version = c.model.version;
  o.refuse_no_texture = c.no_texture == texel::codec::EncoderConfig::NoTexture::refuse ? 1 : 0;
  o.target = TEXEL_TARGET_AUTOMATIC;
  return o;
}

texel_status texel_encode_with(const double* amplitudes, std::size_t count, double spacing_mm,
                               const texel_encode_options* options, texel_encode_result** out) {
  return create(out, [&] {
    if (count > 0) need(amplitudes, "amplitudes");
    need_finite(spacing_mm, "spacing_mm");
    const texel::codec::EncoderConfig config = options ? config_of(*options) : texel::codec::EncoderConfig{};
    return encoded(texel::codec::encoder_signal(map_signal(amplitudes, count, spacing_mm)), config);
  });
}

texel_status texel_encode(const double* amplitudes, std::size_t count, double spacing_mm, texel_encode_result** out) {
  return texel_encode_with(amplitudes, count, spacing_mm, nullptr, out);
}

texel_status texel_encode_file(const char* path, const char* device, double swipe_speed_mm_s, const texel_encode_options* options,
                               texel_encode_result** out) {
  return create(out, [&] {
    need_text(path, "path");
    need_finite(swipe_speed_mm_s, "swipe_speed_mm_s");
    if (swipe_speed_mm_s < 0.0)
      throw InvalidArgument("swipe_speed_mm_s is " + num(swipe_speed_mm_s) + "; allowed: 0 (none) or a speed > 0 mm/s");
    texel::SignalOptions lo;
    if (device) lo.device = texel::load_device(device);
    if (swipe_speed_mm_s > 0.0) lo.swipe_speed = texel::MmPerSecond(swipe_speed_mm_s);
    texel::codec::EncoderConfig config = options ? config_of(*options) : texel::codec::EncoderConfig{};
    if (lo.swipe_speed) config.model.swipe_speed = *lo.swipe_speed;  // as texel encode --swipe-speed
    if (lo.device) config.model.display = lo.device->response;       // as texel encode --device
    const texel::Signal signal = texel::codec::load_signal(path, lo);
    return encoded(texel::codec::encoder_signal(signal), config);
  });
}

texel_status texel_encode_result_bytes(const texel_encode_result* result, std::uint8_t* buffer, std::size_t capacity,
                                       std::size_t* needed) {
  return guarded([&] {
    const auto& bytes = need(result, "result").result.bytes;
    copy_out(bytes.data(), bytes.size(), buffer, capacity, needed);
  });
}

texel_status texel_encode_result_params(const texel_encode_result* result, texel_params* out, int* has_coarse_profile) {
  return guarded([&] {
    const auto& r = need(result, "result").result;
    need(out, "out") = params_of(r.spec, has_coarse_profile);
  });
}

texel_status texel_encode_result_distance(const texel_encode_result* result, double* jnd) {
  return guarded([&] {
    const auto& r = need(result, "result").result;
    need(jnd, "jnd") = r.model_distance;
  });
}

texel_status texel_encode_result_flags(const texel_encode_result* result, texel_encode_flags* out) {
  return guarded([&] {
    const auto& r = need(result, "result").result;
    texel_encode_flags& f = need(out, "out");
    f.model_version = r.model_version;
    f.no_texture = r.no_texture ? 1 : 0;
    f.central_pitch_at_bound = r.at_bound.central_pitch ? 1 : 0;
    f.irregularity_at_bound = r.at_bound.irregularity ? 1 : 0;
    f.irregularity_identifiable = r.irregularity_identifiable ? 1 : 0;
    f.target = r.target == texel::codec::EncoderConfig::Target::centroid ? TEXEL_TARGET_CENTROID : TEXEL_TARGET_FELT;
  });
}

void texel_encode_result_destroy(texel_encode_result* result) { delete result; }

texel_status texel_decode(const std::uint8_t* bytes, std::size_t size, const char* device, texel_document** out) {
  return create(out, [&] {
    if (size > 0) need(bytes, "bytes");
    const texel::codec::Bitstream b = texel::codec::parse_bitstream(std::as_bytes(std::span<const std::uint8_t>(bytes, size)));
    texel::Document doc = texel::codec::decode_document(b, device_named(device));
    return std::make_unique<texel_document>(texel_document{std::move(doc)});
  });
}

// --------------------------------------------------------------- spectrum

texel_spectrum_options texel_spectrum_options_default(void) {
  const texel::AnalysisOptions a;
  texel_spectrum_options o{};
  o.window = TEXEL_WINDOW_BLACKMAN_HARRIS;
  o.zero_pad = static_cast<unsigned>(a.spectrum.zero_pad);
  o.threshold_db = a.peaks.threshold.value();
  o.max_peaks = a.peaks.max_peaks;
  o.welch_segment = a.welch.segment;
  o.welch_overlap = a.welch.overlap;
  return o;
}

texel_status texel_spectrum_analyse(const double* amplitudes, std::size_t count, double spacing_mm,
                                    const texel_spectrum_options* options, texel_spectrum** out) {
  return create(out, [&] {
    const texel_spectrum_options o = options ? *options : texel_spectrum_options_default();
    texel::AnalysisOptions a;
    switch (enum_value(o.window)) {
      case TEXEL_WINDOW_BLACKMAN_HARRIS: a.spectrum.window = texel::Window::blackman_harris; break;
      case TEXEL_WINDOW_HANN: a.spectrum.window = texel::Window::hann; break;
      case TEXEL_WINDOW_FLAT_TOP: a.spectrum.window = texel::Window::flat_top; break;
      case TEXEL_WINDOW_RECTANGULAR: a.spectrum.window = texel::Window::rectangular; break;
      default:
        throw InvalidArgument("window is " + std::to_string(enum_value(o.window)) +
                              "; allowed: TEXEL_WINDOW_BLACKMAN_HARRIS (0), TEXEL_WINDOW_HANN (1), TEXEL_WINDOW_FLAT_TOP (2), "
                              "TEXEL_WINDOW_RECTANGULAR (3)");
    }
    // The ranges `texel spectrum` checks, under the C field names.
    if (o.zero_pad < 1 || o.zero_pad > 16)
      throw InvalidArgument("zero_pad is " + std::to_string(o.zero_pad) + "; allowed: 1 … 16");
    need_finite(o.threshold_db, "threshold_db");
    if (!(o.threshold_db <= 0.0 && o.threshold_db >= -300.0))
      throw InvalidArgument("threshold_db is " + num(o.threshold_db) + " dB; allowed: -300 … 0");
    if (o.max_peaks < 1 || o.max_peaks > 100000)
      throw InvalidArgument("max_peaks is " + std::to_string(o.max_peaks) + "; allowed: 1 … 100000");
    need_finite(o.welch_overlap, "welch_overlap");
    if (!(o.welch_overlap >= 0.0 && o.welch_overlap <= 0.95))
      throw InvalidArgument("welch_overlap is " + num(o.welch_overlap) + "; allowed: 0 … 0.95");
    need_finite(spacing_mm, "spacing_mm");
    if (count > 0) need(amplitudes, "amplitudes");
    if (count < 16) throw InvalidArgument("count is " + std::to_string(count) + " samples; a spectrum needs at least 16");
    a.spectrum.zero_pad = static_cast<int>(o.zero_pad);
    a.peaks.threshold = texel::DecibelsLevel{o.threshold_db};
    a.peaks.max_peaks = o.max_peaks;
    a.welch.segment = o.welch_segment;
    a.welch.overlap = o.welch_overlap;
    auto s = std::make_unique<texel_spectrum>();
    s->report = texel::analyse_spectrum(std::span<const double>(amplitudes, count), texel::Millimetres(spacing_mm), a);
    s->samples = count;
    s->spacing_mm = spacing_mm;
    return s;
  });
}

texel_status texel_spectrum_get_summary(const texel_spectrum* spectrum, texel_spectrum_summary* out) {
  return guarded([&] {
    const texel_spectrum& s = need(spectrum, "spectrum");
    const texel::SpectralReport& r = s.report;
    texel_spectrum_summary m{};
    m.samples = s.samples;
    m.spacing_mm = s.spacing_mm;
    m.nfft = r.spectrum.nfft;
    m.bin_cpm = r.spectrum.bin.value();
    m.resolution_cpm = r.spectrum.resolution.value();
    m.mean_amplitude = r.mean;
    m.rms_amplitude = r.rms;
    m.centroid_cpm = r.summary.centroid.value();
    m.log_centroid_db = r.summary.log_centroid.value();
    m.spread_cpm = r.summary.spread.value();
    m.log_spread_db = r.summary.log_spread.value();
    m.welch_segment = r.psd.segment;
    m.welch_segments = r.psd.segments;
    m.psd_bin_cpm = r.psd.bin.value();
    need(out, "out") = m;
  });
}

texel_status texel_spectrum_get_series(const texel_spectrum* spectrum, texel_spectrum_series series, double* values,
                                       std::size_t capacity, std::size_t* needed) {
  return guarded([&] {
    const texel::SpectralReport& r = need(spectrum, "spectrum").report;
    std::vector<double> picked;
    const std::vector<double>* v = &picked;
    switch (enum_value(series)) {
      case TEXEL_SERIES_FREQUENCY_CPM: v = &r.spectrum.frequency_cpm; break;
      case TEXEL_SERIES_MAGNITUDE: v = &r.spectrum.magnitude; break;
      case TEXEL_SERIES_PSD_FREQUENCY_CPM: v = &r.psd.frequency_cpm; break;
      case TEXEL_SERIES_PSD: v = &r.psd.density; break;
      case TEXEL_SERIES_PEAK_FREQUENCY_CPM:
        for (const auto& p : r.peaks) picked.push_back(p.frequency.value());
        break;
      case TEXEL_SERIES_PEAK_AMPLITUDE:
        for (const auto& p : r.peaks) picked.push_back(p.amplitude);
        break;
      case TEXEL_SERIES_PEAK_LEVEL_DB:
        for (const auto& p : r.peaks) picked.push_back(p.level.value());
        break;
      case TEXEL_SERIES_BAND_LO_CPM:
        for (const auto& b : r.bands) picked.push_back(b.lo.value());
        break;
      case TEXEL_SERIES_BAND_HI_CPM:
        for (const auto& b : r.bands) picked.push_back(b.hi.value());
        break;
      case TEXEL_SERIES_BAND_MEAN_SQUARE:
        for (const auto& b : r.bands) picked.push_back(b.mean_square);
        break;
      case TEXEL_SERIES_BAND_FRACTION:
        for (const auto& b : r.bands) picked.push_back(b.fraction);
        break;
      default:
        throw InvalidArgument("series is " + std::to_string(enum_value(series)) +
                              "; allowed: TEXEL_SERIES_FREQUENCY_CPM (0) … TEXEL_SERIES_BAND_FRACTION (10)");
    }
    if (!check_count(v->size(), values, capacity, needed, "values", "values")) return;
    std::copy(v->begin(), v->end(), values);
  });
}

void texel_spectrum_destroy(texel_spectrum* spectrum) { delete spectrum; }

// ----------------------------------------------------------------- player

texel_player_config texel_player_config_default(void) {
  const texel::PlayerConfig c;
  texel_player_config p{};
  p.rate_hz = c.rate_hz;
  p.mode = TEXEL_OUTPUT_AMPLITUDE;
  p.gain = c.gain;
  p.carrier_hz = c.carrier_hz;
  p.prediction_s = c.prediction_s;
  p.response_handling = TEXEL_RESPONSE_LIMIT;
  p.response_limit_db = c.response_limit_db;
  return p;
}

texel_status texel_player_create(const texel_player_config* config, texel_player** out) {
  return create(out, [&] { return std::make_unique<texel_player>(player_config_of(need(config, "config"))); });
}

texel_status texel_player_set_surface(texel_player* player, const texel_surface* surface) {
  return guarded([&] {
    texel_player& p = need(player, "player");
    const texel_surface& s = need(surface, "surface");
    // The map carries the surface's device response (player.hpp).
    p.player.set_map(texel::PlayerMap::from_surface(s.surface, s.device.response));
  });
}

texel_status texel_player_push(texel_player* player, double t_s, double x_mm, int touch) {
  return guarded([&] {
    texel_player& p = need(player, "player");
    need_finite(t_s, "t_s");
    need_finite(x_mm, "x_mm");
    if (!p.player.push(texel::FingerSample{t_s, x_mm, touch != 0}))
      throw BufferTooSmall{"the player's event queue is full (" + std::to_string(p.player.event_capacity()) +
                           " events); let texel_player_process run, then push again"};
  });
}

texel_status texel_player_set_gain(texel_player* player, double gain) {
  return guarded([&] {
    texel_player& p = need(player, "player");
    need_finite(gain, "gain");
    if (!p.player.set_gain(gain))
      throw BufferTooSmall{"the player's event queue is full; let texel_player_process run, then try again"};
  });
}

texel_status texel_player_collect(texel_player* player, std::size_t* freed) {
  return guarded([&] {
    const std::size_t n = need(player, "player").player.collect();
    if (freed) *freed = n;
  });
}

texel_status texel_player_process(texel_player* player, float* out, std::size_t frames, float* positions_mm) {
  // Real-time: no guarded() (its error slot is a std::string), no allocation.
  if (!player || (!out && frames > 0)) return TEXEL_INVALID_ARGUMENT;
  if (frames == 0) return TEXEL_OK;
  std::span<float> pos;
  if (positions_mm) pos = std::span<float>(positions_mm, frames);
  (void)player->player.process(std::span<float>(out, frames), pos);  // noexcept
  return TEXEL_OK;
}

std::uint64_t texel_player_samples(const texel_player* player) { return player ? player->player.samples() : 0; }

void texel_player_destroy(texel_player* player) { delete player; }

// ----------------------------------------------------------- 2-D surfaces

texel_status texel_surface2d_create(const texel_document* doc, texel_surface2d** out) {
  return create(
      out, [&] { return std::make_unique<texel_surface2d>(texel_surface2d{texel::prepare_surface2d(need(doc, "doc").doc)}); });
}

texel_status texel_surface2d_info(const texel_surface2d* surface, texel_bitmap_info* out) {
  return guarded([&] {
    const texel::BitmapGeometry& g = need(surface, "surface").surface.geometry();
    texel_bitmap_info& i = need(out, "out");
    i.width_px = g.width;
    i.height_px = g.height;
    i.pixel_pitch_mm = g.pitch.value();
    i.depth_bits = g.depth;
    i.polarity =
        g.polarity == texel::BitmapPolarity::brighter_more_friction ? TEXEL_BRIGHTER_MORE_FRICTION : TEXEL_DARKER_MORE_FRICTION;
  });
}

texel_status texel_surface2d_render_rows(const texel_surface2d* surface, int first_row, int rows, double* out,
                                         std::size_t count) {
  return guarded([&] {
    const texel::Surface2D& s = need(surface, "surface").surface;
    check_rows(s, first_row, rows, out, count);
    if (count > 0) s.render_rows(first_row, rows, std::span<double>(out, count));
  });
}

texel_status texel_surface2d_render_pixels(const texel_surface2d* surface, int first_row, int rows, int depth_bits,
                                           std::uint16_t* out, std::size_t count) {
  return guarded([&] {
    const texel::Surface2D& s = need(surface, "surface").surface;
    if (depth_bits != 0 && depth_bits != 8 && depth_bits != 16)
      throw InvalidArgument("depth_bits is " + std::to_string(depth_bits) + "; allowed: 0 (the device's), 8, 16");
    check_rows(s, first_row, rows, out, count);
    if (count > 0) texel::render_pixel_rows(s, first_row, rows, depth_bits, std::span<std::uint16_t>(out, count));
  });
}

texel_status texel_surface2d_write(const texel_surface2d* surface, const char* path, int depth_bits) {
  return guarded([&] {
    const texel::Surface2D& s = need(surface, "surface").surface;
    if (depth_bits != 0 && depth_bits != 8 && depth_bits != 16)
      throw InvalidArgument("depth_bits is " + std::to_string(depth_bits) + "; allowed: 0 (the device's), 8, 16");
    texel::BitmapFileOptions o;
    o.depth = depth_bits;
    texel::write_bitmap(need_text(path, "path"), s, o);
  });
}

void texel_surface2d_destroy(texel_surface2d* surface) { delete surface; }

texel_path2d_config texel_path2d_config_default(void) {
  const texel::Path2DConfig c;
  texel_path2d_config p{};
  p.shape = TEXEL_PATH2D_LINE;
  copy_path_numbers(c, p);
  return p;
}

texel_status texel_path2d_simulate(const texel_path2d_config* config, texel_finger2d* trace, std::size_t capacity,
                                   std::size_t* needed) {
  return guarded([&] {
    const texel_path2d_config& c = need(config, "config");
    texel::Path2DConfig p;
    p.shape = choose<texel::Path2DShape>(c.shape, "shape",
                                         {{TEXEL_PATH2D_LINE, texel::Path2DShape::line, "TEXEL_PATH2D_LINE"},
                                          {TEXEL_PATH2D_CIRCLE, texel::Path2DShape::circle, "TEXEL_PATH2D_CIRCLE"},
                                          {TEXEL_PATH2D_ZIGZAG, texel::Path2DShape::zigzag, "TEXEL_PATH2D_ZIGZAG"}});
    copy_path_numbers(c, p);
    const std::vector<texel::FingerSample2D> samples = texel::simulate_path_2d(p);
    if (!check_count(samples.size(), trace, capacity, needed, "trace", "samples")) return;
    for (std::size_t i = 0; i < samples.size(); ++i)
      trace[i] = texel_finger2d{samples[i].x_mm, samples[i].y_mm, samples[i].t_s, samples[i].touch ? 1 : 0};
  });
}

texel_status texel_swipe_2d(const texel_document* doc, const texel_finger2d* trace, std::size_t samples, texel_map2d_mode mode,
                            texel_path_at_lift at_lift, const texel_player_config* config, float* out, std::size_t frames,
                            float* x_mm, float* y_mm) {
  return guarded([&] {
    const texel::Document& d = need(doc, "doc").doc;
    texel::PlayerConfig pc = player_config_of(need(config, "config"));
    pc.response = d.device.response;  // the display's, as `texel swipe` takes it
    if (samples > 0) need(trace, "trace");
    if (frames > 0) need(out, "out");
    const auto lift = choose<texel::PathAtLift>(at_lift, "at_lift",
                                                {{TEXEL_PATH_KEEP, texel::PathAtLift::keep, "TEXEL_PATH_KEEP"},
                                                 {TEXEL_PATH_RESET, texel::PathAtLift::reset, "TEXEL_PATH_RESET"}});
    std::vector<texel::FingerSample2D> t(samples);
    for (std::size_t i = 0; i < samples; ++i) {
      const texel_finger2d& f = trace[i];
      if (!std::isfinite(f.x_mm) || !std::isfinite(f.y_mm) || !std::isfinite(f.t_s))
        throw InvalidArgument("trace[" + std::to_string(i) + "] is not finite");
      if (i > 0 && !(f.t_s >= t[i - 1].t_s))
        throw InvalidArgument("trace[" + std::to_string(i) + "].t_s is below the sample before; times must be non-decreasing");
      t[i] = texel::FingerSample2D{f.t_s, f.x_mm, f.y_mm, f.touch != 0};
    }
    const bool bitmap = choose<bool>(
        mode, "mode", {{TEXEL_MAP2D_PATH, false, "TEXEL_MAP2D_PATH"}, {TEXEL_MAP2D_BITMAP, true, "TEXEL_MAP2D_BITMAP"}});
    const std::unique_ptr<const texel::PlayerMap2D> map =
        bitmap ? texel::PlayerMap2D::bitmap(texel::render_raster(texel::prepare_surface2d(d)), d.device.response)
               : texel::PlayerMap2D::path_indexed(d, d.surface2d ? std::optional(texel::coarse_raster(d)) : std::nullopt);
    std::vector<float> xs, ys;
    const std::vector<float> o =
        texel::render_trace_2d(*map, pc, t, frames, x_mm ? &xs : nullptr, y_mm ? &ys : nullptr, 64, lift);
    std::copy(o.begin(), o.end(), out);
    if (x_mm) std::copy(xs.begin(), xs.end(), x_mm);
    if (y_mm) std::copy(ys.begin(), ys.end(), y_mm);
  });
}

// ------------------------------------------------------------ 2-D encoding

texel_encode2d_options texel_encode2d_options_default(void) {
  const texel::codec::Encode2DConfig c;
  texel_encode2d_options o{};
  o.directions = c.directions;
  o.scan_samples = c.scan_samples;
  o.correction_rounds = c.correction_rounds;
  return o;
}

texel_status texel_encode_2d(const double* amplitudes, int width_px, int height_px, double pitch_mm,
                             const texel_encode_options* options, const texel_encode2d_options* options2d,
                             texel_encode2d_result** out) {
  return create(out, [&] {
    need_finite(pitch_mm, "pitch_mm");
    if (width_px < 1 || height_px < 1)
      throw InvalidArgument("width_px and height_px are " + std::to_string(width_px) + " and " + std::to_string(height_px) +
                            "; both must be >= 1");
    need(amplitudes, "amplitudes");
    texel::codec::Encode2DConfig config = config2d_of(options, options2d);
    texel::Raster2D map;
    map.width = width_px;
    map.height = height_px;
    map.pitch = texel::Millimetres(pitch_mm);
    // The one input rule, on the doubles given (as the CLI applies it to a .npy's): texel::to_amplitudes.
    std::vector<double> values(amplitudes, amplitudes + static_cast<std::size_t>(width_px) * static_cast<std::size_t>(height_px));
    try {
      (void)texel::to_amplitudes(values, "amplitudes");
    } catch (const texel::FormatError& e) {
      throw InvalidArgument(e.what());  // an argument, not a file (as map_signal)
    }
    map.values.assign(values.begin(), values.end());
    return std::make_unique<texel_encode2d_result>(texel_encode2d_result{texel::codec::encode_surface2d(map, config)});
  });
}

texel_status texel_encode_2d_file(const char* path, double pitch_mm, const char* device, int polarity, double swipe_speed_mm_s,
                                  const texel_encode_options* options, const texel_encode2d_options* options2d,
                                  texel_encode2d_result** out) {
  return create(out, [&] {
    need_text(path, "path");
    need_finite(pitch_mm, "pitch_mm");
    need_finite(swipe_speed_mm_s, "swipe_speed_mm_s");
    if (pitch_mm < 0.0) throw InvalidArgument("pitch_mm is " + num(pitch_mm) + "; allowed: 0 (the device's) or a pitch > 0 mm");
    if (swipe_speed_mm_s < 0.0)
      throw InvalidArgument("swipe_speed_mm_s is " + num(swipe_speed_mm_s) + "; allowed: 0 (none) or a speed > 0 mm/s");
    if (polarity != -1 && polarity != TEXEL_DARKER_MORE_FRICTION && polarity != TEXEL_BRIGHTER_MORE_FRICTION)
      throw InvalidArgument("polarity is " + std::to_string(polarity) +
                            "; allowed: -1 (the device's), TEXEL_DARKER_MORE_FRICTION (0), TEXEL_BRIGHTER_MORE_FRICTION (1)");
    texel::codec::Encode2DConfig config = config2d_of(options, options2d);
    texel::codec::Raster2DLoadOptions load;
    texel::SignalOptions signal;
    if (pitch_mm > 0.0) load.pitch = signal.spacing = texel::Millimetres(pitch_mm);
    if (device) {
      load.device = signal.device = texel::load_device(device);
      config.encoder.model.display = load.device->response;  // as texel encode --device
      if (load.device->bitmap) config.device = load.device;
    }
    if (polarity != -1)
      load.polarity = polarity == TEXEL_BRIGHTER_MORE_FRICTION ? texel::BitmapPolarity::brighter_more_friction
                                                               : texel::BitmapPolarity::darker_more_friction;
    if (swipe_speed_mm_s > 0.0) config.encoder.model.swipe_speed = *(signal.swipe_speed = texel::MmPerSecond(swipe_speed_mm_s));
    return std::make_unique<texel_encode2d_result>(
        texel_encode2d_result{texel::codec::encode_2d_file(path, load, signal, config)});
  });
}

texel_status texel_encode2d_result_document(const texel_encode2d_result* result, texel_document** out) {
  return create(out, [&] { return std::make_unique<texel_document>(texel_document{need(result, "result").result.document}); });
}

texel_status texel_encode2d_result_json(const texel_encode2d_result* result, char* buffer, std::size_t capacity,
                                        std::size_t* needed) {
  return guarded([&] {
    const std::string text = texel::codec::to_json(need(result, "result").result);
    copy_out(text.c_str(), text.size() + 1, buffer, capacity, needed);
  });
}

texel_status texel_encode2d_result_save(const texel_encode2d_result* result, const char* document_path) {
  return guarded(
      [&] { texel::codec::write_encoding2d(need(result, "result").result, need_text(document_path, "document_path")); });
}

void texel_encode2d_result_destroy(texel_encode2d_result* result) { delete result; }

}  // extern "C"
