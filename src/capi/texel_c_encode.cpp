// The C ABI: the encoder (a map, in memory or a file, to its bitstream and
// parameters) and the decoder (texel_c_internal.hpp).
#include "texel_c_internal.hpp"

#include <span>

#include "texel/io.hpp"

using namespace capi_detail;

namespace {

std::unique_ptr<texel_encode_result> encoded(const texel::codec::Signal& signal, const texel::codec::EncoderConfig& config) {
  return std::make_unique<texel_encode_result>(texel_encode_result{texel::codec::encode(signal, config)});
}

}  // namespace

namespace capi_detail {

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

}  // namespace capi_detail

extern "C" {

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

}  // extern "C"
