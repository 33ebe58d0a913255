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
// One source per API area, sharing texel_c_internal.hpp: this file (version,
// status and the error slot, devices, documents and the conversions the
// areas share), texel_c_surface.cpp (1-D maps), texel_c_encode.cpp (encoder,
// decoder), texel_c_spectrum.cpp, texel_c_player.cpp, texel_c_2d.cpp (2-D
// surfaces, paths and the 2-D encoder).
//
// texel_player_process is the exception: it is real-time, so it neither
// allocates nor touches the (std::string) error slot; it only returns a code.
#include "texel_c_internal.hpp"

#include <cmath>
#include <cstdio>
#include <variant>

#include "texel/reference.hpp"

using namespace capi_detail;

namespace {

texel_sample_format to_c(texel::SampleFormat f) {
  switch (f) {
    case texel::SampleFormat::u16le: return TEXEL_SAMPLE_U16LE;
    case texel::SampleFormat::u8: return TEXEL_SAMPLE_U8;
    case texel::SampleFormat::f32le: return TEXEL_SAMPLE_F32LE;
    case texel::SampleFormat::f64le: return TEXEL_SAMPLE_F64LE;
  }
  return TEXEL_SAMPLE_U16LE;
}

texel_parameterization to_c(texel::Parameterization p) {
  return p == texel::Parameterization::log ? TEXEL_PARAMETERIZATION_LOG : TEXEL_PARAMETERIZATION_MOMENTS;
}

}  // namespace

namespace capi_detail {

// The last error of this thread.
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

const char* need_text(const char* p, const char* name) {
  if (!p) throw InvalidArgument(std::string(name) + " is NULL");
  return p;
}

void need_finite(double v, const char* name) {
  if (!std::isfinite(v)) throw InvalidArgument(std::string(name) + " is not a finite number");
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

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

texel::Parameterization parameterization_of(const texel_parameterization& p) {
  switch (enum_value(p)) {
    case TEXEL_PARAMETERIZATION_MOMENTS: return texel::Parameterization::moments;
    case TEXEL_PARAMETERIZATION_LOG: return texel::Parameterization::log;
    default:
      throw InvalidArgument("parameterization is " + std::to_string(enum_value(p)) +
                            "; allowed: TEXEL_PARAMETERIZATION_MOMENTS (0), TEXEL_PARAMETERIZATION_LOG (1)");
  }
}

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

texel::DeviceProfile device_named(const char* name) { return texel::load_device(need_text(name, "device")); }

}  // namespace capi_detail

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

}  // extern "C"
