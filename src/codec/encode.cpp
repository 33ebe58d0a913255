// The encoder's pipeline (docs/encoder.md): checks, recovery or split and
// fit, the coarse section, the bitstream and the decoded texture's percept.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "encoder_parts.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel::codec {

using texel::detail::num;

using namespace parts;
namespace {

/// How much more the envelope must vary than a fine-only texture's own (relative range).
constexpr double coarse_margin = 0.1;
/// Largest band-spectrum difference a fine-only explanation may leave (dB).
constexpr double max_shape_db = 3.0;

}  // namespace

EncodeResult encode(const Signal& signal, const EncoderConfig& cfg) {
  const auto t0 = std::chrono::steady_clock::now();
  const double dx = signal.spacing.value();
  const std::size_t n = signal.amplitude.size();
  if (!(std::isfinite(dx) && dx > 0.0)) throw InvalidArgument("signal spacing is " + num(dx) + " mm; it must be > 0");
  if (!(cfg.boundary.value() > 0.0 && std::isfinite(cfg.boundary.value())))
    throw FieldError("boundary", "is " + num(cfg.boundary.value()) + " mm; it must be > 0");
  if (!(cfg.texel_length.value() >= 0.001 && cfg.texel_length.value() <= 65.535))
    throw FieldError("texel_length", "is " + num(cfg.texel_length.value()) + " mm; allowed: 0.001 … 65.535 mm");
  if (!(cfg.model.swipe_speed.value() > 0.0 && std::isfinite(cfg.model.swipe_speed.value())))
    throw FieldError("swipe_speed", "is " + num(cfg.model.swipe_speed.value()) + " mm/s; it must be > 0");
  if (!(cfg.model.weight_exponent > 0.0 && cfg.model.weight_exponent <= 4.0))
    throw FieldError("weight_exponent", "is " + num(cfg.model.weight_exponent) + "; allowed: > 0 … 4");
  if (!(cfg.model.sensitivity_scale >= 0.0 && cfg.model.sensitivity_scale <= 1.0))
    throw FieldError("sensitivity_scale", "is " + num(cfg.model.sensitivity_scale) + "; allowed: 0 … 1");
  if (!(cfg.model.drawn_weight >= 0.0 && cfg.model.drawn_weight <= 100.0))
    throw FieldError("drawn_weight", "is " + num(cfg.model.drawn_weight) + "; allowed: 0 … 100");
  if (cfg.coarse_bits < 1 || cfg.coarse_bits > 16)
    throw FieldError("coarse_bits", "is " + std::to_string(cfg.coarse_bits) + "; allowed: 1 … 16");
  const double len = static_cast<double>(n) * dx;
  if (n < 64 || len < 4.0 * cfg.texel_length.value())
    throw InvalidArgument("the input has " + std::to_string(n) + " samples over " + num(len) +
                          " mm; at least 64 samples and 4 texels are needed");
  for (double v : signal.amplitude)
    if (!std::isfinite(v)) throw InvalidArgument("the input holds a non-finite value");
  std::vector<double> a = signal.amplitude;
  for (double& v : a) v = std::clamp(v, 0.0, 1.0);
  if (!(cfg.model.felt_band_top.value() > 0.0 && std::isfinite(cfg.model.felt_band_top.value())))
    throw FieldError("felt_band_top", "is " + num(cfg.model.felt_band_top.value()) + " Hz; it must be > 0");

  EncodeResult res;
  res.samples = n;
  res.spacing = Millimetres(dx);
  res.model = cfg.model;
  res.model_version = cfg.model.version;
  res.fit_method = cfg.fit_method;
  (void)model_defaults(cfg.model.version);  // FieldError "model" for an unknown version
  // No texture (docs/encoder.md, "Honest results"): a constant or all-zero
  // input, or one whose variation is below one 16-bit step.
  {
    double mean = 0.0, sq = 0.0;
    for (double v : a) mean += v;
    mean /= static_cast<double>(n);
    for (double v : a) sq += (v - mean) * (v - mean);
    res.texture_rms = std::sqrt(sq / static_cast<double>(n));
    res.no_texture = res.texture_rms <= no_texture_floor;
    if (res.no_texture) res.irregularity_identifiable = false;  // nothing was estimated
    if (res.no_texture && cfg.no_texture == EncoderConfig::NoTexture::refuse)
      throw InvalidArgument("the input has no texture: its variation (RMS " + num(res.texture_rms) + ") is at most " +
                            num(no_texture_floor) + " of full scale (constant or all zero)");
  }
  // How much of the input lies above the felt band (docs/encoder.md §2,
  // "Version 3"): reported whatever the model. A recording dominated by it
  // is flagged, since versions 1 and 2 weigh it and version 3 estimates from
  // the rest; a map is not: its fine content above the band at the nominal
  // speed is texture, felt at slower strokes (the studies' textures reach
  // 19.7 dB, 93 cycles/mm).
  if (!res.no_texture) {
    const CyclesPerMm top = felt_band_top_cpm(cfg.model);
    res.beyond_felt_band = power_share_above(a, dx, top.value());
    if (signal.recording && res.beyond_felt_band > 0.5) {
      std::string w = num(std::round(res.beyond_felt_band * 1000.0) / 10.0) +
                      " % of the input's power lies above the felt band (" + num(cfg.model.felt_band_top.value()) + " Hz at " +
                      num(cfg.model.swipe_speed.value()) + " mm/s, " + num(std::round(top.value() * 100.0) / 100.0) +
                      " cycles/mm): airborne sound, a sensor resonance, or texture too fine to feel at this speed; ";
      w += cfg.model.version == 3 ? "model 3 gives it no weight and estimates from the felt band"
                                  : "model " + std::to_string(cfg.model.version) + " weighs it (model 3 does not)";
      if (cfg.model.version == 3 && res.beyond_felt_band > 1.0 - 1e-6)
        w += "; next to nothing is in the felt band, so the whole spectrum decided";
      res.warnings.push_back(std::move(w));
    }
  }
  // The band the decoded texture draws from: the analysed grid's Nyquist
  // frequency, rounded down to the stream's 0.01 dB steps (device independent).
  Bitstream b;
  FineFields& f = b.fine;
  f.band_max_cdb = static_cast<std::int16_t>(std::floor(db_of(0.5 / dx) * 100.0));
  const CyclesPerMm band_max = to_cpm(Decibels(f.band_max_cdb / 100.0));
  f.seed = cfg.seed;
  f.parameterization = cfg.parameterization;
  const std::size_t cand = std::min<std::size_t>(n, std::size_t{1} << 16);

  // An input that is itself a fine-only Texel rendering: recover its texel
  // length and (P, I) from the texels' frequencies; kept if the model says
  // the result feels the same as the input (else the fit below decides).
  // A coarse profile without fine texture (F = 0) as the renderer draws it
  // is constant over each texel: its texel length is detected (§1 step 0).
  std::vector<double> lengths{cfg.texel_length.value()};
  lengths.insert(lengths.end(), candidate_texel_lengths_mm.begin(), candidate_texel_lengths_mm.end());
  const std::optional<double> stepped = res.no_texture ? std::nullopt : stepped_texel_length(a, dx, lengths);
  const std::optional<TexelRecovery> rec =
      cfg.recover_texel && !stepped && !res.no_texture ? recover_texel(a, dx, cfg, band_max) : std::nullopt;
  const double L_used = rec ? rec->L : stepped ? *stepped : cfg.texel_length.value();
  f.texel_length_um = static_cast<std::uint16_t>(std::lround(L_used * 1000.0));
  EncoderConfig fit_cfg = cfg;
  fit_cfg.texel_length = Millimetres(f.texel_length_um / 1000.0);
  if (fit_cfg.target == EncoderConfig::Target::automatic)
    fit_cfg.target = signal.recording ? EncoderConfig::Target::centroid : EncoderConfig::Target::felt;
  res.target = fit_cfg.target;
  fit_cfg.model.centroid = fit_cfg.target == EncoderConfig::Target::centroid;

  // Version 3 analyses what can be felt (docs/encoder.md §2, "Version 3"):
  // the split, the strengths and the fit see the input without its content
  // above the felt band, which would otherwise shape the envelope and the
  // fine strength (a recording's airborne sound). A recording is scaled
  // again as the loader scales one (a = 0.5 + 0.5·y/max|y|), so its felt
  // part fills the range as it would recorded without that content. Texel
  // renderings (recovered above from the samples themselves) and inputs
  // with next to nothing in the felt band are analysed as they are.
  const bool felt_only = cfg.model.version == 3 && !res.no_texture && !rec && !stepped && res.beyond_felt_band > 1e-4 &&
                         res.beyond_felt_band < 1.0 - 1e-6;
  // A recording was captured at one speed, its nominal one: what lies above
  // the felt band there (airborne sound, a sensor's resonance) is cut at the
  // band's top. A map is a surface people explore at a range of speeds
  // (PerceptualModel::speed_spread): cut only where no speed feels it.
  const double cut_cpm = signal.recording ? felt_band_top_cpm(cfg.model).value() : felt_band_reach_cpm(cfg.model).value();
  if (felt_only) {
    lowpass_felt(a, dx, cut_cpm);
    if (signal.recording) {
      double mean = 0.0, peak = 0.0;
      for (double v : a) mean += v;
      mean /= static_cast<double>(n);
      for (double v : a) peak = std::max(peak, std::fabs(v - mean));
      if (peak > 0.0)
        for (double& v : a) v = 0.5 + 0.5 * (v - mean) / peak;
    }
    for (double& v : a) v = std::clamp(v, 0.0, 1.0);
  }

  Split sp = split(a, dx, fit_cfg,
                   rec                         ? SplitMode::fine_only
                   : stepped || res.no_texture ? SplitMode::coarse_only
                                               : SplitMode::automatic);
  FineFit fit;
  bool has_fine = sp.F >= 0.02 && !res.no_texture;
  bool recovered = false;
  if (rec && has_fine) {
    FineFit r;
    r.input = perceive(sp.fine, dx, fit_cfg.model);
    Fitter fitter(fit_cfg, r.input, dx, cand, band_max);
    const Box box = fit_box(fit_cfg, band_max);
    r.p_db = std::clamp(rec->p_db, box.p_lo, box.p_hi);
    r.i_db = std::clamp(rec->i_db, box.i_lo, box.i_hi);
    r.distance = fitter(r.p_db, r.i_db);
    // The residual test has decided that the input is this rendering; the
    // model still reports the distance and whether Irregularity is felt.
    identifiability(fitter, box, r);
    r.evaluations = fitter.evaluations;
    fit = r;
    recovered = true;
    res.texel_recovered = true;
  }
  if (recovered) {
  } else if (sp.coarse && has_fine) {
    // Analysis-by-synthesis for the split too: a fine-only texture with low
    // or widely spread frequencies has an uneven envelope by itself. Keep the
    // coarse profile only if the input's envelope varies clearly more than
    // that of the best fine-only explanation.
    Split flat = split(a, dx, fit_cfg, SplitMode::fine_only);
    // The check needs the neighbourhood, not the last 0.1 dB: a shorter
    // search. The simplex's (a third of its budget) is the result if this
    // explanation is kept; least squares runs two iterations, P and I only,
    // and is finished below if it is kept.
    EncoderConfig quick = fit_cfg;
    quick.max_evaluations = fit_cfg.max_evaluations / 3;
    const bool simplex = fit_cfg.fit_method == FitMethod::simplex;
    FineFit flat_fit =
        fit_fine(flat.fine, dx, cand, band_max, quick, 0.0, nullptr, simplex ? FitOptions{} : FitOptions{false, 2, std::nullopt});
    std::vector<double> r(n);
    fine_texture(flat_fit.p_db, flat_fit.i_db, fit_cfg, band_max, Millimetres(len))
        .render(Grid{Millimetres(0.0), Millimetres(dx), static_cast<std::int64_t>(n)}, 0, r);
    if (felt_only) lowpass_felt(r, dx, cut_cpm);  // compared as the input is
    const Split own = split(r, dx, fit_cfg);
    const double shape = shape_distance_db(a, r, dx);
    if (sp.range <= own.range + coarse_margin && shape <= max_shape_db) {
      sp = std::move(flat);
      if (simplex) {
        fit = flat_fit;
      } else {
        fit = fit_fine(sp.fine, dx, cand, band_max, fit_cfg, 0.0, nullptr,
                       FitOptions{true, 8, std::array<double, 2>{flat_fit.p_db, flat_fit.i_db}});
        fit.evaluations += flat_fit.evaluations;
      }
    } else {
      fit = fit_fine(sp.fine, dx, cand, band_max, fit_cfg, 1.0 / cfg.boundary.value(), &sp);
      fit.evaluations += flat_fit.evaluations;
    }
  } else if (has_fine) {
    fit = fit_fine(sp.fine, dx, cand, band_max, fit_cfg);
  }
  res.coarse = sp.coarse;
  has_fine = sp.F >= 0.02 && !res.no_texture;
  double p_est = 10.0, i_est = cfg.parameterization == Parameterization::log ? 1.0 : -5.0;
  if (has_fine) {
    p_est = fit.p_db;
    i_est = fit.i_db;
    res.input = fit.input;
    res.irregularity_identifiable = fit.identifiable;
    res.irregularity_bound_db = fit.bound_db;
    res.evaluations = fit.evaluations;
    // A value at an edge of the search box is the box's limit, not an
    // estimate (within half a stream step, 0.005 dB).
    const Box box = fit_box(fit_cfg, band_max);
    res.at_bound.central_pitch = p_est <= box.p_lo + 0.005 || p_est >= box.p_hi - 0.005;
    res.at_bound.irregularity = i_est <= box.i_lo + 0.005 || i_est >= box.i_hi - 0.005;
    if (res.at_bound.any()) res.irregularity_identifiable = false;
  }
  f.central_pitch_cdb = static_cast<std::int16_t>(std::lround(p_est * 100.0));
  f.irregularity_cdb = static_cast<std::int16_t>(std::lround(i_est * 100.0));

  // Coarse part and strengths.
  const double F = has_fine ? sp.F : 0.0;
  std::vector<double> decoded_c;
  if (sp.coarse) {
    std::vector<CoarseFields> options;
    if (cfg.max_bytes) {
      for (unsigned bits = 8; bits >= 2; --bits)
        for (std::uint32_t stride : {1u, 2u, 3u, 4u, 6u, 8u, 12u, 16u, 24u, 32u, 48u, 64u})
          for (std::uint8_t pred : {std::uint8_t{1}, std::uint8_t{2}})
            options.push_back(coarse_fields(sp.c, sp.C, F, bits, stride, pred));
    } else {
      for (std::uint8_t pred : {std::uint8_t{1}, std::uint8_t{2}})
        options.push_back(coarse_fields(sp.c, sp.C, F, cfg.coarse_bits, 1, pred));
    }
    const std::size_t fixed = write_bitstream(b).size();
    const CoarseFields* chosen = nullptr;
    double chosen_err = 0;
    std::size_t chosen_size = 0;
    for (const auto& o : options) {
      const std::size_t size = fixed + coarse_section_bytes(o);
      if (cfg.max_bytes && size > *cfg.max_bytes) continue;
      const double err = coarse_error(sp.c, o);
      if (!chosen || err < chosen_err - 1e-12 || (std::fabs(err - chosen_err) <= 1e-12 && size < chosen_size))
        chosen = &o, chosen_err = err, chosen_size = size;
    }
    if (!chosen)
      throw FieldError("max_bytes", std::to_string(*cfg.max_bytes) +
                                        " is too small for this texture's coarse profile; it needs at least " +
                                        std::to_string(fixed + coarse_section_bytes(options.back())) + " bytes");
    b.coarse = *chosen;
    decoded_c = decoded_profile(*chosen, sp.c.size());
    res.coarse_correlation = correlation(sp.c, decoded_c);
  } else {
    const auto c8 = static_cast<std::uint8_t>(std::lround(sp.C * 255.0));
    const auto f8 = static_cast<std::uint8_t>(std::lround(F * 255.0));
    if (c8 != 0 || f8 != 255) {
      CoarseFields c;
      c.coarse_strength = c8;
      c.fine_strength = f8;
      c.bits = 0;
      b.coarse = c;
    }
  }
  res.bytes = write_bitstream(b);
  res.bitstream = parse_bitstream(res.bytes);  // what a decoder sees
  res.spec = to_spec(res.bitstream);
  // The centroid target's last step (docs/encoder.md §3, "Targets"): the
  // fit matched the fine part's log-spectral moments; the decoded texture as
  // a whole (coarse profile, fine strength, the stream's own seed) is then
  // moved in Central Pitch until its log-spectral centroid is the input's,
  // by secant steps on the stream's 0.01 dB grid. Not where the part below
  // the fine/coarse boundary carries half the power or more: the centroid
  // then follows the coarse profile's power, which Central Pitch would be
  // bent to make up for.
  double below = 0.0;
  const double v = fit_cfg.model.swipe_speed.value();
  // Version 3: the felt band (the whole band when next to nothing is in it, as the model does).
  const double centroid_top =
      res.beyond_felt_band > 1.0 - 1e-6 ? std::numeric_limits<double>::infinity() : centroid_top_cpm(fit_cfg.model);
  const double goal = fit_cfg.target == EncoderConfig::Target::centroid && has_fine && !recovered
                          ? log_centroid_db(a, dx, v, 1.0 / cfg.boundary.value(), &below, centroid_top)
                          : 0.0;
  if (fit_cfg.target == EncoderConfig::Target::centroid && has_fine && !recovered && below < 0.5) {
    std::vector<double> d(n);
    auto centroid_at = [&](std::int16_t cdb) {
      f.central_pitch_cdb = cdb;
      res.bytes = write_bitstream(b);
      res.bitstream = parse_bitstream(res.bytes);
      res.spec = to_spec(res.bitstream);
      TexelTexture(res.spec, Millimetres(len), Sampling{Grid{Millimetres(0.0), Millimetres(dx), 0}, band_max})
          .render(Grid{Millimetres(0.0), Millimetres(dx), static_cast<std::int64_t>(n)}, 0, d);
      return log_centroid_db(d, dx, v, 0.0, nullptr, centroid_top);
    };
    const Box box = fit_box(fit_cfg, band_max);
    const auto lo = static_cast<std::int16_t>(std::ceil(box.p_lo * 100.0)),
               hi = static_cast<std::int16_t>(std::floor(box.p_hi * 100.0));
    std::int16_t p0 = f.central_pitch_cdb;
    double c0 = centroid_at(p0);
    double slope = 1.0;  // the centroid rises with Central Pitch about dB for dB
    for (int step = 0; step < 6 && std::fabs(c0 - goal) > 0.02; ++step) {
      const auto p1 = static_cast<std::int16_t>(std::clamp<long>(std::lround(p0 + 100.0 * (goal - c0) / slope), lo, hi));
      if (p1 == p0) break;
      const double c1 = centroid_at(p1);
      const double s = (c1 - c0) / ((p1 - p0) / 100.0);
      if (std::fabs(c1 - goal) < std::fabs(c0 - goal)) p0 = p1, c0 = c1;
      if (!(s > 0.1)) break;  // flat at the band's edge: keep the better point
      slope = s;
    }
    centroid_at(p0);
    res.at_bound.central_pitch = p0 <= lo || p0 >= hi;
    if (res.at_bound.any()) res.irregularity_identifiable = false;
  }

  // The decoded texture on the input's grid, under the model.
  if (has_fine) {
    const TexelTexture t(res.spec, Millimetres(len), Sampling{Grid{Millimetres(0.0), Millimetres(dx), 0}, band_max});
    std::vector<double> d(n);
    t.render(Grid{Millimetres(0.0), Millimetres(dx), static_cast<std::int64_t>(n)}, 0, d);
    EncoderConfig c2 = fit_cfg;
    const Split dsp = res.coarse ? split(d, dx, c2, SplitMode::two_scale, sp.window) : split(d, dx, c2, SplitMode::fine_only);
    res.decoded = perceive(dsp.fine, dx, fit_cfg.model, res.coarse ? 1.0 / cfg.boundary.value() : 0.0);
    res.model_distance = distance(res.input, res.decoded, cfg.model);
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

Document decode_document(const Bitstream& b, const DeviceProfile& device) { return make_document(device, to_spec(b)); }

}  // namespace texel::codec
