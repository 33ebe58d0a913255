// The 2-D encoder (docs/encoder.md "2-D inputs"): the plane's coarse/fine
// split, straight scans encoded by the 1-D encoder, the correction through
// the 2-D design by analysis-by-synthesis, the lattice of cell borders, and
// the version-4 document. The raster helpers (encode2d_raster.cpp) and the
// lattice detection (encode2d_lattice.cpp) are shared through
// encode2d_parts.hpp; the result's JSON and files are encode2d_output.cpp.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numeric>

#include <nlohmann/json.hpp>

#include "encode2d_parts.hpp"
#include "texel/detail/format.hpp"
#include "texel/encode2d.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/signal.hpp"
#include "texel/surface2d.hpp"

namespace texel::codec {
namespace {

using namespace encode2d_parts;

/// The cosine law's spread in natural-log units (π/√12): the narrowest log
/// spread a straight scan of a stationary isotropic field can have.
constexpr double kCosineSigma = 0.9068996821171089;
/// [choice] The log spread (natural units) a not identifiable Irregularity
/// is reported at: a narrow texture (moments: SD a tenth of the mean).
constexpr double kNarrowSigma = 0.1;
/// [measured] How much higher the scans of a narrow texture's isotropic
/// field feel than the texture, under model 2 (2.2–2.4 dB on the test grid:
/// docs/encoder.md "2-D inputs"): the design correction's first guess.
constexpr double kNarrowScanOffsetDb = 2.3;
/// Largest candidate raster side rendered for the design correction.
constexpr int kCandidateSide = 1024;
/// Directions a candidate (an isotropic design) is scanned along.
constexpr int kCandidateDirections = 6;

// --- log spread and Irregularity ------------------------------------------------

double log_sigma(double p_db, double i_db, Parameterization param) {
  if (param == Parameterization::log) return i_db * std::log(10.0) / 10.0;
  const double r = std::pow(10.0, (i_db - p_db) / 10.0);  // s/m
  return std::sqrt(std::log1p(r * r));
}
double irregularity_for_sigma(double p_db, double sigma, Parameterization param) {
  if (param == Parameterization::log) return sigma * 10.0 / std::log(10.0);
  return p_db + 10.0 * std::log10(std::sqrt(std::expm1(sigma * sigma)));
}

// --- scans encoded by the 1-D encoder ----------------------------------------

/// A zero-mean signal as the 1-D encoder's amplitude in [0, 1].
Signal as_signal(const std::vector<double>& y, double spacing, std::string description) {
  double peak = 0.0;
  for (double v : y) peak = std::max(peak, std::abs(v));
  Signal s;
  s.spacing = Millimetres(spacing);
  s.description = std::move(description);
  s.amplitude.resize(y.size());
  for (std::size_t k = 0; k < y.size(); ++k) s.amplitude[k] = peak > 0.0 ? 0.5 + 0.5 * y[k] / peak : 0.5;
  return s;
}

DirectionEncode encode_direction(const Signal& s, double direction, int lines, const EncoderConfig& cfg) {
  const EncodeResult r = encode(s, cfg);
  DirectionEncode d;
  d.direction_deg = direction;
  d.central_pitch_db = r.spec.central_pitch.value();
  d.irregularity_db = r.spec.irregularity.value();
  d.percept = r.input;
  d.samples = s.amplitude.size();
  d.scans = lines;
  return d;
}

/// What the analysis of a map gives.
struct Analysis {
  Envelope env;
  std::vector<DirectionEncode> directions;
  double mean_p = 0.0, mean_i = 0.0, mean_spread = 0.0;
  double range = 0.0;  ///< relative_range of the envelope
};

/// The fine part (the amplitude less its local mean, over its local RMS)
/// scanned along `directions` directions, each encoded by the 1-D encoder.
Analysis analyse(const Raster2D& map, const Encode2DConfig& cfg, int directions) {
  const int w = map.width, h = map.height;
  Analysis a;
  a.env = envelope(map, cfg.encoder.boundary.value());
  a.range = relative_range(a.env, w, h);
  double rms_max = 0.0;
  for (double r : a.env.rms) rms_max = std::max(rms_max, r);
  std::vector<double> fine(map.values.size(), 0.0);
  for (std::size_t k = 0; k < fine.size(); ++k) {
    const double r = a.env.rms[k];
    if (r > 1e-3 * rms_max) fine[k] = (map.values[k] - a.env.mean[k]) / r;
  }
  for (int d = 0; d < directions; ++d) {
    const double theta = 180.0 * d / directions;
    int lines = 0;
    const std::vector<double> y = scan_lines(fine, w, h, theta, cfg.scan_samples, lines);
    if (y.size() < 1024)
      throw InvalidArgument("the map is too small to scan: " + std::to_string(y.size()) + " samples along " + detail::num(theta) +
                            "° (at least 1024; " + std::to_string(w) + " × " + std::to_string(h) + " pixels)");
    a.directions.push_back(
        encode_direction(as_signal(y, map.pitch.value(), "scans at " + detail::num(theta) + "°"), theta, lines, cfg.encoder));
  }
  for (const auto& d : a.directions) {
    a.mean_p += d.central_pitch_db / directions;
    a.mean_i += d.irregularity_db / directions;
    a.mean_spread += d.percept.spread_db / directions;
  }
  return a;
}

// --- documents -----------------------------------------------------------------

DeviceProfile generated_device(int w, int h, double pitch, int depth, BitmapPolarity polarity) {
  DeviceProfile d;
  d.name = "encoded-2d";
  d.description = "The grid of an encoded 2-D map (texel encode): " + std::to_string(w) + " × " + std::to_string(h) +
                  " pixels of " + detail::num(pitch) + " mm";
  d.samples = w;
  d.spacing = Millimetres(pitch);
  d.format = SampleFormat::f32le;
  d.refresh = Hertz(6250.0);
  d.bitmap = BitmapGeometry{w, h, Millimetres(pitch), depth, polarity};
  validate(d);
  return d;
}

Document surface_document(const DeviceProfile& device, bool device_inline, int w, int h, double pitch, const TexelSpec& spec,
                          Field2D field, double orientation, const Coarse2D& coarse, std::string description) {
  Document doc;
  doc.version = 4;
  doc.device = device;
  doc.device_inline = device_inline;
  Region2DSpec r;
  r.name = "map";
  r.width = Millimetres(w * pitch);
  r.height = Millimetres(h * pitch);
  r.texel = spec;
  r.field = field;
  r.orientation_deg = orientation;
  r.coarse = coarse;
  doc.surface2d = Surface2DSpec{{r}};
  doc.description = std::move(description);
  return doc;
}

/// The fine-only rendering (C = 0, F = 1: a = 0.5 + 0.5·s) of a candidate
/// texture on a grid of w × h pixels, by the library's 2-D renderer.
Raster2D render_candidate(const TexelSpec& spec, Field2D field, double orientation, int w, int h, double pitch) {
  TexelSpec s = spec;
  s.coarse_strength = 0.0;
  s.fine_strength = 1.0;
  const Document doc = surface_document(generated_device(w, h, pitch, 16, BitmapPolarity::darker_more_friction), true, w, h,
                                        pitch, s, field, orientation, ConstantProfile{}, "candidate");
  Raster2D r = render_raster(prepare_surface2d(doc));
  r.pitch = Millimetres(pitch);
  return r;
}

TexelSpec base_spec(const EncoderConfig& c, double p_db, double i_db, double texel_length) {
  TexelSpec s;
  s.central_pitch = Decibels(p_db);
  s.irregularity = Decibels(i_db);
  s.texel_length = Millimetres(texel_length);
  s.seed = c.seed;
  s.parameterization = c.parameterization;
  return s;
}

/// The band a pitch must stay in on a grid of `pitch` mm (the 1-D encoder's
/// search box: P ≥ −19.5 dB, below the grid's Nyquist frequency; for the
/// isotropic designs 3.02 dB lower).
double clamp_pitch(double p_db, double pitch, Field2D field) {
  // Isotropic designs draw their frequencies 3.01 dB above the 1-D ones
  // (docs/algorithm.md §11.1), and those must stay below the grid's Nyquist frequency.
  const double top = 10.0 * std::log10(0.5 / pitch) - 0.05 - (field == Field2D::oriented ? 0.0 : 3.02);
  return std::clamp(p_db, -19.5, top);
}

/// The design correction (docs/encoder.md "2-D inputs" §2): candidates of
/// the document's design are rendered, analysed as the input was, and moved
/// until their scans' mean Central Pitch (and, when identifiable,
/// Irregularity) are the input's. `measure` analyses a candidate raster.
struct Corrected {
  double p = 0.0, i = 0.0;
  bool identifiable = true;
  int rounds = 0;
  double residual = 0.0;
  double fine_rms = 1.0 / 3.0;  ///< RMS of the last candidate's s
  double range = 0.0;           ///< the last candidate's envelope range
};

template <class Measure>
Corrected correct(double p_in, double i_in, double spread_in, const Encode2DConfig& cfg, Field2D field, double orientation,
                  double texel_length, int w, int h, double pitch, Measure&& measure) {
  const Parameterization param = cfg.encoder.parameterization;
  Corrected c;
  c.p = clamp_pitch(p_in, pitch, field);
  c.i = i_in;
  const int cw = std::min(w, kCandidateSide), ch = std::min(h, kCandidateSide);
  const auto round = [&](double p, double i) {
    const Raster2D r = render_candidate(base_spec(cfg.encoder, p, i, texel_length), field, orientation, cw, ch, pitch);
    double mean = 0.0, sq = 0.0;
    for (float v : r.values) mean += v;
    mean /= static_cast<double>(r.values.size());
    for (float v : r.values) sq += (v - mean) * (v - mean);
    c.fine_rms = 2.0 * std::sqrt(sq / static_cast<double>(r.values.size()));
    return measure(r);
  };
  if (cfg.correction_rounds <= 0) return c;
  std::optional<std::pair<double, double>> last;  // (candidate P, its scans' P) of the same Irregularity rule
  // Round 0: the narrowest texture at the input's pitch. If the input's
  // scans are no wider than its scans, no Irregularity is identifiable.
  if (field != Field2D::oriented) {
    // Started where a narrow texture's field is usually found: its scans
    // feel kNarrowScanOffsetDb higher than the texture (which keeps the
    // candidate off the band top, where the scans' pitch stops following).
    c.p = clamp_pitch(p_in - kNarrowScanOffsetDb, pitch, field);
    const double i_narrow = irregularity_for_sigma(c.p, kNarrowSigma, param);
    const Analysis a = round(c.p, i_narrow);
    c.range = a.range;
    ++c.rounds;
    if (spread_in <= a.mean_spread + 0.3) {
      c.identifiable = false;
      last = {c.p, a.mean_p};
      c.p = clamp_pitch(c.p + (p_in - a.mean_p), pitch, field);
      c.i = irregularity_for_sigma(c.p, kNarrowSigma, param);
      c.residual = std::abs(p_in - a.mean_p);
    }
  }
  for (int k = 0; k < cfg.correction_rounds; ++k) {
    const Analysis a = round(c.p, c.i);
    c.range = a.range;
    ++c.rounds;
    c.residual = std::abs(p_in - a.mean_p);
    // A secant step through the last two candidates of the same
    // Irregularity rule (the scans' pitch need not follow the document's
    // one to one near the band top); a unit step otherwise.
    double slope = 1.0;
    if (last && std::abs(c.p - last->first) > 0.05) {
      const double s = (a.mean_p - last->second) / (c.p - last->first);
      if (s > 0.3 && s < 3.0) slope = s;
    }
    last = {c.p, a.mean_p};
    c.p = clamp_pitch(c.p + (p_in - a.mean_p) / slope, pitch, field);
    if (c.identifiable) {
      c.i += i_in - a.mean_i;
      if (field != Field2D::oriented && log_sigma(c.p, c.i, param) < kCosineSigma) {
        c.i = irregularity_for_sigma(c.p, kCosineSigma, param);
      }
    } else {
      c.i = irregularity_for_sigma(c.p, kNarrowSigma, param);
    }
  }
  return c;
}

void fill_spread(Encode2DResult& r, bool strongest_from_pitch) {
  if (r.per_direction.empty()) return;
  double lo_p = 1e300, hi_p = -1e300, lo_i = 1e300, hi_i = -1e300;
  for (const auto& d : r.per_direction) {
    if (strongest_from_pitch && d.central_pitch_db > hi_p) r.strongest_direction_deg = d.direction_deg;
    lo_p = std::min(lo_p, d.central_pitch_db);
    hi_p = std::max(hi_p, d.central_pitch_db);
    lo_i = std::min(lo_i, d.irregularity_db);
    hi_i = std::max(hi_i, d.irregularity_db);
  }
  r.central_pitch_spread_db = hi_p - lo_p;
  r.irregularity_spread_db = hi_i - lo_i;
}

void check_config(const Encode2DConfig& c) {
  if (c.directions < 2 || c.directions > 360)
    throw InvalidArgument("directions is " + std::to_string(c.directions) + "; allowed: 2 … 360");
  if (c.scan_samples < 1024 || c.scan_samples > (std::size_t{1} << 22))
    throw InvalidArgument("scan_samples is " + std::to_string(c.scan_samples) + "; allowed: 1024 … 4194304");
  if (c.correction_rounds < 0 || c.correction_rounds > 8)
    throw InvalidArgument("correction_rounds is " + std::to_string(c.correction_rounds) + "; allowed: 0 … 8");
  if (!(c.anisotropy_threshold_db > 0.0))
    throw InvalidArgument("anisotropy_threshold_db is " + detail::num(c.anisotropy_threshold_db) + "; it must be > 0");
  if (!(c.coarse_pitch.value() >= 0.0))
    throw InvalidArgument("coarse_pitch is " + detail::num(c.coarse_pitch.value()) + " mm; it must be >= 0");
  if (c.depth != 8 && c.depth != 16) throw InvalidArgument("depth is " + std::to_string(c.depth) + "; allowed: 8, 16");
  if (c.coarse_image_path.empty() || output_extension(c.coarse_image_path) != ".npy")
    throw InvalidArgument("coarse_image_path '" + c.coarse_image_path + "' must name a .npy file");
}

/// The document's device: the configured one (the map must fit its bitmap
/// at its pitch) or a generated profile of the map's grid.
std::pair<DeviceProfile, bool> document_device(const Encode2DConfig& cfg, int w, int h, double pitch) {
  if (!cfg.device) return {generated_device(w, h, pitch, cfg.depth, cfg.polarity), true};
  const DeviceProfile& d = *cfg.device;
  if (!d.bitmap) throw InvalidArgument("device '" + d.name + "' has no bitmap: a 2-D document needs a device with \"bitmap\"");
  if (std::abs(d.bitmap->pitch.value() - pitch) > 0.01 * pitch)
    throw InvalidArgument("the map's pitch " + detail::num(pitch) + " mm is not device '" + d.name + "''s pixel pitch " +
                          detail::num(d.bitmap->pitch.value()) + " mm");
  if (w > d.bitmap->width || h > d.bitmap->height)
    throw InvalidArgument("the map (" + std::to_string(w) + " × " + std::to_string(h) + " pixels) is larger than device '" +
                          d.name + "''s bitmap (" + std::to_string(d.bitmap->width) + " × " + std::to_string(d.bitmap->height) +
                          ")");
  const auto names = builtin_device_names();
  const bool builtin = std::find(names.begin(), names.end(), d.name) != names.end();
  return {d, !builtin};
}

Encode2DResult new_result(std::string method, const Encode2DConfig& config) {
  Encode2DResult r;
  r.method = std::move(method);
  r.model_version = config.encoder.model.version;
  r.target =
      config.encoder.target == EncoderConfig::Target::centroid ? EncoderConfig::Target::centroid : EncoderConfig::Target::felt;
  return r;
}

double strength(double v);

/// An input without texture: a flat surface at its mean level (F = 0), or
/// refused (EncoderConfig::NoTexture::refuse).
void flat_surface(Encode2DResult& r, const Encode2DConfig& config, double mean_level, const std::string& why,
                  const DeviceProfile& device, bool device_inline, int w, int h, double pitch, const std::string& description) {
  if (config.encoder.no_texture == EncoderConfig::NoTexture::refuse) throw InvalidArgument("the input has no texture: " + why);
  r.no_texture = true;
  r.irregularity_identifiable = false;
  r.field = Field2D::spectral;
  r.spec = base_spec(config.encoder, TexelSpec{}.central_pitch.value(), TexelSpec{}.irregularity.value(),
                     config.encoder.texel_length.value());
  r.spec.fine_strength = 0.0;
  r.spec.coarse_strength = strength(1.0 - mean_level);
  r.document = surface_document(device, device_inline, w, h, pitch, r.spec, r.field, 0.0, ConstantProfile{0.0}, description);
}

double strength(double v) {
  v = std::clamp(v, 0.0, 1.0);
  if (v > 0.98) return 1.0;  // within 2 % of full scale: full scale (as in 1-D)
  if (v < 0.02) return 0.0;
  return v;
}

}  // namespace

Encode2DResult encode_surface2d(const Raster2D& given, const Encode2DConfig& config) {
  check_config(config);
  const int w = given.width, h = given.height;
  const double p = given.pitch.value();
  if (!(std::isfinite(p) && p > 0.0)) throw InvalidArgument("the map's pitch is " + detail::num(p) + " mm; it must be > 0");
  if (w < 16 || h < 16 || given.values.size() != static_cast<std::size_t>(w) * static_cast<std::size_t>(h))
    throw InvalidArgument("the map is " + std::to_string(w) + " × " + std::to_string(h) +
                          " pixels; a 2-D encode needs at least 16 × 16 (and width·height values)");
  // The one input rule (signal.hpp to_amplitudes): a map outside [0, 1] is
  // scaled to full range, as every front door scales it.
  std::optional<Raster2D> scaled;
  if (std::any_of(given.values.begin(), given.values.end(), [](float v) { return !(v >= 0.0f && v <= 1.0f); })) {
    std::vector<double> v(given.values.begin(), given.values.end());
    (void)to_amplitudes(v, "the map");
    scaled = given;
    scaled->values.assign(v.begin(), v.end());
  }
  const Raster2D& map = scaled ? *scaled : given;
  double mean = 0.0;
  for (const float v : map.values) mean += v;
  mean /= static_cast<double>(map.values.size());
  double var = 0.0;
  for (float v : map.values) var += (v - mean) * (v - mean);
  const double rms = std::sqrt(var / static_cast<double>(map.values.size()));
  const auto [device, device_inline] = document_device(config, w, h, p);

  Encode2DResult r = new_result("bitmap", config);
  r.texture_rms = rms;
  const std::string description = "Encoded by texel encode from a " + std::to_string(w) + " × " + std::to_string(h) + " map";
  if (rms <= no_texture_floor) {
    flat_surface(r, config, mean, "variation RMS " + detail::num(rms) + " <= " + detail::num(no_texture_floor), device,
                 device_inline, w, h, p, description);
    return r;
  }

  // 1. Scans of the fine part, per direction.
  Analysis in = analyse(map, config, config.directions);
  r.per_direction = in.directions;
  fill_spread(r, false);
  r.anisotropic = r.central_pitch_spread_db > config.anisotropy_threshold_db;
  r.mean_central_pitch_db = in.mean_p;
  r.mean_irregularity_db = in.mean_i;

  // 2. Texel length from a lattice of cell borders; the design.
  double texel_length = config.encoder.texel_length.value();
  Field2D field = config.field.value_or(Field2D::spectral);
  std::vector<double> fine(map.values.size(), 0.0);
  for (std::size_t k = 0; k < fine.size(); ++k)
    if (in.env.rms[k] > 0.0) fine[k] = (map.values[k] - in.env.mean[k]) / in.env.rms[k];
  r.strongest_direction_deg = principal_direction(fine, w, h);
  if (config.detect_lattice) {
    if (const auto L = detect_lattice(map, fine)) {
      texel_length = *L;
      r.texel_length_detected = true;
      if (!config.field) field = Field2D::cells;
    }
  }
  const double orientation = field == Field2D::oriented ? std::fmod(r.strongest_direction_deg, 180.0) : 0.0;
  r.field = field;

  // 3. The design correction.
  const Corrected c =
      correct(in.mean_p, in.mean_i, in.mean_spread, config, field, orientation, texel_length, w, h, p,
              [&](const Raster2D& cand) { return analyse(cand, config, std::min(config.directions, kCandidateDirections)); });
  r.irregularity_identifiable = c.identifiable;
  r.irregularity_bound_db = c.identifiable ? 0.0 : irregularity_for_sigma(c.p, kCosineSigma, config.encoder.parameterization);
  r.correction_rounds = c.rounds;
  r.correction_residual_db = c.residual;
  r.spec = base_spec(config.encoder, c.p, c.i, texel_length);

  // 4. Strengths and the coarse profile: e(1 − F/2) = local mean, e·F/2 =
  // local RMS / the design's RMS (texel_mix).
  const double sigma_s = c.fine_rms > 0.0 ? c.fine_rms : 1.0 / 3.0;
  std::vector<double> fs;
  fs.reserve(map.values.size());
  for (std::size_t k = 0; k < map.values.size(); ++k) {
    const double g = in.env.rms[k] / sigma_s, e = in.env.mean[k] + g;
    if (e > 0.05) fs.push_back(2.0 * g / e);
  }
  const double F = strength(fs.empty() ? 1.0 : percentile(fs, 0.5));
  std::vector<double> e(map.values.size());
  double e_min = 1.0, e_max = 0.0, e_sum = 0.0;
  for (std::size_t k = 0; k < e.size(); ++k) {
    e[k] = std::clamp(in.env.mean[k] / (1.0 - 0.5 * F), 0.0, 1.0);
    e_min = std::min(e_min, e[k]);
    e_max = std::max(e_max, e[k]);
    e_sum += e[k];
  }
  r.coarse = in.range >= config.encoder.flat_envelope && in.range > c.range + 0.1;
  r.spec.fine_strength = F;
  Coarse2D coarse = ConstantProfile{0.0};
  if (!r.coarse) {
    r.spec.coarse_strength = strength(1.0 - e_sum / static_cast<double>(e.size()));
  } else {
    const double C = std::max(1.0 - e_min, 1e-6);
    r.spec.coarse_strength = C;
    const double cp =
        config.coarse_pitch.value() > 0.0 ? config.coarse_pitch.value() : std::max(p, 0.25 * config.encoder.boundary.value());
    Raster2D img;
    img.width = std::max(2, static_cast<int>(std::lround(w * p / cp)));
    img.height = std::max(2, static_cast<int>(std::lround(h * p / cp)));
    img.pitch = Millimetres(w * p / img.width);
    img.origin_x = Millimetres(0.5 * w * p / img.width);
    img.origin_y = Millimetres(0.5 * h * p / img.height);
    img.values.resize(static_cast<std::size_t>(img.width) * img.height);
    for (int j = 0; j < img.height; ++j)
      for (int i = 0; i < img.width; ++i) {
        // The image pixel's centre, in map pixels (pixel k sits at k·p).
        const double x = (i + 0.5) * w / img.width - 0.5, y = (j + 0.5) * h / img.height - 0.5;
        const double ev = bilinear(e, w, h, x, y);
        img.values[static_cast<std::size_t>(j) * img.width + i] = static_cast<float>(std::clamp((ev - (1.0 - C)) / C, 0.0, 1.0));
      }
    r.coarse_image = std::move(img);
    coarse = Image2D{config.coarse_image_path, Millimetres(0.0), Millimetres(0.0), Millimetres(w * p), Millimetres(h * p), false};
  }
  r.document = surface_document(device, device_inline, w, h, p, r.spec, field, orientation, coarse, description);
  return r;
}

Encode2DResult encode_scans(const ScanBundle& bundle, const Encode2DConfig& config) {
  check_config(config);
  if (bundle.scans.empty()) throw InvalidArgument("a scan bundle needs at least one scan");
  double spacing = 0.0, longest = 0.0;
  for (std::size_t k = 0; k < bundle.scans.size(); ++k) {
    const Scan1D& s = bundle.scans[k];
    const double sp = s.spacing.value();
    if (!(std::isfinite(sp) && sp > 0.0))
      throw InvalidArgument("scans[" + std::to_string(k) + "]: spacing is " + detail::num(sp) + " mm; it must be > 0");
    if (!std::isfinite(s.direction_deg))
      throw InvalidArgument("scans[" + std::to_string(k) + "]: direction_deg is not a finite number");
    spacing = k == 0 ? sp : std::min(spacing, sp);
    longest = std::max(longest, sp * static_cast<double>(s.amplitude.size()));
  }
  double pitch = spacing;
  if (config.device && config.device->bitmap) pitch = config.device->bitmap->pitch.value();
  const double width_mm = bundle.width.value() > 0.0 ? bundle.width.value() : longest;
  const double height_mm = bundle.height.value() > 0.0 ? bundle.height.value() : longest;
  const int w = std::max(16, static_cast<int>(std::lround(width_mm / pitch)));
  const int h = std::max(16, static_cast<int>(std::lround(height_mm / pitch)));
  const auto [device, device_inline] = document_device(config, w, h, pitch);

  Encode2DResult r = new_result("scans", config);
  // Per scan: the 1-D encoder. Directions folded to [0°, 180°).
  std::vector<double> fs, means;
  double total_rms = 0.0;
  for (const Scan1D& s : bundle.scans) {
    const EncodeResult e = encode(Signal{s.amplitude, s.spacing, s.description, false}, config.encoder);
    DirectionEncode d;
    d.direction_deg = std::fmod(std::fmod(s.direction_deg, 180.0) + 180.0, 180.0);
    d.central_pitch_db = e.spec.central_pitch.value();
    d.irregularity_db = e.spec.irregularity.value();
    d.percept = e.input;
    d.samples = s.amplitude.size();
    d.scans = 1;
    if (!e.no_texture) r.per_direction.push_back(d);
    fs.push_back(e.spec.fine_strength);
    double m = 0.0;
    for (double v : s.amplitude) m += v;
    means.push_back(m / static_cast<double>(s.amplitude.size()));
    total_rms = std::max(total_rms, e.texture_rms);
  }
  r.texture_rms = total_rms;
  const std::string description = "Encoded by texel encode from " + std::to_string(bundle.scans.size()) + " scans";
  const double F = strength(percentile(fs, 0.5));
  const double mean_amp = std::accumulate(means.begin(), means.end(), 0.0) / static_cast<double>(means.size());
  if (r.per_direction.empty()) {
    flat_surface(r, config, mean_amp, "every scan's variation RMS is at most " + detail::num(no_texture_floor), device,
                 device_inline, w, h, pitch, description);
    return r;
  }
  std::sort(r.per_direction.begin(), r.per_direction.end(),
            [](const DirectionEncode& a, const DirectionEncode& b) { return a.direction_deg < b.direction_deg; });
  fill_spread(r, true);
  r.anisotropic = r.per_direction.size() > 1 && r.central_pitch_spread_db > config.anisotropy_threshold_db;
  double mp = 0.0, mi = 0.0, ms = 0.0;
  for (const auto& d : r.per_direction) {
    mp += d.central_pitch_db;
    mi += d.irregularity_db;
    ms += d.percept.spread_db;
  }
  const auto n = static_cast<double>(r.per_direction.size());
  r.mean_central_pitch_db = mp / n;
  r.mean_irregularity_db = mi / n;
  const Field2D field = config.field.value_or(Field2D::spectral);
  r.field = field;
  const double orientation = field == Field2D::oriented ? r.strongest_direction_deg : 0.0;
  // The candidates are scanned as the input was: raw 1-D scans along the
  // bundle's directions, each as long as the input's, encoded by the 1-D encoder.
  const Corrected c = correct(mp / n, mi / n, ms / n, config, field, orientation, config.encoder.texel_length.value(), w, h,
                              pitch, [&](const Raster2D& cand) {
                                Analysis a;
                                const std::vector<double> v(cand.values.begin(), cand.values.end());
                                for (const auto& d : r.per_direction) {
                                  int lines = 0;
                                  std::vector<double> y = scan_lines(v, cand.width, cand.height, d.direction_deg,
                                                                     std::max<std::size_t>(d.samples, 1024), lines);
                                  const double m = std::accumulate(y.begin(), y.end(), 0.0) / static_cast<double>(y.size());
                                  for (double& x : y) x -= m;
                                  a.directions.push_back(encode_direction(as_signal(y, cand.pitch.value(), "candidate"),
                                                                          d.direction_deg, lines, config.encoder));
                                }
                                for (const auto& d : a.directions) {
                                  a.mean_p += d.central_pitch_db / n;
                                  a.mean_i += d.irregularity_db / n;
                                  a.mean_spread += d.percept.spread_db / n;
                                }
                                return a;
                              });
  r.irregularity_identifiable = c.identifiable;
  r.irregularity_bound_db = c.identifiable ? 0.0 : irregularity_for_sigma(c.p, kCosineSigma, config.encoder.parameterization);
  r.correction_rounds = c.rounds;
  r.correction_residual_db = c.residual;
  r.spec = base_spec(config.encoder, c.p, c.i, config.encoder.texel_length.value());
  r.spec.fine_strength = F;
  // The mean level: e(1 − F/2) = the scans' mean amplitude, a constant profile.
  r.spec.coarse_strength = strength(1.0 - std::clamp(mean_amp / (1.0 - 0.5 * F), 0.0, 1.0));
  r.document =
      surface_document(device, device_inline, w, h, pitch, r.spec, field, orientation, ConstantProfile{0.0}, description);
  return r;
}

}  // namespace texel::codec
