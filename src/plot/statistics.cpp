// The summaries that box plots and histograms draw, for texel/plot.hpp:
// box_stats (quartiles, Tukey whiskers, outliers, mean) and make_histogram
// (equal-width bins on a linear or log scale).
#include "texel/plot.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "texel/error.hpp"

#include "drawing.hpp"

namespace texel {
using plot_detail::nan;

BoxStats box_stats(std::span<const double> values) {
  std::vector<double> v;
  v.reserve(values.size());
  for (const double x : values)
    if (std::isfinite(x)) v.push_back(x);
  BoxStats st;
  st.n = v.size();
  if (v.empty()) {
    st.q1 = st.median = st.q3 = st.whisker_low = st.whisker_high = st.mean = nan;
    return st;
  }
  std::sort(v.begin(), v.end());
  // Hyndman & Fan type 7: h = (n − 1)p, linear between order statistics.
  const auto q = [&](double prob) {
    const double h = static_cast<double>(v.size() - 1) * prob;
    const auto lo = static_cast<std::size_t>(std::floor(h));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
  };
  st.q1 = q(0.25);
  st.median = q(0.5);
  st.q3 = q(0.75);
  const double iqr = st.q3 - st.q1;
  const double fence_lo = st.q1 - 1.5 * iqr, fence_hi = st.q3 + 1.5 * iqr;
  st.whisker_low = st.q1;
  st.whisker_high = st.q3;
  double sum = 0;
  for (const double x : v) {
    sum += x;
    if (x < fence_lo || x > fence_hi)
      st.outliers.push_back(x);
    else
      st.whisker_low = std::min(st.whisker_low, x), st.whisker_high = std::max(st.whisker_high, x);
  }
  st.mean = sum / static_cast<double>(v.size());
  return st;
}

Histogram make_histogram(std::span<const double> values, std::size_t bins, AxisScale scale) {
  if (bins > 100000) throw InvalidArgument("histogram bins is " + std::to_string(bins) + "; allowed 0 (auto) … 100000");
  const bool log = scale == AxisScale::log10;
  std::vector<double> t;
  t.reserve(values.size());
  for (const double v : values)
    if (std::isfinite(v) && (!log || v > 0)) t.push_back(log ? std::log10(v) : v);
  Histogram h;
  if (t.empty()) return h;
  if (bins == 0)
    bins = std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(2.0 * std::cbrt(static_cast<double>(t.size())))), 5, 80);
  auto [lo_it, hi_it] = std::minmax_element(t.begin(), t.end());
  double lo = *lo_it, hi = *hi_it;
  if (!(lo < hi)) {
    // All equal: one bin around the value (±0.05 decade on log, ±0.5 on linear).
    const double half = log ? 0.05 : 0.5;
    lo -= half;
    hi += half;
  }
  h.counts.assign(bins, 0.0);
  h.edges.resize(bins + 1);
  for (std::size_t i = 0; i <= bins; ++i) {
    const double e = lo + (hi - lo) * static_cast<double>(i) / static_cast<double>(bins);
    h.edges[i] = log ? std::pow(10.0, e) : e;
  }
  for (const double v : t) {
    const auto k = static_cast<std::size_t>(
        std::clamp((v - lo) / (hi - lo) * static_cast<double>(bins), 0.0, static_cast<double>(bins - 1)));
    h.counts[k] += 1.0;
  }
  return h;
}

}  // namespace texel
