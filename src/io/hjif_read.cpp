// MPEG-I Haptics JSON (.hjif) in: parse_hjif reads a file the published
// schemas accept (docs/interchange.md "Import"; the walk is in
// hjif_conformance.cpp), evaluate() samples what it read on a grid.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <limits>

#include <nlohmann/json.hpp>

#include "hjif_internal.hpp"
#include "texel/detail/format.hpp"
#include "texel/detail/json_fields.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"
#include "texel/surface.hpp"

namespace texel::hjif {
namespace {

using detail::pow10i;
using detail::quote_value;
using nlohmann::json;
using texel::detail::num;

/// Ticks per millimetre of a perception (spatial) or per mm at the swipe speed (temporal).
double ticks_per_mm(const Experience& e, const Perception& p, std::optional<MmPerSecond> v) {
  if (p.spatial) return static_cast<double>(e.timescale) / pow10i(p.unit_exponent + 3);
  if (!v)
    throw FieldError("swipe_speed",
                     "is required: the file's perceptions are temporal (Vibrotactile or Other), and the swipe "
                     "speed (mm/s) turns their time into position");
  return static_cast<double>(e.timescale) / v->value();
}

}  // namespace

double detail::curve_at(const CurveEffect& c, double u) {
  const auto& k = c.keyframes;
  constexpr double slack = 1e-6;
  if (k.empty() || u < static_cast<double>(k.front().position) - slack || u > static_cast<double>(k.back().position) + slack)
    return 0.0;
  // First keyframe with position > u.
  auto hi =
      std::upper_bound(k.begin(), k.end(), u, [](double x, const Keyframe& f) { return x < static_cast<double>(f.position); });
  if (hi == k.begin()) return k.front().amplitude;
  if (hi == k.end()) return k.back().amplitude;
  const Keyframe& a = *(hi - 1);
  const Keyframe& b = *hi;
  const double t = (u - static_cast<double>(a.position)) / static_cast<double>(b.position - a.position);
  return a.amplitude + (b.amplitude - a.amplitude) * t;
}

namespace {

/// A VectorialWave or Transient effect prepared for evaluation: amplitude and
/// frequency breakpoints, and the phase accumulated at each frequency breakpoint.
struct PreparedWave {
  const WaveEffect* w = nullptr;
  std::vector<std::pair<double, double>> amp;   // (relative ticks, amplitude)
  std::vector<std::pair<double, double>> freq;  // (relative ticks, Hz)
  std::vector<double> phase_at;                 // phase (rad) at each freq breakpoint
  double ticks_per_second = 1000.0;
  double end = 0.0;  // last relative tick it covers
};

constexpr double kTwoPi = 6.283185307179586;
/// Transient bursts last 22 ms: two sine periods (the reference software's reading).
constexpr double kTransientSeconds = 0.022;

/// Linear through breakpoints, held before the first and after the last.
double held_linear(const std::vector<std::pair<double, double>>& p, double r, double fallback) {
  if (p.empty()) return fallback;
  if (r <= p.front().first) return p.front().second;
  if (r >= p.back().first) return p.back().second;
  const auto hi = std::upper_bound(p.begin(), p.end(), r, [](double x, const auto& q) { return x < q.first; });
  const auto& a = *(hi - 1);
  const auto& b = *hi;
  return b.first == a.first ? b.second : a.second + (b.second - a.second) * (r - a.first) / (b.first - a.first);
}

PreparedWave prepare(const WaveEffect& w, std::uint32_t timescale) {
  PreparedWave p;
  p.w = &w;
  p.ticks_per_second = timescale;
  for (const auto& k : w.keyframes) {
    if (k.amplitude) p.amp.emplace_back(static_cast<double>(k.position), *k.amplitude);
    if (k.frequency) p.freq.emplace_back(static_cast<double>(k.position), *k.frequency);
  }
  double phase = w.phase;
  double prev_r = 0.0;
  double prev_f = p.freq.empty() ? 0.0 : p.freq.front().second;
  for (const auto& [r, f] : p.freq) {
    phase += kTwoPi * 0.5 * (prev_f + f) * (r - prev_r) / p.ticks_per_second;  // trapezoid: exact for a linear chirp
    p.phase_at.push_back(phase);
    prev_r = r, prev_f = f;
  }
  p.end = w.keyframes.empty() ? 0.0 : static_cast<double>(w.keyframes.back().position);
  if (w.kind == WaveEffect::Kind::transient) p.end += kTransientSeconds * p.ticks_per_second;
  return p;
}

double base_signal(std::string_view shape, double theta) {
  const double cycle = theta / kTwoPi - std::floor(theta / kTwoPi);  // 0 … 1
  if (shape == "Square") return cycle < 0.5 ? 1.0 : -1.0;
  if (shape == "Triangle") return cycle < 0.25 ? 4 * cycle : cycle < 0.75 ? 2 - 4 * cycle : 4 * cycle - 4;
  if (shape == "SawToothUp") return 2 * cycle - 1;
  if (shape == "SawToothDown") return 1 - 2 * cycle;
  return std::sin(theta);
}

/// A prepared wave at relative tick r (0 outside it).
double wave_at(const PreparedWave& p, double r) {
  if (r < 0.0 || r > p.end) return 0.0;
  const WaveEffect& w = *p.w;
  if (w.kind == WaveEffect::Kind::transient) {
    const double d = kTransientSeconds * p.ticks_per_second;
    double sum = 0.0;
    for (const auto& k : w.keyframes)
      if (k.amplitude && r >= static_cast<double>(k.position) && r <= static_cast<double>(k.position) + d)
        sum += *k.amplitude * std::sin(2.0 * kTwoPi * (r - static_cast<double>(k.position)) / d);
    return w.gain * sum;
  }
  const double a = held_linear(p.amp, r, 1.0);
  double theta = w.phase;
  if (!p.freq.empty()) {
    const auto hi = std::upper_bound(p.freq.begin(), p.freq.end(), r, [](double x, const auto& q) { return x < q.first; });
    const auto i = static_cast<std::size_t>(hi - p.freq.begin());
    const double r0 = i == 0 ? 0.0 : p.freq[i - 1].first;
    const double f0 = i == 0 ? p.freq.front().second : p.freq[i - 1].second;
    const double f1 = held_linear(p.freq, r, 0.0);
    theta = (i == 0 ? w.phase : p.phase_at[i - 1]) + kTwoPi * 0.5 * (f0 + f1) * (r - r0) / p.ticks_per_second;
  }
  return w.gain * a * base_signal(w.base_signal, theta);
}

/// Bounds what parsing a carried document may cost before parse_document
/// prepares it (the caps Texel Studio applies, service.cpp check_cost): a
/// device by name must be built in (a name may be a path, e.g. /dev/zero),
/// and samples and texels over the longest length the JSON implies stay
/// under `cap`.
void check_carried_cost(const json& doc, std::size_t cap) {
  double longest = 0.0;
  for (const auto& name : builtin_device_names()) longest = std::max(longest, load_device(name).length().value());
  double min_texel = std::numeric_limits<double>::infinity();
  double min_spacing = std::numeric_limits<double>::infinity();
  double samples = 0.0;
  auto walk = [&](const json& v, const std::string& key, auto&& self) -> void {
    if (v.is_object()) {
      for (auto it = v.begin(); it != v.end(); ++it) self(it.value(), it.key(), self);
    } else if (v.is_array()) {
      for (const auto& x : v) self(x, key, self);
    } else if (v.is_number()) {
      const double d = std::fabs(v.get<double>());
      if (key == "texel_length_mm" && d > 0) min_texel = std::min(min_texel, d);
      if (key == "spacing_mm" && d > 0) min_spacing = std::min(min_spacing, d);
      if (key == "samples") samples = std::max(samples, d);
      if (key == "length_mm" || key == "start_mm") longest = std::max(longest, d);
    }
  };
  walk(doc, "", walk);
  if (doc.is_object() && doc.contains("device") && doc["device"].is_string()) {
    const auto names = builtin_device_names();
    if (std::find(names.begin(), names.end(), doc["device"].get<std::string>()) == names.end())
      throw FormatError("it names the device " + quote_value(doc["device"].get<std::string>()) + ", which is not built in");
  }
  if (std::isfinite(min_spacing)) longest = std::max(longest, samples * min_spacing);
  const double c = static_cast<double>(cap);
  if (samples > c || (std::isfinite(min_spacing) && longest / min_spacing > c) ||
      (std::isfinite(min_texel) && longest / min_texel > c))
    throw FormatError("it asks for more than " + std::to_string(cap) + " samples or texels");
}

}  // namespace

Experience parse_hjif(std::string_view text, std::string_view origin, const ImportLimits& limits) {
  detail::Walked w = detail::walk_text(text, origin, limits, detail::Mode::read);
  if (!w.errors.empty()) throw FormatError("'" + std::string(origin) + "': " + w.errors.front());
  Experience e = std::move(w.experience);
  if (e.perceptions.empty()) {
    std::string found;
    for (const auto& m : e.skipped) found += (found.empty() ? "" : ", ") + m;
    throw FormatError("'" + std::string(origin) +
                      "' has no perception Texel can sample (Friction, Vibrotactile Texture, or "
                      "Vibrotactile or Other at a swipe speed)" +
                      (found.empty() ? std::string() : "; it has: " + found));
  }
  // The carried document, used only when its rendering agrees with the curves.
  const auto at = e.description.find(carried_marker);
  if (at != std::string::npos) {
    try {
      double tolerance = default_tolerance;
      const auto t = e.description.rfind("texel-tolerance:", at);
      if (t != std::string::npos) tolerance = std::strtod(e.description.c_str() + t + 16, nullptr);
      if (!(tolerance > 0.0 && tolerance <= 0.5)) throw FormatError("its texel-tolerance is not in (0, 0.5]");
      const std::string_view carried = std::string_view(e.description).substr(at + carried_marker.size());
      if (detail::nesting_depth(carried, limits.max_depth) > limits.max_depth) throw FormatError("it nests JSON too deeply");
      check_carried_cost(texel::detail::parse_json(carried, "the carried document"), limits.max_keyframes);
      Document doc = parse_document(carried, "the carried document");
      if (doc.device.samples > static_cast<std::int64_t>(limits.max_keyframes))
        throw FormatError("its device has " + std::to_string(doc.device.samples) + " samples, more than are read");
      const Surface s = prepare_surface(doc);
      const std::vector<double> map = s.render();
      std::vector<double> x(map.size());
      for (std::size_t i = 0; i < x.size(); ++i) x[i] = s.grid().position(static_cast<std::int64_t>(i)).value();
      const std::vector<double> curve = evaluate(e, x);
      double worst = 0.0;
      for (std::size_t i = 0; i < map.size(); ++i) worst = std::max(worst, std::fabs(curve[i] - map[i]));
      // 1e-6: a writer that keeps amplitudes in single precision (the reference software) moves them by ≤ 6e-8.
      if (!(worst <= tolerance + 1e-6))
        throw FormatError("it renders up to " + num(worst) + " away from the file's curves (tolerance " + num(tolerance) + ")");
      e.carried = std::move(doc);
    } catch (const Error& err) {
      e.carried_rejected = std::string("the carried Texel document is not used: ") + err.what();
    }
  }
  return e;
}

Experience load_hjif(const std::string& path, const ImportLimits& limits) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > limits.max_bytes)
    throw FormatError("'" + path + "' has " + std::to_string(size) + " bytes; at most " + std::to_string(limits.max_bytes) +
                      " are read");
  return parse_hjif(read_file(path), path, limits);
}

