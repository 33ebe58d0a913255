// Axis ticks for texel/plot.hpp (axis_ticks): 1-2-5 steps on linear axes;
// powers of ten, with 2 and 5 between on short ranges, on log axes; labels
// with as many decimals as the step needs, and the dB value beside them
// when asked.
#include "texel/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

#include "drawing.hpp"

namespace texel {
// typographic() and db_text(), shared with the rest of the figure layer.
using namespace plot_detail;

namespace {

/// A tick value printed with as many decimals as `step` needs ("0.25", "100", "1e-06").
std::string format_tick(double v, double step) {
  if (std::abs(v) < step * 1e-9) v = 0.0;
  const double mag = std::max(std::abs(v), step);
  if (mag >= 1e6 || step < 1e-4) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return typographic(buf);
  }
  const int digits = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  return typographic(detail::fixed(v, digits));
}

/// The smallest 1-2-5 × 10^k step at least `raw`.
double nice_step(double raw) {
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw * (1.0 - 1e-9)) return m * p;
  return 10.0 * p;
}

std::vector<Tick> linear_ticks(double lo, double hi, int target) {
  const double step = nice_step((hi - lo) / std::max(1, target));
  std::vector<Tick> ticks;
  const double eps = step * 1e-9;
  // Values as k·step, not accumulated, so 0.1 + 0.2 never prints 0.30000000000000004.
  const auto k0 = static_cast<std::int64_t>(std::ceil((lo - eps) / step));
  const auto k1 = static_cast<std::int64_t>(std::floor((hi + eps) / step));
  for (std::int64_t k = k0; k <= k1 && ticks.size() < 1000; ++k) {
    const double v = static_cast<double>(k) * step;
    ticks.push_back({v, format_tick(v, step), {}, true});
  }
  return ticks;
}

std::vector<Tick> log_ticks(double lo, double hi, bool db_labels, int target) {
  const double l0 = std::log10(lo);
  const double l1 = std::log10(hi);
  const double eps = 1e-9;
  const auto d0 = static_cast<int>(std::ceil(l0 - eps));
  const auto d1 = static_cast<int>(std::floor(l1 + eps));
  const int decades = d1 - d0 + 1;  // powers of ten inside the range
  std::vector<Tick> ticks;
  const auto label = [&](double v) {
    const double step = std::pow(10.0, std::floor(std::log10(v) + eps));
    std::string text = step >= 1e5 || step < 1e-4 ? [&] {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%g", v);
      return std::string(buf);
    }()
                                                  : format_tick(v, step);
    return Tick{v, text, db_labels ? "(" + db_text(v) + ")" : std::string(), true};
  };
  const auto in_range = [&](double v) { return v >= lo * (1 - eps) && v <= hi * (1 + eps); };
  if (decades >= 2) {
    const int stride = std::max(1, (decades + target - 1) / std::max(1, target));
    const bool label_25 = l1 - l0 < 1.5;
    for (int d = d0 - 1; d <= d1; ++d) {
      const double p = std::pow(10.0, d);
      if (d >= d0 && (d - d0) % stride == 0) ticks.push_back(label(p));
      if (stride > 1) continue;
      for (int m = 2; m <= 9; ++m) {
        const double v = m * p;
        if (!in_range(v)) continue;
        if (label_25 && (m == 2 || m == 5))
          ticks.push_back(label(v));
        else
          ticks.push_back({v, {}, {}, false});
      }
    }
    std::sort(ticks.begin(), ticks.end(), [](const Tick& a, const Tick& b) { return a.value < b.value; });
    return ticks;
  }
  // Less than two powers of ten inside: 1-2-5 multiples, else a linear scale.
  for (int d = static_cast<int>(std::floor(l0)); d <= static_cast<int>(std::ceil(l1)); ++d)
    for (const double m : {1.0, 2.0, 5.0}) {
      const double v = m * std::pow(10.0, d);
      if (in_range(v)) ticks.push_back(label(v));
    }
  if (ticks.size() >= 3) return ticks;
  ticks = linear_ticks(lo, hi, std::min(target, 5));
  if (db_labels)
    for (auto& t : ticks)
      if (t.value > 0) t.secondary = "(" + db_text(t.value) + ")";
  return ticks;
}

}  // namespace

std::vector<Tick> axis_ticks(double min, double max, AxisScale scale, bool db_labels, int target) {
  if (!std::isfinite(min) || !std::isfinite(max) || !(min < max))
    throw InvalidArgument("axis range is " + detail::num(min) + " … " + detail::num(max) + "; needs finite min < max");
  target = std::clamp(target, 2, 20);
  if (scale == AxisScale::log10) {
    if (min <= 0) throw InvalidArgument("log axis min is " + detail::num(min) + "; must be > 0");
    return log_ticks(min, max, db_labels, target);
  }
  return linear_ticks(min, max, target);
}

}  // namespace texel
