// The C ABI: 2-D surfaces, simulated 2-D finger paths, swipes over a 2-D
// map, and the 2-D encoder (texel_c_internal.hpp).
#include "texel_c_internal.hpp"

#include <cmath>
#include <span>
#include <vector>

#include "texel/bitmap_file.hpp"
#include "texel/io.hpp"
#include "texel/player2d.hpp"

using namespace capi_detail;

namespace {

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