std::vector<double> evaluate(const Experience& e, std::span<const double> x, std::optional<MmPerSecond> v) {
  std::vector<double> out(x.size(), 0.0);
  // On ascending positions (every grid) each effect visits only the
  // positions it covers; the total is bounded so that a file of many
  // overlapping effects is refused rather than sampled for hours.
  const bool ascending = std::is_sorted(x.begin(), x.end());
  constexpr double max_work = 4294967296.0;  // 2^32 effect-samples
  double work = 0.0;
  for (const Perception& p : e.perceptions) {
    const double k = ticks_per_mm(e, p, v);
    for (const CurveEffect& c : p.effects) {
      std::size_t first = 0;
      std::size_t last = x.size();
      if (ascending && !c.keyframes.empty()) {
        const double lo = (static_cast<double>(c.keyframes.front().position) - 1.0) / k;
        const double hi = (static_cast<double>(c.keyframes.back().position) + 1.0) / k;
        first = static_cast<std::size_t>(std::lower_bound(x.begin(), x.end(), lo) - x.begin());
        last = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), hi) - x.begin());
      }
      work += static_cast<double>(last - first);
      if (work > max_work)
        throw FormatError(
            "the file's effects cover more than 2^32 samples in all on this grid (overlapping effects); "
            "it is not sampled");
      for (std::size_t i = first; i < last; ++i) out[i] += detail::curve_at(c, x[i] * k);
    }
    for (const WaveEffect& w : p.waves) {
      const PreparedWave pw = prepare(w, e.timescale);
      const double start = static_cast<double>(w.position);
      std::size_t first = 0;
      std::size_t last = x.size();
      if (ascending) {
        first = static_cast<std::size_t>(std::lower_bound(x.begin(), x.end(), (start - 1.0) / k) - x.begin());
        last = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), (start + pw.end + 1.0) / k) - x.begin());
      }
      work += static_cast<double>(last - first) * static_cast<double>(std::max<std::size_t>(1, w.keyframes.size()));
      if (work > max_work)
        throw FormatError("the file's effects cover more than 2^32 samples in all on this grid; it is not sampled");
      for (std::size_t i = first; i < last; ++i) out[i] += wave_at(pw, x[i] * k - start);
    }
  }
  return out;
}

double extent_mm(const Experience& e, std::optional<MmPerSecond> v) {
  double most = 0.0;
  for (const Perception& p : e.perceptions) {
    const double k = ticks_per_mm(e, p, v);
    for (const CurveEffect& c : p.effects)
      if (!c.keyframes.empty()) most = std::max(most, static_cast<double>(c.keyframes.back().position) / k);
    for (const WaveEffect& w : p.waves)
      if (!w.keyframes.empty()) most = std::max(most, (static_cast<double>(w.position) + prepare(w, e.timescale).end) / k);
  }
  return most;
}

}  // namespace texel::hjif
